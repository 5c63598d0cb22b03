"""The rig family with parts of every rig's hidden reality set (a controlled experiment).

Runs ``benchmarks/rig_family.py`` in this process with each rig built as
``VirtualRig(...).with_reality(**OVERRIDES)`` (:class:`gearshot.rig.reality.RigReality`
fields, e.g. ``speed_drift``, ``speed_ripple``, ``load_ripple``, ``snr_db``,
``motor_level``): what the family's error owes to one part of the rigs' reality. The
rigs' cache key does not hold the overrides, so give the run its own ``--rigs-cache``;
``--workers 1`` (the overrides live in this process only).

    GEARSHOT_DATA=DIR python benchmarks/rig_family_reality.py '{"speed_drift": 0}' \\
        --seeds 102 103 121 --tag T --workers 1 --rigs-cache DIR/rigs-T --rigs-table
"""

from __future__ import annotations

import json
import runpy
import sys
from pathlib import Path


def main() -> None:
    if len(sys.argv) < 2 or sys.argv[1].startswith("-"):
        sys.exit(__doc__)
    overrides = json.loads(sys.argv[1])
    if not isinstance(overrides, dict):
        sys.exit(f"OVERRIDES must be a JSON object; got {sys.argv[1]!r}")
    if "--rigs-cache" not in sys.argv:
        sys.exit("give the run its own --rigs-cache: the cache key does not hold the overrides")
    from gearshot.experiments import family_rigs

    plain = family_rigs._rig

    def with_reality(cls, seed, paths, grade, path_index):
        return plain(cls, seed, paths, grade, path_index).with_reality(**overrides)

    family_rigs._rig = with_reality
    sys.argv = [str(Path(__file__).with_name("rig_family.py")), *sys.argv[2:]]
    runpy.run_path(sys.argv[0], run_name="__main__")


if __name__ == "__main__":
    main()
