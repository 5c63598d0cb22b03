"""The command-line contract (issue #32): one-line errors before any long work, options
that are never silently ignored, the same bounds in every command and API function,
all-or-nothing outputs, a batch that goes on past a bad record, speed hints for records
without a tacho, progress as promised and the global options.

The commands run in this process through :func:`gearshot.app.cli.main`, with every long
piece of work (a database build, an experiment, a rig campaign, a fit) replaced by a
function that fails the test if it is reached: a refusal is proved to come first.
"""

from __future__ import annotations

import errno
import io
import json
import math
import sys
import threading
import zipfile
from pathlib import Path

import numpy as np
import pytest
from phm09_records import crop as _crop

from gearshot import GearshotError

ROOT = Path(__file__).resolve().parents[1]
MACHINES = ROOT / "examples" / "machines"
SPUR = MACHINES / "phm09_spur.toml"
SPUR_NOTACHO = MACHINES / "phm09_spur_notacho.toml"
PHM = ROOT.parent / "shared" / "data" / "phm09"


class LongWork(Exception):
    """Raised by the stand-ins of the long work: reaching one fails the test."""


@pytest.fixture
def no_long_work(monkeypatch):
    """Every long piece of work of the commands replaced by a :class:`LongWork` raiser."""
    import gearshot.app.campaigns as campaigns
    import gearshot.app.demo as demo
    import gearshot.app.experiment_runs as runs
    import gearshot.app.predict as predict
    import gearshot.app.simulate as simulate

    def stop(*args, **kwargs):
        raise LongWork("the long work started")

    for module, name in ((simulate, "simulate_database"),
                         (simulate, "simulate_machine_database"),
                         (runs, "run_simulated_experiment"), (runs, "run_rig_experiment"),
                         (runs, "run_rig_family"), (demo, "run_demo"),
                         (campaigns, "make_rig"), (predict, "predict_recordings")):
        monkeypatch.setattr(module, name, stop)


def gearshot(monkeypatch, capsys, *args) -> tuple[int, str, str]:
    """Run ``gearshot ARGS`` in this process: (exit status, stdout, stderr)."""
    from gearshot._progress import set_quiet
    from gearshot.app.cli import main
    from gearshot.app.cli._apps import VERBOSITY

    monkeypatch.setattr(sys, "argv", ["gearshot", *map(str, args)])
    code = 0
    try:
        main()
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else 1
    finally:
        VERBOSITY.update(verbose=False, quiet=False)
        set_quiet(False)
    out, err = capsys.readouterr()
    return code, out, err


