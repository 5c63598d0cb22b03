"""The ``gearshot`` command and its ``experiment`` group (the commands register on them)."""

from __future__ import annotations

import typer

from ... import __version__

__all__ = ["app", "experiment_app"]

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
    version: bool = typer.Option(False, "--version", callback=_version_callback,
                                 is_eager=True, help="Print the version and exit."),
) -> None:
    """One-fault-shot gear tooth-fault size estimation."""
