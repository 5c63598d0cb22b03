"""Options shared by several commands, and the checks every command runs before its work.

The checks turn a bad option into one :class:`~gearshot.GearshotError` line naming the
option and the value, before any long work starts (and before an output that cannot be
written would be found out at the end).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Annotated

import typer

from ..._atomic import check_writable, write_json_atomic
from ..._errors import GearshotError
from ..._validation import check_attenuation, check_load, check_speed
from ...paper import CYCLES_PER_SEGMENT, GEAR_TEETH, PINION_TEETH

__all__ = ["NHealthy", "NFaulty", "Scheduler", "Workers", "RigGrade", "ResultsJson",
           "FiguresOut", "HELP_PARAM", "MAX_DURATION", "MAX_COUNT", "write_json", "early",
           "check_duration", "check_condition", "check_frf_folder", "check_count",
           "check_counts", "check_seed", "given", "refuse_together", "only_with",
           "check_store_folder", "check_attenuations", "empty_value"]

HELP_N_HEALTHY = "Simulated healthy signals per grade and condition."
HELP_N_FAULTY = ("Simulated faulty signals per grade and condition (sizes drawn uniformly "
                 "in (0, 1]).")
HELP_SCHEDULER = "Address of a running Dask scheduler (default: a LocalCluster of --workers)."
HELP_WORKERS = "LocalCluster workers when no --scheduler is given."
HELP_PARAM = ("NAME=VALUE: an estimator parameter for every variant (VALUE as JSON when it "
              "parses).")

NHealthy = Annotated[int, typer.Option("--n-healthy", help=HELP_N_HEALTHY)]
NFaulty = Annotated[int, typer.Option("--n-faulty", help=HELP_N_FAULTY)]
Scheduler = Annotated[str | None, typer.Option("--scheduler", help=HELP_SCHEDULER)]
Workers = Annotated[int, typer.Option("--workers", help=HELP_WORKERS)]
RigGrade = Annotated[int | None, typer.Option("--rig-grade", help="Force the rig's true "
                                              "surface grade (default: hidden, drawn).")]
ResultsJson = Annotated[Path | None, typer.Option("--json", help="Write results as JSON.")]
FiguresOut = Annotated[Path | None, typer.Option("--out", help="Folder for figures and "
                                                 "report.")]

MAX_DURATION = 1200.0   # s per recording (60 s in the paper)
MAX_COUNT = 10_000      # recordings per campaign size / simulated signals are bounded below


def write_json(path: Path | None, payload: dict) -> None:
    """Write ``payload`` to ``path`` (nothing when None), floats for numpy scalars."""
    if path is None:
        return
    write_json_atomic(payload, path, make_parents=True, indent=2, sort_keys=False,
                      default=float)


def early(path: Path | None, option: str, *, folder: bool = False) -> None:
    """Fail now, before the long work, if an output cannot be written."""
    if path is not None:
        check_writable(path, option, folder=folder)


def check_duration(duration: float, speed: float, *, option: str = "--duration",
                   gear_teeth: int = GEAR_TEETH, pinion_teeth: int = PINION_TEETH) -> None:
    """A recording must hold one SA segment (the paper's 50 gear revolutions) at ``speed``."""
    check_speed(speed, "--speed")
    if not (0 < duration <= MAX_DURATION):
        raise GearshotError(f"{option} must lie in (0, {MAX_DURATION:g}] s; got {duration!r}")
    revs = duration * speed * pinion_teeth / gear_teeth
    need = CYCLES_PER_SEGMENT * gear_teeth / (pinion_teeth * speed)
    if revs < CYCLES_PER_SEGMENT:
        raise GearshotError(
            f"{option} {duration:g} s holds {revs:.3g} gear revolution(s) at --speed "
            f"{speed:g} rps; one SA segment needs {CYCLES_PER_SEGMENT} "
            f"(--duration >= {need:.3g} s)")


def check_condition(speeds: Iterable[float], loads: Iterable[float]) -> None:
    """Physical bounds on the --speed / --load values (rev/s, N m)."""
    for v in speeds:
        check_speed(v, "--speed")
    for v in loads:
        check_load(v, "--load")


def check_frf_folder(folder: Path | None, *, minimum: int = 1) -> None:
    """The FRF folder exists and holds at least ``minimum`` readable FRFs (checked now,
    before any database is built)."""
    if folder is None:
        return
    if not folder.is_dir():
        raise GearshotError(f"--frf-folder {str(folder)!r} is not a folder")
    from ...transfer import TransferFunctionBank

    try:
        n_frfs = len(TransferFunctionBank.from_folder(folder))
    except GearshotError as exc:
        raise GearshotError(f"--frf-folder: {exc}") from None
    if n_frfs < minimum:
        raise GearshotError(f"--frf-folder {str(folder)!r} holds {n_frfs} FRF(s); "
                            f"this needs at least {minimum}")


def check_count(value: int, option: str, *, minimum: int = 0,
                maximum: int = MAX_COUNT) -> None:
    """``minimum <= value <= maximum`` or a line naming ``option`` and ``value``."""
    if not minimum <= value <= maximum:
        raise GearshotError(f"{option} must lie in {minimum} … {maximum}; got {value}")


def check_counts(n_healthy: int, n_faulty: int, workers: int) -> None:
    """The simulated-signal counts and the LocalCluster's workers."""
    check_count(n_healthy, "--n-healthy", maximum=100_000)
    check_count(n_faulty, "--n-faulty", maximum=100_000)
    check_count(workers, "--workers", minimum=1, maximum=256)


def check_seed(seed: int, option: str = "--seed") -> None:
    """A seed numpy takes (0 … 2**32 - 1)."""
    check_count(seed, option, maximum=2**32 - 1)


def given(ctx: typer.Context, option: str) -> bool:
    """Whether ``option`` (as spelt on the command line, ``"--speed"``) was given by the
    user rather than left at its default."""
    for param in ctx.command.params:
        if option in param.opts or option in getattr(param, "secondary_opts", ()):
            source = ctx.get_parameter_source(param.name or "")
            # by name: typer's parser is its own copy of click's, with its own enum
            return getattr(source, "name", None) in ("COMMANDLINE", "ENVIRONMENT")
    raise GearshotError(f"no option {option!r} on {ctx.command_path}")  # a wrong call


def refuse_together(ctx: typer.Context, first: str, second: str, why: str) -> None:
    """Refuse ``first`` and ``second`` given together (one would be ignored or
    overridden): a line naming both and ``why``."""
    if given(ctx, first) and given(ctx, second):
        raise GearshotError(f"{first} and {second} cannot be given together: {why}")


def only_with(ctx: typer.Context, option: str, needed: str, why: str = "") -> None:
    """Refuse ``option`` given without ``needed`` (it would be silently ignored)."""
    if given(ctx, option) and not given(ctx, needed):
        raise GearshotError(f"{option} applies only with {needed}"
                            + (f": {why}" if why else "") + f"; remove {option} or give "
                            f"{needed}")


def empty_value(args: list[str]) -> str | None:
    """The option (or ``"an argument"``) given an empty value in ``args`` -- an empty path
    would silently mean the current folder -- or None."""
    for i, arg in enumerate(args):
        if arg.startswith("--") and arg.endswith("=") and len(arg) > 3:
            return arg[:-1]
        if arg == "" or (arg.strip() == "" and arg):
            before = args[i - 1] if i > 0 else ""
            return before if before.startswith("-") and "=" not in before else "an argument"
    return None


def check_store_folder(store: Path | None, option: str = "--store") -> None:
    """A database store is a new or empty folder or a gearshot database (its
    ``manifest.json`` or ``blocks``): never a folder of other files (a campaign's
    recordings, a home folder) that a build would mix a store into."""
    if store is None or not store.is_dir():
        return
    if (store / "manifest.json").exists() or (store / "blocks").is_dir():
        return
    held = sorted(p.name for p in store.iterdir())
    if held:
        shown = ", ".join(held[:3]) + (", ..." if len(held) > 3 else "")
        raise GearshotError(f"{option} {str(store)!r} is a folder of other files ({shown}), "
                            f"not a gearshot database; give a new or empty folder")


def check_attenuations(values: Iterable[float], option: str = "--attenuation-db") -> None:
    """Every path attenuation within the bounds of every command and API function
    (:data:`gearshot._validation.ATTENUATION_DB_RANGE`)."""
    for v in values:
        check_attenuation(v, option)
