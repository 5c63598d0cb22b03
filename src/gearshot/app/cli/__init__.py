"""The ``gearshot`` command line.

The commands live by what they do: :mod:`.build` (``demo``, ``simulate``, ``rig``),
:mod:`.experiment` (``experiment simulated | rig | rig-family``) and :mod:`.estimate`
(``predict``, ``indicators``, ``report``); each parses its options and calls an application
function of :mod:`gearshot.app`. Importing this package (``gearshot --help``,
``gearshot indicators``) imports no heavy library: each command imports what it needs.
:func:`main` is the console entry point (``gearshot``, ``python -m gearshot``).
"""

from __future__ import annotations

import os
import sys

import typer

from ..._atomic import os_error_text
from ..._errors import GearshotError
from . import build, estimate, experiment, monitor  # noqa: F401  (they register the commands)
from ._apps import VERBOSITY, app, experiment_app
from ._options import empty_value

__all__ = ["app", "experiment_app", "main"]


def _one_line(exc: object) -> str:
    """A message on one line (libraries' messages may span several)."""
    return " ".join(str(exc).split())


def _usage_line(exc) -> str:
    """A click usage error as one line, naming the command and where its help is."""
    text = " ".join(str(exc.format_message()).split())
    ctx = getattr(exc, "ctx", None)
    command = getattr(ctx, "command_path", None) or "gearshot"
    return f"{text} (see `{command} --help`)"


def _error(text: str, code: int) -> None:
    typer.secho(f"gearshot: error: {text}", err=True, fg="red")
    sys.exit(code)


def _click_error(exc: Exception) -> None:
    """Typer's click usage errors: one line, exit 2 (the help where it asks for help);
    anything else is a bug, reported in one line (exit 3) unless GEARSHOT_DEBUG is set."""
    if hasattr(exc, "show") and hasattr(exc, "exit_code"):
        if type(exc).__name__ == "NoArgsIsHelpError" or not hasattr(exc, "format_message"):
            exc.show()       # `gearshot` or `gearshot experiment` alone: the help
            sys.exit(exc.exit_code)
        _error(_usage_line(exc), exc.exit_code)
    if os.environ.get("GEARSHOT_DEBUG") or VERBOSITY["verbose"]:
        raise exc
    _error(f"unexpected {type(exc).__name__}: {exc} (a bug: please report it; "
           f"GEARSHOT_DEBUG=1 shows the traceback)", 3)


def main() -> None:
    """Console entry point: user errors become one line and a non-zero exit."""
    from ..files import spread_file_options

    try:
        empty = empty_value(sys.argv[1:])
        if empty is not None:
            raise GearshotError(f"{empty} is empty; give a path or value (an empty path "
                                f"would silently mean the current folder)")
        app(args=spread_file_options(sys.argv[1:]), prog_name="gearshot",
            standalone_mode=False)
    except GearshotError as exc:
        _error(_one_line(exc), 2)
    except OSError as exc:  # disk full, file too large, permission, missing file
        where = f" {exc.filename!r}" if getattr(exc, "filename", None) else ""
        typer.secho(f"gearshot: error:{where} {_one_line(os_error_text(exc))}", err=True,
                    fg="red")
        sys.exit(1)
    except MemoryError:
        _error("out of memory; try fewer or shorter signals (smaller counts or sizes)", 1)
    except KeyboardInterrupt:
        typer.secho("gearshot: interrupted", err=True)
        sys.exit(130)
    except typer.Exit as exc:
        sys.exit(exc.exit_code)
    except typer.Abort:
        sys.exit(1)
    except Exception as exc:  # usage errors of typer's click: one line, exit 2
        _click_error(exc)
