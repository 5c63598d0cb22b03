"""Fingerprints of what the machine-file and recording readers produce (issue #21 item 6).

Prints one SHA-256 line per output: every machine file's parsed ``Machine`` (repr and its
train: ratios, mesh orders, gear pair), the SAs of every shaft of every shared PHM09 record
read with its machine (tacho), the SAs of two records read without the tacho (speed from
the vibration), a synthetic recording written and read back in every format (SAs from tooth
counts), and the text of every error of a set of bad machine descriptions and reads. Run it
before and after a refactor and compare the two outputs with ``diff``: they must be equal.

    PYTHONPATH=src python benchmarks/check_io_identical.py > before.txt
"""

from __future__ import annotations

import hashlib
import sys
import tempfile
from pathlib import Path

import numpy as np

from gearshot import GearshotError, Machine
from gearshot.io import Recording

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data" / "phm09"
MACHINES = ROOT / "examples" / "machines"


def digest(value: object) -> str:
    if isinstance(value, np.ndarray):
        data = np.ascontiguousarray(value).tobytes() + str(value.shape).encode()
    else:
        data = repr(value).encode()
    return hashlib.sha256(data).hexdigest()[:16]


def machines() -> None:
    for toml in sorted(MACHINES.glob("*.toml")):
        m = Machine.from_toml(toml)
        train = [(s, m.speed_ratio(s), m.mesh_orders(s), m.gear_teeth(s)) for s in m.shafts]
        pair = m.gear_pair() if m.monitored is not None else None
        print(toml.name, "machine", digest(m), digest(train), digest(pair))


def phm09_sas() -> None:
    for path in sorted(DATA.glob("*.zip")):
        kind = "spur" if path.name.startswith("spur") else "helical"
        m = Machine.from_toml(MACHINES / f"phm09_{kind}.toml")
        rec = Recording.read(path, machine=m)
        print(path.name, "acc", digest(rec.acceleration), "speed", repr(rec.shaft_speed()))
        for shaft in m.shafts:
            sa = rec.to_sa_segments(shaft=shaft, cycles_per_segment=None)
            seg = rec.to_sa_segments(shaft=shaft, cycles_per_segment=10, samples_per_cycle=512)
            print(path.name, shaft, digest(sa), digest(seg))


def notacho_sas() -> None:
    for name, kind in (("spur2_30hz_High_1.zip", "spur"), ("helical2_40hz_Low_1.zip", "helical")):
        m = Machine.from_toml(MACHINES / f"phm09_{kind}_notacho.toml")
        rec = Recording.read(DATA / name, machine=m)
        angle = rec.vibration_angle()
        sa = rec.to_sa_segments(shaft=m.monitored.shaft, cycles_per_segment=None)
        print(name, "notacho", digest(angle.pulse_times), repr(rec.speed_uncertainty),
              digest(sa))


def round_trips() -> None:
    rng = np.random.default_rng(0)
    fs, n = 20000.0, 40000
    t = np.arange(n) / fs
    acc = np.sin(2 * np.pi * 17 * 15 * t) + 0.1 * rng.standard_normal(n)
    tacho = (np.sin(2 * np.pi * 15 * t) > 0.99).astype(float)
    rec = Recording(acc, tacho, fs, speed=15.0, load=10.0, fault_size=0.25,
                    tacho_pulses_per_rev=1, extras={"rig": "x"})
    with tempfile.TemporaryDirectory() as tmp:
        for suffix in (".h5", ".mat", ".wav", ".csv"):
            path = Path(tmp) / f"rec{suffix}"
            rec.write(path)
            back = Recording.read(path)
            sa = back.to_sa_segments(gear_teeth=38, pinion_teeth=17, cycles_per_segment=5,
                                     samples_per_cycle=256)
            print("roundtrip", suffix, digest(back.acceleration), digest(back.metadata),
                  digest(sa))


BAD_MACHINES = [
    {}, {"name": 3}, {"shafts": "a"}, {"shafts": ["a", "b"]},
    {"shafts": ["a", "b"], "stage": [{"driver": "a"}]},
    {"shafts": ["a", "b"], "stage": [{"driver": "a", "driver_teeth": 10, "driven": "b",
                                      "driven_teeth": 0}]},
    {"shafts": ["a", "b"], "stage": [{"driver": "a", "driver_teeth": 10, "driven": "a",
                                      "driven_teeth": 20}]},
]


