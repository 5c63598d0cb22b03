"""The ``gearshot`` command line."""

from __future__ import annotations

import sys

import typer

from . import __version__
from ._errors import GearshotError

app = typer.Typer(
    name="gearshot",
    help="One-fault-shot gear tooth-fault size estimation (Matania et al., 2023).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)


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


@app.command()
def demo(
    out: str = typer.Option("gearshot-demo", "--out", help="Folder for figures and report."),
) -> None:
    """Run the main pipeline on a small built-in example and write a report."""
    from .demo import run_demo

    run_demo(out)


def main() -> None:
    """Console entry point: user errors become one line and a non-zero exit."""
    try:
        app(standalone_mode=True)
    except GearshotError as exc:
        typer.secho(f"gearshot: error: {exc}", err=True, fg="red")
        sys.exit(2)


if __name__ == "__main__":  # pragma: no cover
    main()
