"""Rig-family fits that cannot read their own example, and the error of their estimates.

For each rig of the family (segments cached by ``benchmarks/rig_family.py``) and each
example draw, the library-default fit is made as the family benchmark makes it, and its
``fit_check_.example_self`` (the fit's estimate of the example it calibrated on) is set
beside the row's test MAE from a family results file of the same rigs, draws and
defaults. Printed: per fit, then the count of fits misreading their example by more
than ``EXAMPLE_LIMIT`` and the mean MAE of those and of the others.

    GEARSHOT_DATA=/work/data-w-estimator PYTHONPATH=src python \\
        benchmarks/example_self_family.py --seeds $(seq 100 123) \\
        --results /work/data-w-estimator/family/base24.jsonl
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from gearshot._paths import data_home
from gearshot.estimator.fit_check import EXAMPLE_LIMIT
from gearshot.experiments.family_rigs import cached_family_fits


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, nargs="+", required=True)
    ap.add_argument("--draws", type=int, default=2)
    ap.add_argument("--results", type=Path, required=True,
                    help="family results (JSON lines) of the same rigs; the first config")
    ap.add_argument("--frf-folder", type=Path,
                    default=Path(__file__).resolve().parents[2] / "shared" / "data" / "frf")
    args = ap.parse_args()
    rows = [json.loads(line) for line in args.results.read_text().splitlines() if line]
    config = rows[0]["config"]
    mae = {(r["seed"], r["draw"]): 100 * r["mae"] for r in rows
           if r["config"] == config and r["variant"] == "full"}
    misread, other = [], []
    for rig, draw, ds, _, est in cached_family_fits(args.seeds, data_home(), args.frf_folder,
                                                    draws=args.draws):
        own = est.fit_check_.example_self
        off = abs(own - ds.faulty_size) > EXAMPLE_LIMIT
        err = mae.get((rig.seed, draw), float("nan"))
        (misread if off else other).append(err)
        print(f"rig {rig.seed} draw {draw} grade {rig.grade:2d} example {ds.faulty_size:.2f}"
              f" reads {own:.2f}{' MISREAD' if off else ''}  MAE {err:.1f} %", flush=True)
    n = len(misread) + len(other)
    print(f"\nfits misreading their own example by more than {EXAMPLE_LIMIT:g}: "
          f"{len(misread)} / {n}; MAE {np.nanmean(misread):.1f} % against "
          f"{np.nanmean(other):.1f} % for the other {len(other)}")


if __name__ == "__main__":
    main()