def _good(**tables: object) -> dict[str, object]:
    data: dict[str, object] = {
        "name": "m", "shafts": ["a", "b"],
        "stage": [{"driver": "a", "driver_teeth": 10, "driven": "b", "driven_teeth": 20,
                   "module_mm": 2.0, "helix_angle_deg": 10.0}],
        "tacho": {"channel": "t", "shaft": "a", "pulses_per_rev": 2},
        "sensor": [{"name": "s", "sensitivity": "10 mV/g"}],
        "file": {"columns": ["s", "t"], "fs": "1000/3"},
        "monitored": {"shaft": "b", "teeth": 20},
    }
    data.update(tables)
    return {k: v for k, v in data.items() if v is not None}


BAD_MACHINES += [
    _good(), _good(tacho={"channel": "t", "shaft": "a"}), _good(tacho=None),
    _good(tacho=None, speed={"range_hz": [30, 20]}), _good(speed={"shaft": "c"}),
    _good(speed={"bogus": 1}), _good(sensor=[{"name": "s", "ac_coupled": 1}]),
    _good(sensor=[{"channel": "s"}]), _good(sensor=[{"name": "s", "sensitivity": "10 V"}]),
    _good(sensor=[{"name": "s", "sensitivity": "10 mV/g", "unit": "m/s^2"}]),
    _good(sensor=[{"name": "s", "sensitivity": -1}]), _good(sensor=[{"name": "x"}]),
    _good(sensor=[{"name": "s"}, {"name": "s"}]), _good(file={"columns": ["s", "t"]}),
    _good(file={"columns": [], "fs": 10}), _good(file={"columns": ["s", "t"], "fs": "a/b"}),
    _good(file={"columns": ["s", "t"], "fs": 1e9}), _good(file={"columns": ["s", "s"], "fs": 1}),
    _good(file={"columns": ["s", "t"], "fs": 1, "delimiter": "|"}),
    _good(file={"columns": ["s", "t"], "fs": 1, "header": "yes"}),
    _good(monitored={"shaft": "b"}), _good(monitored={"shaft": "b", "teeth": 21}),
    _good(monitored={"shaft": "c", "teeth": 20}), _good(analysis={"cycles_per_segment": "x"}),
    _good(analysis={"cycles_per_segment": 0}), _good(analysis={"shaft_orders": 1}),
    _good(analysis={"samples_per_cycle": 8}), _good(analysis={"antialias": "no"}),
    _good(analysis={"n_sidebands": -1}), _good(analysis={"shaft_orders": [1, 0]}),
    _good(shafts=["a", "b", "c"]), _good(shafts=["a", "a"]), _good(shafts=["a", ""]),
    _good(stage=[{"driver": "a", "driver_teeth": 10, "driven": "b", "driven_teeth": 20},
                 {"driver": "b", "driver_teeth": 10, "driven": "a", "driven_teeth": 10}]),
    _good(stage=[{"driver": "a", "driver_teeth": 10, "driven": "b", "driven_teeth": 20,
                  "helix_angle_deg": 95}]),
    _good(stage=[{"driver": "a", "driver_teeth": 10, "driven": "b", "driven_teeth": 20,
                  "module_mm": [1]}]),
    _good(stage=[{"driver": "a", "driver_teeth": 10, "driven": "z", "driven_teeth": 20}]),
    _good(stage="x"), _good(stage=[3]), _good(bogus=1), _good(tacho=3),
    _good(tacho={"channel": "q", "shaft": "a", "pulses_per_rev": 1}),
    _good(tacho={"channel": "t", "shaft": "a", "pulses_per_rev": 1, "threshold": "x"}),
]


def errors() -> None:
    for i, data in enumerate(BAD_MACHINES):
        try:
            m = Machine.from_dict(data)
            print("machine", i, "ok", digest(m))
        except GearshotError as exc:
            print("machine", i, "error", str(exc))
    with tempfile.TemporaryDirectory() as tmp:
        bad = Path(tmp) / "x.toml"
        bad.write_text("name = [")
        for path in (bad, Path(tmp) / "missing.toml"):
            try:
                Machine.from_toml(path)
            except GearshotError as exc:
                print("toml", path.name, str(exc).replace(tmp, "TMP"))
        for name in ("x.xyz", "missing.h5"):
            try:
                Recording.read(Path(tmp) / name)
            except GearshotError as exc:
                print("read", name, str(exc).replace(tmp, "TMP"))


if __name__ == "__main__":
    parts = sys.argv[1:] or ["machines", "errors", "round_trips", "phm09_sas", "notacho_sas"]
    for part in parts:
        globals()[part]()
        sys.stdout.flush()