def one_line(code: int, err: str, *words: str) -> str:
    """The run was refused with exit 2 and exactly one error line holding ``words``."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2, (code, err)
    assert len(lines) == 1 and lines[0].startswith("gearshot: error:"), err
    assert "Traceback" not in err and "LongWork" not in err, err
    for w in words:
        assert w in lines[0], (w, err)
    return lines[0]


def _predict(t: Path, *extra: str) -> list:
    return ["predict", "--database", t / "db", "--healthy", t / "h.h5", "--faulty",
            t / "f.h5", "--faulty-size", "0.5", "--recordings", t, "--speed", "15",
            *extra]


# ------------------------------------------------ 1. options never silently ignored
IGNORED = {
    "simulate --paper --speed": (lambda t: ["simulate", "--paper", "--speed", "15"],
                                 ["--paper", "--speed"]),
    "simulate --paper --load": (lambda t: ["simulate", "--paper", "--load", "5"],
                                ["--paper", "--load"]),
    "simulate --paper --machine": (lambda t: ["simulate", "--paper", "--machine", SPUR,
                                              "--speed", "30"], ["--paper", "--machine"]),
    "experiment simulated --full --speed": (lambda t: ["experiment", "simulated", "--full",
                                                       "--speed", "20"],
                                            ["--full", "--speed"]),
    "experiment simulated --full --load": (lambda t: ["experiment", "simulated", "--full",
                                                      "--load", "5"], ["--full", "--load"]),
    "predict --machine --gear-teeth": (lambda t: _predict(t, "--machine", SPUR,
                                                          "--gear-teeth", "38"),
                                       ["--machine", "--gear-teeth"]),
    "predict --machine --pinion-teeth": (lambda t: _predict(t, "--machine", SPUR,
                                                            "--pinion-teeth", "17"),
                                         ["--machine", "--pinion-teeth"]),
    "predict --cycles-per-segment": (lambda t: _predict(t, "--cycles-per-segment", "10"),
                                     ["--cycles-per-segment", "--machine"]),
    "predict --sensor": (lambda t: _predict(t, "--sensor", "acc_input"),
                         ["--sensor", "--machine"]),
    "predict --speed-tolerance": (lambda t: _predict(t, "--speed-tolerance", "0.1"),
                                  ["--speed-tolerance", "--machine"]),
    "rig-family --range --seed": (lambda t: ["experiment", "rig-family", "--range",
                                             "heldout", "--seed", "5"],
                                  ["--range", "--seed"]),
    "simulate --machine without --speed": (lambda t: ["simulate", "--machine", SPUR,
                                                      "--store", t / "db"],
                                           ["--machine", "--speed"]),
}


@pytest.mark.parametrize("case", IGNORED)
def test_an_option_that_would_be_ignored_is_refused_naming_both(case, tmp_path, monkeypatch,
                                                                capsys, no_long_work):
    args, words = IGNORED[case]
    code, _, err = gearshot(monkeypatch, capsys, *args(tmp_path))
    one_line(code, err, *words)


def test_predict_api_refuses_what_its_path_would_ignore(tmp_path):
    from gearshot.app.predict import predict_recordings

    with pytest.raises(GearshotError, match="gear_teeth=38"):
        predict_recordings(tmp_path / "db", [], tmp_path / "f.h5", 0.5, [], machine=SPUR,
                           gear_teeth=38)
    with pytest.raises(GearshotError, match="sensor='acc_input'"):
        predict_recordings(tmp_path / "db", [], tmp_path / "f.h5", 0.5, [], speed=15,
                           sensor="acc_input")


# ------------------------------------------------------------------- 1. paths
EMPTY = {
    "simulate --store ''": ["simulate", "--store", ""],
    "rig ''": ["rig", ""],
    "demo --out ''": ["demo", "--out", ""],
    "demo --out=": ["demo", "--out="],
}


@pytest.mark.parametrize("case", EMPTY)
def test_an_empty_path_is_refused(case, tmp_path, monkeypatch, capsys, no_long_work):
    monkeypatch.chdir(tmp_path)
    code, _, err = gearshot(monkeypatch, capsys, *EMPTY[case])
    one_line(code, err, "empty", "current folder")
    assert not any(tmp_path.iterdir())


@pytest.mark.parametrize("command", [["simulate"], ["experiment", "simulated"],
                                     ["experiment", "rig"]])
def test_a_store_into_a_folder_of_other_files_is_refused(command, tmp_path, monkeypatch,
                                                         capsys, no_long_work):
    campaign = tmp_path / "campaign"
    campaign.mkdir()
    (campaign / "index.csv").write_text("path,fault_size\n")
    (campaign / "s15_l10_y0.00_r0.h5").write_bytes(b"x")
    code, _, err = gearshot(monkeypatch, capsys, *command, "--store", campaign)
    one_line(code, err, "--store", "campaign", "index.csv", "not a gearshot database")
    assert sorted(p.name for p in campaign.iterdir()) == ["index.csv", "s15_l10_y0.00_r0.h5"]


def test_a_store_into_an_empty_folder_reaches_the_build(tmp_path, monkeypatch, capsys,
                                                        no_long_work):
    (tmp_path / "db").mkdir()
    code, _, err = gearshot(monkeypatch, capsys, "simulate", "--store", tmp_path / "db",
                            "--grade", "7")
    assert code == 3 and "LongWork" in err      # the stand-in of the build was reached


# --------------------------------------------- 1. checks before the long work
EARLY = {
    "experiment rig --attenuation-db inf": (["experiment", "rig", "--attenuation-db", "inf"],
                                            ["--attenuation-db", "inf"]),
    "experiment simulated --attenuation-db nan": (["experiment", "simulated",
                                                   "--attenuation-db", "nan"],
                                                  ["--attenuation-db", "nan"]),
    "experiment simulated --attenuation-db -inf": (["experiment", "simulated",
                                                    "--attenuation-db", "-inf"],
                                                   ["--attenuation-db", "-inf"]),
    "experiment simulated --attenuation-db 1e308": (["experiment", "simulated",
                                                     "--attenuation-db", "1e308"],
                                                    ["--attenuation-db", "1e+308"]),
    "experiment simulated --attenuation-db -1000": (["experiment", "simulated",
                                                     "--attenuation-db", "-1000"],
                                                    ["--attenuation-db", "-1000"]),
    "experiment simulated --selection-tf bogus": (["experiment", "simulated",
                                                   "--selection-tf", "bogus"],
                                                  ["--selection-tf", "'bogus'"]),
    "experiment simulated --n-healthy 2": (["experiment", "simulated", "--n-healthy", "2"],
                                           ["--n-healthy", "2"]),
    "experiment simulated --n-faulty 3": (["experiment", "simulated", "--n-faulty", "3"],
                                          ["--n-faulty", "3"]),
    "demo --seed 2**40": (["demo", "--seed", str(2**40)], ["--seed", str(2**40)]),
    "simulate --seed 2**40": (["simulate", "--seed", str(2**40)], ["--seed", str(2**40)]),
    "rig --seed 2**40": (["rig", "{t}/rig", "--seed", str(2**40)], ["--seed", str(2**40)]),
    "simulated --seed 2**40": (["experiment", "simulated", "--seed", str(2**40)],
                               ["--seed", str(2**40)]),
    "simulate --load 1e-320": (["simulate", "--load", "1e-320"], ["--load", "0.001"]),
    "rig --load 1e-320": (["rig", "{t}/rig", "--load", "1e-320"], ["--load", "0.001"]),
    "experiment rig --load 1e-320": (["experiment", "rig", "--load", "1e-320"],
                                     ["--load", "0.001"]),
    "demo --draws 0": (["demo", "--draws", "0"], ["--draws", "0"]),
}


@pytest.mark.parametrize("case", EARLY)
def test_a_bad_value_fails_before_the_long_work_and_leaves_nothing(case, tmp_path,
                                                                   monkeypatch, capsys,
                                                                   no_long_work):
    args, words = EARLY[case]
    args = [a.replace("{t}", str(tmp_path)) for a in args]
    if args[0] in ("simulate", "experiment") and "rig-family" not in args:
        args += ["--store", str(tmp_path / "db")]
    monkeypatch.setenv("GEARSHOT_DATA", str(tmp_path / "home"))
    code, _, err = gearshot(monkeypatch, capsys, *args)
    one_line(code, err, *words)
    assert not (tmp_path / "db").exists() and not (tmp_path / "rig").exists()
    assert not (tmp_path / "home").exists()


@pytest.mark.parametrize("value", [-1.0, 200.5, math.nan, math.inf, -math.inf, 1e308])
def test_attenuation_bounds_are_the_same_in_every_command_and_api_function(value, tmp_path,
                                                                           monkeypatch,
                                                                           capsys,
                                                                           no_long_work):
    from gearshot.experiments import simulated_dataset, simulated_experiment
    from gearshot.rig import VirtualRig

    for command in (["experiment", "rig"], ["experiment", "simulated"]):
        code, _, err = gearshot(monkeypatch, capsys, *command, "--attenuation-db",
                                repr(value), "--store", tmp_path / "db")
        one_line(code, err, "--attenuation-db", "[0.0, 200.0]")
    rng = np.random.default_rng(0)
    with pytest.raises(GearshotError, match=r"attenuation_db must lie in \[0.0, 200.0\]"):
        VirtualRig(seed=1, engine="surrogate").with_reality(attenuation_db=value)
    with pytest.raises(GearshotError, match=r"attenuation_db must lie in \[0.0, 200.0\]"):
        simulated_dataset(rng.standard_normal((20, 64)), np.r_[np.zeros(10), np.ones(10)],
                          np.ones(64), attenuation_db=value)
    with pytest.raises(GearshotError, match=r"attenuations_db\[\] must lie in \[0.0, 200.0\]"):
        simulated_experiment(tmp_path / "db", speeds=[15], loads=[10],
                             attenuations_db=[value])
    assert not (tmp_path / "db").exists()


def test_the_attenuation_bounds_themselves_are_accepted_everywhere():
    from gearshot._validation import ATTENUATION_DB_RANGE, check_attenuation
    from gearshot.rig import VirtualRig

    for value in ATTENUATION_DB_RANGE:
        assert check_attenuation(value) == value
        rig = VirtualRig(seed=1, engine="surrogate").with_reality(attenuation_db=value)
        assert rig.reveal().attenuation_db == value


def test_the_selection_tf_check_names_the_bank():
    from gearshot.experiments import check_selection_tf

    assert check_selection_tf(None, None, seed=0) == "synthetic_023"
    assert check_selection_tf(None, "synthetic_004", seed=0) == "synthetic_004"
    with pytest.raises(GearshotError, match="'bogus' is not in the bank"):
        check_selection_tf(None, "bogus", seed=0)


# ------------------------------------------- 1. bounds in the API and the files
def _machine_text(**changes: str) -> str:
    lines = SPUR.read_text().splitlines()
    for key, value in changes.items():
        hits = [i for i, ln in enumerate(lines) if ln.split("=")[0].strip() == key]
        lines[hits[-1]] = f"{key} = {value}"
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("key, value", [("driven_teeth", str(10**30)),
                                        ("driver_teeth", str(10**6)),
                                        ("pulses_per_rev", str(2**40)),
                                        ("teeth", str(10**30))])
def test_huge_integers_in_a_machine_file_are_refused(key, value, tmp_path):
    from gearshot import Machine

    path = tmp_path / "m.toml"
    path.write_text(_machine_text(**{key: value}))
    with pytest.raises(GearshotError, match=f"{key} must be <= 100000"):
        Machine.from_toml(path)


def test_a_huge_samples_per_cycle_is_refused(tmp_path):
    from gearshot import Machine

    path = tmp_path / "m.toml"
    path.write_text(_machine_text(samples_per_cycle=str(2**40)))
    with pytest.raises(GearshotError, match="analysis.samples_per_cycle must be <= 16777216"):
        Machine.from_toml(path)
    path.write_text(_machine_text(samples_per_cycle="4096"))
    assert Machine.from_toml(path).samples_per_cycle == 4096


def test_overflowing_rates_and_ratios_are_gearshot_errors():
    from gearshot.signal import antialias_filter, shaft_cycle_times
    from gearshot.signal.antialias import bandlimited_resynthesis

    x = np.sin(np.arange(256) / 3.0)
    with pytest.raises(GearshotError, match=r"fs must lie in \(0, 1e\+08\] Hz; got 1e\+308"):
        antialias_filter(x, fs=1e308, cutoff=10.0)
    with pytest.raises(GearshotError, match="cutoff"):
        antialias_filter(x, fs=1000.0, cutoff=1e308)
    with pytest.raises(GearshotError, match="fs"):
        bandlimited_resynthesis(x, 1e308, cutoff=10.0, rate=100.0)
    for ratio in (math.inf, -math.inf, math.nan, np.float64(math.inf)):
        with pytest.raises(GearshotError, match="revs_per_cycle must be an exact ratio"):
            shaft_cycle_times(np.arange(10) * 0.1, revs_per_cycle=ratio)


def test_a_huge_declared_schema_is_refused_before_it_is_read(tmp_path, monkeypatch):
    """A skops file whose schema.json declares 1 GiB: refused from the zip directory (the
    member is never opened)."""
    from gearshot.estimator.persistence import MAX_SCHEMA_BYTES, load_estimator

    path = tmp_path / "big.skops"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("schema.json", b"{}")
    data = bytearray(path.read_bytes())
    central = data.index(b"PK\x01\x02")
    data[central + 24: central + 28] = (2**30).to_bytes(4, "little")  # uncompressed size
    path.write_bytes(bytes(data))
    assert zipfile.ZipFile(path).getinfo("schema.json").file_size == 2**30 > MAX_SCHEMA_BYTES

    def never(*args, **kwargs):
        raise AssertionError("a member was opened")

    monkeypatch.setattr(zipfile.ZipFile, "open", never)
    with pytest.raises(GearshotError, match="schema.json of 1073741824 bytes"):
        load_estimator(path)


# ----------------------------------------- 4. indicators: batches and outputs

@pytest.fixture(scope="module")
def phm(tmp_path_factory):
    """Cropped PHM09 spur records (1.5 s) at 30 and 40 Hz, an unreadable file and a
    record too short for one revolution."""
    folder = tmp_path_factory.mktemp("phm")
    files = {"30": _crop("spur2_30hz_High_1.zip", folder, 100_000),
             "40": _crop("spur3_40hz_High_1.zip", folder, 100_000),
             "short": folder / "spur1_30hz_High_1.zip"}
    with zipfile.ZipFile(PHM / "spur1_30hz_High_1.zip") as zf:
        member = zf.namelist()[0]
        head = zf.read(member).splitlines(keepends=True)[:50]
    with zipfile.ZipFile(files["short"], "w") as zf:
        zf.writestr(member, b"".join(head))
    files["bad"] = folder / "broken.zip"
    files["bad"].write_bytes(b"not a zip file")
    return files


def test_a_batch_goes_on_past_bad_records(phm, tmp_path, monkeypatch, capsys):
    out = tmp_path / "ind.json"
    code, stdout, err = gearshot(monkeypatch, capsys, "indicators", "--machine", SPUR,
                                 "--shaft", "input", "--sensor", "acc_input", phm["30"],
                                 phm["bad"], phm["short"], phm["40"], "--json", out)
    lines = err.strip().splitlines()
    assert code == 2 and "Traceback" not in err
    assert len(lines) == 3 and all(ln.startswith("gearshot: error:") for ln in lines), err
    assert "broken.zip" in lines[0] and "spur1_30hz_High_1.zip" in lines[1]
    assert "2 of 4 recording(s) failed" in lines[2]
    payload = json.loads(out.read_text())
    assert [r["file"] for r in payload["records"]] == ["spur2_30hz_High_1.zip",
                                                       "spur3_40hz_High_1.zip"]
    assert [Path(f["file"]).name for f in payload["failures"]] == ["broken.zip",
                                                                   "spur1_30hz_High_1.zip"]
    assert "spur3_40hz_High_1.zip" in stdout


def test_a_batch_of_only_bad_records_writes_nothing(phm, tmp_path, monkeypatch, capsys):
    out = tmp_path / "ind.json"
    code, _, err = gearshot(monkeypatch, capsys, "indicators", "--machine", SPUR, "--shaft",
                            "input", phm["bad"], phm["short"], "--json", out)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 3 and "none of the 2 recording(s)" in lines[-1]
    assert not out.exists()
    code, _, err = gearshot(monkeypatch, capsys, "indicators", "--machine", SPUR, "--shaft",
                            "input", phm["bad"], "--json", out)
    one_line(code, err, "broken.zip")                  # one record: its own error alone
    assert not out.exists()


def test_record_indicators_raises_by_default_and_collects_on_request(phm):
    from gearshot import Machine
    from gearshot.app.indicators import record_indicators

    machine = Machine.from_toml(SPUR)
    with pytest.raises(GearshotError, match="broken.zip"):
        record_indicators([phm["bad"], phm["30"]], machine, shaft="input",
                          sensors=["acc_input"])
    payload = record_indicators([phm["bad"], phm["30"]], machine, shaft="input",
                                sensors=["acc_input"], errors="collect")
    assert len(payload["records"]) == 1 and len(payload["failures"]) == 1
    with pytest.raises(GearshotError, match="errors must be"):
        record_indicators([phm["30"]], machine, shaft="input", errors="ignore")


def test_indicators_on_a_full_disk_leave_neither_json_nor_figures(phm, tmp_path, monkeypatch,
                                                                  capsys):
    """The third figure hits a full disk: no JSON, no figure, no temporary is left."""
    from matplotlib.figure import Figure

    real = Figure.savefig
    calls = []

    def full_disk(self, *args, **kwargs):
        calls.append(1)
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", full_disk)
    figs, out = tmp_path / "figs", tmp_path / "ind.json"
    code, _, err = gearshot(monkeypatch, capsys, "indicators", "--machine", SPUR, "--shaft",
                            "input", "--sensor", "acc_input", phm["30"], "--json", out,
                            "--out", figs)
    assert code != 0 and "No space left" in err and "Traceback" not in err, err
    assert len(calls) == 3
    assert not out.exists()
    assert not figs.exists() or not list(figs.rglob("*"))
    assert not [p for p in tmp_path.rglob("*") if ".tmp" in p.name]
    monkeypatch.setattr(Figure, "savefig", real)       # the same run on a healthy disk
    code, _, err = gearshot(monkeypatch, capsys, "indicators", "--machine", SPUR, "--shaft",
                            "input", "--sensor", "acc_input", phm["30"], "--json", out,
                            "--out", figs)
    assert code == 0, err
    assert out.is_file() and len(list(figs.glob("*.png"))) == 12
    assert not [p for p in tmp_path.rglob("*") if ".tmp" in p.name]


def test_speed_hints_find_each_tacho_free_record_at_its_own_speed(phm, tmp_path, monkeypatch,
                                                                  capsys):
    """One machine file without a tacho, records at 30 and 40 Hz: FILE@HZ and --speed-hint
    give each its nominal speed; the speeds agree with the tacho's within 0.2 %."""
    out_tacho, out_hint = tmp_path / "tacho.json", tmp_path / "hint.json"
    code, _, err = gearshot(monkeypatch, capsys, "indicators", "--machine", SPUR, "--shaft",
                            "input", "--sensor", "acc_input", phm["30"], phm["40"],
                            "--json", out_tacho)
    assert code == 0, err
    code, _, err = gearshot(monkeypatch, capsys, "indicators", "--machine", SPUR_NOTACHO,
                            "--shaft", "input", "--sensor", "acc_input", f"{phm['30']}@30",
                            phm["40"], "--speed-hint", "40", "--json", out_hint)
    assert code == 0, err
    tacho = json.loads(out_tacho.read_text())["records"]
    hint = json.loads(out_hint.read_text())["records"]
    assert [r["speed_source"] for r in hint] == ["vibration", "vibration"]
    for t, h in zip(tacho, hint):
        assert h["tacho_speed_hz"] == pytest.approx(t["tacho_speed_hz"], rel=2e-3)


