"""``python -m gearshot``: the ``gearshot`` command."""

from .app.cli import main

main()
