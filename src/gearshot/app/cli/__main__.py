"""``python -m gearshot.app.cli``: the ``gearshot`` command."""

from . import main

main()
