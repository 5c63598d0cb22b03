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
from ..._validation import check_load, check_speed
from ...paper import CYCLES_PER_SEGMENT, GEAR_TEETH, PINION_TEETH

__all__ = ["NHealthy", "NFaulty", "Scheduler", "Workers", "RigGrade", "ResultsJson",
           "FiguresOut", "HELP_PARAM", "MAX_DURATION", "MAX_COUNT", "write_json", "early",
           "check_duration", "check_condition", "check_frf_folder", "check_count",
           "check_counts", "check_seed"]

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