@pytest.mark.parametrize("args, words", [
    (["{30}@30"], ["speed hint", "has one"]),
    (["{30}@fast"], ["'@'", "'fast'"]),
    (["{30}", "--speed-hint", "1e9"], ["speed hint", "1e+09"]),
])
def test_bad_speed_hints_are_refused(args, words, phm, monkeypatch, capsys):
    machine = SPUR if "has one" in words else SPUR_NOTACHO
    args = [a.replace("{30}", str(phm["30"])) for a in args]
    code, _, err = gearshot(monkeypatch, capsys, "indicators", "--machine", machine,
                            "--shaft", "input", *args)
    one_line(code, err, *words)


# ------------------------------------------------------ 5. progress as promised
class _Lines(io.StringIO):
    """A stream that counts its lines and says when it holds ``wanted`` of them."""

    def __init__(self, wanted: int):
        super().__init__()
        self.wanted, self.enough = wanted, threading.Event()

    def write(self, text: str) -> int:
        n = super().write(text)
        if self.getvalue().count("\n") >= self.wanted:
            self.enough.set()
        return n


def test_a_progress_line_comes_while_no_step_ends():
    from gearshot._progress import PlainProgress

    stream = _Lines(3)
    bar = PlainProgress("simulating blocks", 4, stream=stream, interval=0.05)
    try:
        assert stream.enough.wait(120), stream.getvalue()   # a guard against a hang only
    finally:
        bar.close()
    lines = stream.getvalue().splitlines()
    assert all(ln.startswith("simulating blocks: 0/4 (0 %)") for ln in lines)
    assert all(ln.endswith("ETA not yet known") for ln in lines)


