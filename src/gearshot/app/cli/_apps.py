"""The ``gearshot`` command and its ``experiment`` group (the commands register on them),
with the global options: ``-V/--version``, ``-v/--verbose``, ``-q/--quiet``."""

from __future__ import annotations

from typing import Any

import typer
import typer.core

from ... import __version__
from ..._errors import GearshotError

__all__ = ["app", "experiment_app", "VERBOSITY"]

#: The global options' effect, read by :func:`gearshot.app.cli.main` (``verbose``: the
#: traceback of an unexpected error).
VERBOSITY = {"verbose": False, "quiet": False}


def _flag_type(self: typer.core.TyperOption, ctx: Any) -> str | None:
    """The help's type column: nothing for a flag (``--paper``, ``--paired/--no-paired``,
    ``--help``), which takes no value; the value's type for every other option."""
    if self.is_flag or self.count:
        return None
    return _option_type(self, ctx)


_option_type = typer.core.TyperOption.display_type_rich
typer.core.TyperOption.display_type_rich = _flag_type  # type: ignore[method-assign]

app = typer.Typer(
    name="gearshot",
    help="One-fault-shot gear tooth-fault size estimation (Matania et al., 2023).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
experiment_app = typer.Typer(help="Run the paper's experiments (Sec. 4.1 and 4.2).",
                             no_args_is_help=True)
app.add_typer(experiment_app, name="experiment")


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"gearshot {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(False, "-V", "--version", callback=_version_callback,
                                 is_eager=True, help="Print the version and exit."),
    verbose: bool = typer.Option(False, "-v", "--verbose", help="On an unexpected error "
                                 "(exit 3), print its full traceback."),
    quiet: bool = typer.Option(False, "-q", "--quiet", help="No progress bars or progress "
                               "lines (results and errors still print)."),
) -> None:
    """One-fault-shot gear tooth-fault size estimation."""
    from ..._progress import set_quiet

    if verbose and quiet:
        raise GearshotError("--verbose and --quiet cannot be given together: one asks for "
                            "more output, the other for less")
    VERBOSITY.update(verbose=verbose, quiet=quiet)
    set_quiet(quiet)
