"""A database store's manifest: what a build is, as written, read, checked and restored.

``manifest.json`` (written first, atomically) records the build's arguments: format, gear
pair (its repr), speeds, loads, grades, signal counts, seed, SA length, and -- only when
they differ from a plain FTFF build, so older stores keep their manifest -- the fault types
with their model versions (:mod:`gearshot.fault_registry`) and ``paired``. A block's name
follows from its position (:func:`block_name`). :func:`prepare_store` checks the manifest a
build finds against the one it was given (restoring a damaged one from the blocks' copies);
:func:`rebuild_hint` is the repair command every error names.
"""

from __future__ import annotations

import ast
import json
import sys
from pathlib import Path

from .._atomic import write_json_atomic
from .._errors import GearshotError
from ._db_checksums import block_manifest
from ._integrity import manifest_diff
from .fault_types import FAULT_MODEL_VERSIONS
from .geometry import GearPair

__all__ = ["FORMAT", "PAIR_ATTRS", "block_name", "make_manifest", "pair_attrs",
           "pair_from_manifest", "check_fault_models", "read_manifest", "rebuild_hint",
           "prepare_store", "repair_command", "blocks_manifest"]

FORMAT = 1

#: Dataset attributes that :func:`~gearshot.sim.load_database` sets from the store's pair.
PAIR_ATTRS = ("pinion_teeth", "gear_teeth", "module", "face_width", "pressure_angle",
              "helix_angle")


def block_name(i, j, k, fault_type="ftff"):
    """``s{i}_l{j}_g{k}.zarr`` (``..._{type}.zarr`` for a fault type other than the FTFF)."""
    if fault_type == "ftff":
        return f"s{i}_l{j}_g{k}.zarr"
    return f"s{i}_l{j}_g{k}_{fault_type}.zarr"


def _pair_repr(pair):
    # a spur pair keeps the text of stores built before helix_angle existed
    text = repr(pair)
    return text.replace(", helix_angle=0.0)", ")") if not pair.is_helical else text


def pair_from_manifest(man: dict) -> GearPair | None:
    """The store's gear pair, read back from the manifest's ``pair`` text (a GearPair
    repr, recorded by every store since the first format); None if it cannot be read."""
    try:
        call = ast.parse(str(man["pair"]), mode="eval").body
        if not (isinstance(call, ast.Call) and isinstance(call.func, ast.Name)
                and call.func.id == "GearPair" and not call.args):
            return None
        fields = {k.arg: _literal(k.value) for k in call.keywords if k.arg}
        if len(fields) != len(call.keywords):   # a **mapping
            return None
        return GearPair(**fields)   # fields absent from older texts take their defaults
    except (KeyError, SyntaxError, ValueError, TypeError, GearshotError):
        return None


def _literal(node):
    """A literal of a repr, numpy scalars (``np.float64(0.003)``, numpy >= 2) included."""
    if (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and isinstance(node.func.value, ast.Name) and node.func.value.id in ("np", "numpy")
            and node.func.attr in ("float64", "float32", "int64", "int32")
            and len(node.args) == 1 and not node.keywords):
        return ast.literal_eval(node.args[0])
    return ast.literal_eval(node)


def pair_attrs(pair: GearPair) -> dict:
    """A gear pair as database attributes (:data:`PAIR_ATTRS`: teeth, m, rad)."""
    return {"pinion_teeth": int(pair.z_pinion), "gear_teeth": int(pair.z_gear),
            "module": float(pair.module), "face_width": float(pair.face_width),
            "pressure_angle": float(pair.pressure_angle),
            "helix_angle": float(pair.helix_angle)}


def make_manifest(pair, speeds, loads, grades, n_healthy, n_faulty, seed, n_points,
                  fault_types=("ftff",), paired=False) -> dict:
    """The manifest of a build (validated arguments)."""
    man = {"format": FORMAT, "pair": _pair_repr(pair), "speeds": [float(s) for s in speeds],
           "loads": [float(x) for x in loads], "grades": [int(g) for g in grades],
           "n_healthy": n_healthy, "n_faulty": n_faulty, "seed": seed, "n_points": n_points}
    if list(fault_types) != ["ftff"]:
        man["fault_types"] = list(fault_types)
        man["fault_models"] = {t: FAULT_MODEL_VERSIONS[t] for t in fault_types}
    if paired:   # only when set: stores built before pairing keep their manifest
        man["paired"] = True
    return man


def check_fault_models(store: Path, man: dict, types) -> None:
    """Refuse SAs of a fault type simulated with an older model of that type."""
    stored = man.get("fault_models", {"ftff": 1})
    for t in types:
        have, want = stored.get(t), FAULT_MODEL_VERSIONS[t]
        if have != want:
            raise GearshotError(f"store {str(store)!r} holds {t!r} SAs of an older model of "
                                f"that fault type (model version {have}, current {want}); "
                                f"rebuild them into a new store (build_database / "
                                f"gearshot simulate --fault-type {t})")