def test_the_eta_waits_for_two_steps_and_ten_seconds():
    from gearshot._progress import PlainProgress

    clock = iter([0.0, 0.0, 20.0, 21.0, 22.0, 40.0]).__next__
    stream = io.StringIO()
    bar = PlainProgress("blocks", 10, stream=stream, interval=0.0, clock=clock)
    bar.advance()                  # 1 step at 20 s: not yet
    clock2 = iter([0.0, 0.0, 3.0, 5.0]).__next__
    quick = PlainProgress("blocks", 10, stream=stream, interval=0.0, clock=clock2)
    quick.advance()
    quick.advance()                # 2 steps in 5 s: not yet
    bar.advance()                  # 2 steps at 21 s: 10.5 s per step, 8 to go
    lines = stream.getvalue().splitlines()
    assert lines[1].endswith("1/10 (10 %), elapsed 20s, ETA not yet known")
    assert lines[4].endswith("2/10 (20 %), elapsed 5s, ETA not yet known")
    assert lines[5].endswith("2/10 (20 %), elapsed 21s, ETA 1m24s")


def test_quiet_silences_progress_and_verbose_shows_the_traceback(monkeypatch, capsys):
    import gearshot._progress as progress_module
    import gearshot.app.simulate as simulate

    seen = []

    def fake_build(store, **kwargs):
        with progress_module.progress("simulating blocks", 2) as bar:
            seen.append(type(bar).__name__)
            bar.advance(2)

    monkeypatch.setattr(simulate, "simulate_database", fake_build)
    code, _, err = gearshot(monkeypatch, capsys, "-q", "simulate", "--store", "/tmp/x-never")
    assert code == 0 and seen == ["_Silent"] and "simulating" not in err
    code, _, err = gearshot(monkeypatch, capsys, "simulate", "--store", "/tmp/x-never")
    assert code == 0 and seen[-1] == "PlainProgress" and "simulating blocks: 2/2" in err
    code, _, err = gearshot(monkeypatch, capsys, "--verbose", "--quiet", "rig", "x")
    one_line(code, err, "--verbose", "--quiet")

    def bug(store, **kwargs):
        raise RuntimeError("an unexpected state")

    monkeypatch.setattr(simulate, "simulate_database", bug)
    code, _, err = gearshot(monkeypatch, capsys, "simulate", "--store", "/tmp/x-never")
    assert code == 3 and "a bug: please report it" in err and "Traceback" not in err
    with pytest.raises(RuntimeError, match="an unexpected state"):
        gearshot(monkeypatch, capsys, "-v", "simulate", "--store", "/tmp/x-never")


@pytest.mark.parametrize("flag", ["-V", "--version"])
def test_version_flags(flag, monkeypatch, capsys):
    from gearshot import __version__

    code, out, _ = gearshot(monkeypatch, capsys, flag)
    assert code == 0 and out.strip() == f"gearshot {__version__}"


HELP = [[], ["demo"], ["simulate"], ["rig"], ["experiment", "simulated"],
        ["experiment", "rig"], ["experiment", "rig-family"], ["predict"], ["indicators"],
        ["report"]]


@pytest.mark.parametrize("sub", HELP, ids=lambda s: " ".join(s) or "root")
def test_help_shows_flags_as_flags(sub, monkeypatch, capsys):
    monkeypatch.setenv("COLUMNS", "200")
    code, out, _ = gearshot(monkeypatch, capsys, *sub, "--help")
    assert code == 0 and "Usage" in out
    assert "<bool>" not in out and "--help" in out
    if sub == ["simulate"]:
        paired = next(ln for ln in out.splitlines() if "--paired" in ln)
        assert "--no-paired" in paired and "<" not in paired
        assert "<list[float]>" in next(ln for ln in out.splitlines() if "--speed " in ln)


@pytest.mark.parametrize("option, value", [("--false-alarm-rate", "0.7"),
                                           ("--false-alarm-rate", "0"), ("--sustain", "0")])
def test_fit_refuses_a_bad_alarm_option_before_fitting(tmp_path, monkeypatch, capsys, option,
                                                       value):
    """``gearshot fit --false-alarm-rate/--sustain`` out of range: one line naming the
    option, before the database or any recording is read."""
    import gearshot.app.predict_fit as predict_fit

    def never(*args, **kwargs):
        raise LongWork("the fit started")

    monkeypatch.setattr(predict_fit, "fit_from_files", never)
    healthy = [tmp_path / f"h{k}.h5" for k in range(2)]
    for path in healthy:
        path.write_bytes(b"")
    code, _, err = gearshot(monkeypatch, capsys, "fit", "--database", tmp_path / "db",
                            "--speed", "15", "--healthy", *healthy,
                            "--model", tmp_path / "m.skops", option, value)
    one_line(code, err, option)
    assert not (tmp_path / "m.skops").exists()