def read_manifest(store: Path) -> dict:
    """The store's ``manifest.json`` (a :class:`~gearshot.GearshotError` naming the repair
    when it is unreadable or not a gearshot manifest)."""
    mpath = store / "manifest.json"
    try:
        man = json.loads(mpath.read_text())
        if not isinstance(man, dict) or not {"speeds", "loads", "grades"} <= set(man):
            raise ValueError("not a gearshot manifest")
    except (OSError, ValueError) as exc:
        text = str(exc).splitlines()[0][:80] if str(exc) else type(exc).__name__
        raise GearshotError(
            f"store {str(store)!r}: manifest.json is damaged ({text}); run `gearshot "
            f"simulate --repair --store {str(store)}`: it restores the manifest from the "
            f"blocks' copies (or build_database / `gearshot simulate` on this store with "
            f"its original arguments)") from None
    return man


def rebuild_hint(store: Path, man: dict, blocks=()) -> str:
    """The command that repairs ``store`` for the build ``man``, and what it will do."""
    def many(opt, values, fmt):
        return " ".join(f"{opt} {fmt(v)}" for v in values)

    cmd = (f"gearshot simulate --store {str(store)} "
           f"{many('--speed', man.get('speeds', []), lambda v: f'{v:g}')} "
           f"{many('--load', man.get('loads', []), lambda v: f'{v:g}')} "
           f"{many('--grade', man.get('grades', []), str)} "
           f"--n-healthy {man.get('n_healthy')} --n-faulty {man.get('n_faulty')} "
           f"--seed {man.get('seed')}"
           + "".join(f" --fault-type {t}" for t in man.get("fault_types", []))
           + ("" if man.get("paired") else " --no-paired"))   # paired is the default
    what = (f"it (re)builds {', '.join(blocks)} and reuses the other blocks" if blocks else
            "it restores manifest.json from the blocks' copies and rebuilds no block")
    return (f"run `gearshot simulate --repair --store {str(store)}` (it checks every block "
            f"in full and rebuilds exactly the damaged and missing ones), or `{cmd}` (or "
            f"build_database with the same arguments): {what}")


def prepare_store(store: Path, manifest: dict, progress: bool = True) -> None:
    """Check (or write, or restore) the manifest and make ``blocks/``; called with the
    store's lock held."""
    mpath = store / "manifest.json"
    if mpath.exists():
        try:
            old = read_manifest(store)
        except GearshotError:
            old = None
        if old != manifest:
            _restore_or_refuse(store, old, manifest, progress)
    try:
        (store / "blocks").mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise GearshotError(f"store {str(store)!r} is not writable ({exc.strerror or exc})") \
            from None
    if not mpath.exists():
        write_json_atomic(manifest, mpath, sort_keys=False)


def _restore_or_refuse(store: Path, old: dict | None, manifest: dict, progress: bool) -> None:
    """manifest.json is damaged (``old`` None) or says another build: restore it only when
    the blocks (by their recorded digests) all vouch for this build, else refuse."""
    copies = [block_manifest(b) for b in (store / "blocks").glob("*.zarr")]
    if copies and all(c == manifest for c in copies):
        if progress:
            what = ("is damaged" if old is None else
                    f"contradicts its blocks (differs in {manifest_diff(old, manifest)})")
            print(f"store {str(store)!r}: manifest.json {what}; restored from the "
                  f"blocks' copies", file=sys.stderr)
        write_json_atomic(manifest, store / "manifest.json", sort_keys=False)
        return
    if old is None:
        read_manifest(store)     # raises its error
        return
    diff = sorted(k for k in manifest if old.get(k) != manifest[k])
    hint = ""
    if diff == ["paired"]:
        hint = (" (it was built without healthy twins: finish it with "
                "paired=False / --no-paired)" if manifest.get("paired") else
                " (it was built with healthy twins: finish it with paired=True"
                " / --paired)")
    raise GearshotError(f"store {str(store)!r} holds a different build "
                        f"(differs in {', '.join(diff)}){hint}; use a new store "
                        f"(--store / store=)")


def repair_command(store) -> str:
    """The command that repairs ``store``: ``gearshot simulate --repair --store STORE``."""
    return f"gearshot simulate --repair --store {str(store)}"


def blocks_manifest(store: Path) -> tuple[dict | None, int, int]:
    """The manifest the store's blocks vouch for: ``(manifest or None, blocks vouching,
    blocks)``; None when no block vouches for one or they vouch for different builds."""
    blocks = sorted((store / "blocks").glob("*.zarr")) if (store / "blocks").is_dir() else []
    copies = [c for c in (block_manifest(b) for b in blocks) if c is not None]
    if not copies or any(c != copies[0] for c in copies[1:]):
        return None, len(copies), len(blocks)
    return copies[0], len(copies), len(blocks)
