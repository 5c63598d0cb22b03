"""Issue #20, the real-machine journey: each friction point a new user met, as a test
(CLI runs on cropped copies of the PHM09 records in ../shared/data/phm09)."""

from __future__ import annotations

import io
import json
import os
import stat
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from phm09_records import crop

from gearshot import GearshotError

ROOT = Path(__file__).resolve().parents[1]
SPUR = ROOT / "examples" / "machines" / "phm09_spur.toml"
PHM = ROOT.parent / "shared" / "data" / "phm09"


def run(*args, env=None, timeout=600, cwd=None):
    return subprocess.run([sys.executable, "-m", "gearshot.app.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=timeout, env=env, cwd=cwd)


def one_line_error(res) -> str:
    err = res.stderr.strip()
    assert res.returncode == 2, (res.returncode, err)
    assert "Traceback" not in err and err.startswith("gearshot: error:"), err
    assert len(err.splitlines()) == 1, err
    return err



@pytest.fixture(scope="module")
def small(tmp_path_factory):
    folder = tmp_path_factory.mktemp("phm")
    return {n: crop(f"{n}_30hz_High_1.zip", folder) for n in ("spur1", "spur2", "spur3")}


# --- 1. several files after one flag, folders, globs ------------------------------------

def test_several_files_after_one_option_are_spread():
    from gearshot.app.files import spread_file_options

    argv = ["predict", "--healthy", "a.zip", "b.zip", "--faulty", "f.zip", "--recordings",
            "c.zip", "d", "--speed", "-3", "--", "--healthy", "x"]
    assert spread_file_options(argv) == [
        "predict", "--healthy", "a.zip", "--healthy", "b.zip", "--faulty", "f.zip",
        "--recordings", "c.zip", "--recordings", "d", "--speed", "-3", "--", "--healthy", "x"]
    # `gearshot rig --healthy 6 FOLDER`: a count, and FOLDER stays the argument
    assert spread_file_options(["rig", "--healthy", "6", "out"]) == ["rig", "--healthy", "6",
                                                                      "out"]
    assert spread_file_options(["indicators", "--baseline", "h1", "h2"]) == [
        "indicators", "--baseline", "h1", "--baseline", "h2"]


def test_healthy_takes_several_files_on_the_command_line(small, tmp_path):
    """`--healthy a b` once stopped with "Got unexpected extra argument(s)"; now the second
    file is read as a healthy recording (and named when it is missing)."""
    res = run("predict", "--database", tmp_path / "db", "--healthy", small["spur1"],
              tmp_path / "missing.zip", "--faulty", small["spur2"], "--faulty-size", "0.5",
              "--recordings", small["spur3"], "--speed", "15")
    err = one_line_error(res)
    assert "--healthy" in err and "missing.zip" in err and "does not exist" in err


def test_folders_and_glob_patterns_expand_to_recordings(small, tmp_path):
    from gearshot.app.files import expand_recordings

    folder = small["spur1"].parent
    (folder / "notes.txt.bak").write_text("not a recording")
    got = expand_recordings([folder, str(folder / "spur[12]_*.zip"), small["spur3"]],
                            "--recordings")
    assert [p.name for p in got] == ["spur1_30hz_High_1.zip", "spur2_30hz_High_1.zip",
                                     "spur3_30hz_High_1.zip"]  # each once, in order
    with pytest.raises(GearshotError, match=r"--healthy '.*nothing\*\.zip' matches no file"):
        expand_recordings([str(tmp_path / "nothing*.zip")], "--healthy")
    with pytest.raises(GearshotError, match="--recordings .* folder without recording files"):
        expand_recordings([tmp_path], "--recordings")


def test_indicators_baseline_takes_several_files(small, tmp_path):
    out = tmp_path / "i.json"
    res = run("indicators", "--machine", SPUR, "--shaft", "input", "--sensor", "acc_input",
              small["spur2"], "--baseline", small["spur1"], small["spur3"], "--json", out)
    assert res.returncode == 0, res.stderr
    with_two = json.loads(out.read_text())["records"][0]["indicators"]["na4"]
    res = run("indicators", "--machine", SPUR, "--shaft", "input", "--sensor", "acc_input",
              small["spur2"], "--baseline", small["spur1"], "--json", out)
    assert res.returncode == 0, res.stderr
    assert json.loads(out.read_text())["records"][0]["indicators"]["na4"] != with_two


# --- 2. what --faulty-size means ---------------------------------------------------------

def test_faulty_size_is_explained_per_fault_type():
    res = run("predict", "--help")
    text = " ".join(res.stdout.split())
    for word in ("ftff", "partial_face", "breakage", "destruction", "chipped"):
        assert word in text, word


# --- 3. self-describing outputs ------------------------------------------------------------

def test_plain_predict_marks_each_row_with_its_role(small):
    from gearshot.app.predict import _roles, summary_table

    fitted = {small["spur1"].resolve()}
    assert _roles(small["spur1"], 3, fitted, small["spur2"]) == ["healthy_fitted"] * 3
    assert _roles(small["spur2"], 3, fitted, small["spur2"]) == ["example", "faulty_rest",
                                                                 "faulty_rest"]
    assert _roles(small["spur3"], 2, fitted, small["spur2"]) == ["test", "test"]
    frame = pd.DataFrame({"recording": ["/x/b.zip", "/x/b.zip", "/x/a.zip"],
                          "role": ["test", "test", "healthy_fitted"],
                          "predicted": [0.2, 0.4, 0.0], "low": [0.1, 0.3, 0.0],
                          "high": [0.3, 0.5, 0.1]})
    table = summary_table(frame)
    assert list(table.columns) == ["recording", "role", "segments", "mean estimated size",
                                   "mean low", "mean high"]
    assert list(table["role"]) == ["healthy_fitted", "test"]   # fit roles first
    assert table.loc[table["role"] == "test", "mean estimated size"].item() == \
        pytest.approx(0.3)


def test_indicators_json_names_machine_shaft_speeds_sensors_units(small, tmp_path):
    out = tmp_path / "i.json"
    res = run("indicators", "--machine", SPUR, "--shaft", "idler", small["spur2"], "--json",
              out)
    assert res.returncode == 0, res.stderr
    payload = json.loads(out.read_text())
    assert payload["machine"] == "PHM09 gearbox, spur train" and payload["shaft"] == "idler"
    assert payload["tacho_shaft"] == "input"
    assert payload["machine_file"] == str(SPUR)
    assert [r["sensor"] for r in payload["records"]] == ["acc_input", "acc_output"]  # all
    for rec in payload["records"]:
        assert 29.0 < rec["tacho_speed_hz"] < 30.0
        assert rec["shaft_speed_hz"] == pytest.approx(rec["tacho_speed_hz"] * 32 / 96)
    units = payload["units"]["indicators"]["acc_input"]
    assert units["rms_raw"] == "g" and units["rms_diff"] == "g" and units["fm4"] == "1"
    assert payload["units"]["speeds"].startswith("Hz")


def test_indicators_figures_without_json(small, tmp_path):
    figs = tmp_path / "figs"
    res = run("indicators", "--machine", SPUR, "--shaft", "input", small["spur2"], "--out",
              figs)
    assert res.returncode == 0, res.stderr
    assert (figs / "fm4.png").stat().st_size > 0 and not list(tmp_path.glob("*.json"))


def test_written_files_keep_the_user_umask(tmp_path):
    from gearshot._atomic import atomic_dir, write_text_atomic

    old = os.umask(0o022)
    try:
        write_text_atomic(tmp_path / "a.txt", "x")
        with atomic_dir(tmp_path / "block") as d:
            (d / "f").write_text("y")
        os.umask(0o077)
        write_text_atomic(tmp_path / "b.txt", "x")
    finally:
        os.umask(old)
    assert stat.S_IMODE((tmp_path / "a.txt").stat().st_mode) == 0o644
    assert stat.S_IMODE((tmp_path / "block").stat().st_mode) == 0o755
    assert stat.S_IMODE((tmp_path / "b.txt").stat().st_mode) == 0o600


def test_cli_outputs_are_readable_by_the_group_under_umask_022(small, tmp_path):
    out = tmp_path / "i.json"
    res = subprocess.run(["bash", "-c", f"umask 022 && {sys.executable} -m gearshot.app.cli "
                          f"indicators --machine {SPUR} --shaft input --sensor acc_input "
                          f"{small['spur2']} --json {out} --out {tmp_path / 'f'}"],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    for path in (out, tmp_path / "f" / "fm4.png"):
        assert stat.S_IMODE(path.stat().st_mode) == 0o644, path


def test_indicator_figures_go_through_the_atomic_writer(small, tmp_path, monkeypatch):
    """A full disk while saving a PNG leaves no 0-byte or partial file behind."""
    from matplotlib.figure import Figure

    from gearshot import Machine
    from gearshot.app.indicators import indicator_figures, record_indicators

    payload = record_indicators([small["spur2"]], Machine.from_toml(SPUR), shaft="input",
                                sensors=["acc_input"])

    def full_disk(self, fname, **kw):
        Path(fname).write_bytes(b"\x89PNG partial")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Figure, "savefig", full_disk)
    with pytest.raises(GearshotError, match="No space left on device"):
        indicator_figures(payload, tmp_path)
    assert list(tmp_path.iterdir()) == []


# --- 4. gearshot report on every JSON gearshot writes --------------------------------------

def _family_payload():
    frame = pd.DataFrame({"mae": [10.0, 12.0]}, index=pd.Index(["full", "no_tuning"],
                                                               name="variant"))
    check = pd.DataFrame({"fits": [48.0], "passed %": [72.917], "MAE passed": [5.542],
                          "MAE refused": [16.198], "coverage passed": [94.405],
                          "width passed": [0.344]}, index=["full"])
    return {"experiment": "rig-family", "range": "dev", "seeds": [100, 101], "draws": 2,
            "params": {}, "results": "x.jsonl",
            "tables": {"condition": json.loads(frame.to_json(orient="split")),
                       "check": json.loads(check.to_json(orient="split"))}}


@pytest.mark.parametrize("kind", ["demo", "rig", "rig-family", "predict", "indicators"])
def test_report_reads_every_json_gearshot_writes(kind, small, tmp_path):
    path = tmp_path / f"{kind}.json"
    if kind == "demo":   # the demo's results.json (its summary)
        payload = {"speed": 15.0, "load": 10.0, "seed": 0, "draws": 5, "mae": 11.0,
                   "mae_std": 2.0, "ablations": {"before_da": 30.0, "full": 11.0},
                   "ablations_std": {"before_da": 4.0, "full": 2.0}, "grade": 7,
                   "rig_grade": 6, "selected_features": ["rms_diff"], "n_neighbors": 5}
    elif kind == "rig":
        payload = {"experiment": "rig", "speed": 15.0, "load": 10.0, "params": {},
                   "mae": 11.0, "ablations": {"full": 11.0},
                   "rows": [{"variant": v, "repeat": r, "mae": m}
                            for v, m in (("full", 0.1), ("before_da", 0.3)) for r in (0, 1)]}
    elif kind == "rig-family":
        payload = _family_payload()
    elif kind == "predict":   # as `predict --out X.json` writes it (orient="records")
        payload = [{"recording": "/d/a.zip", "role": "test", "segment": k,
                    "predicted": 0.3, "low": 0.1, "high": 0.5} for k in range(3)]
    else:
        res = run("indicators", "--machine", SPUR, "--shaft", "input", small["spur2"],
                  "--json", path)
        assert res.returncode == 0, res.stderr
    if kind != "indicators":
        path.write_text(json.dumps(payload))
    out = tmp_path / "rep"
    res = run("report", path, "--out", out)
    assert res.returncode == 0, res.stderr
    text = (out / "report.md").read_text()
    assert text.startswith("# gearshot report")
    want = {"demo": "± 2.0", "rig": "full", "rig-family": "no_tuning", "predict": "a.zip",
            "indicators": "acc_output"}[kind]
    assert want in text, text
    assert list(out.glob("*.png")), "a figure"
    if kind == "rig-family":   # the fits' verdicts, titled, their width not rounded away
        assert "## The fits' own check (`--checked`)" in text
        assert "| full | 48 | 72.9 | 5.54 | 16.2 | 94.4 | 0.344 |" in text, text


@pytest.mark.parametrize("content", ['{"hello": 1}', "[1, 2]", "not json at all"])
def test_report_refuses_other_files_with_one_line(content, tmp_path):
    path = tmp_path / "other.json"
    path.write_text(content)
    err = one_line_error(run("report", path, "--out", tmp_path / "rep"))
    assert "other.json" in err


# --- 5. progress off a terminal; a light one-record path --------------------------------

def test_plain_progress_lines_carry_percent_and_eta():
    from gearshot._progress import PlainProgress

    clock = iter([0.0, 0.0, 5.0, 12.0, 24.0, 30.0]).__next__
    stream = io.StringIO()
    bar = PlainProgress("simulating blocks", 4, completed=1, stream=stream, interval=10,
                        clock=clock)
    for _ in range(3):
        bar.advance()
    lines = stream.getvalue().splitlines()
    assert lines[0] == "simulating blocks: 1/4 (25 %), elapsed 0s, ETA not yet known"
    # the step at 5 s is within the interval: no line; 2 steps in 12 s: 6 s for the last
    assert lines[1] == "simulating blocks: 3/4 (75 %), elapsed 12s, ETA 6s"
    assert lines[2] == "simulating blocks: 4/4 (100 %), elapsed 24s, done"
    assert len(lines) == 3


def test_simulate_prints_progress_when_output_is_not_a_terminal(tmp_path):
    res = run("simulate", "--store", tmp_path / "db", "--grade", "7", "--grade", "8",
              "--n-healthy", "2", "--n-faulty", "2", "--workers", "1",
              env={**os.environ, "GEARSHOT_DATA": str(tmp_path / "data")})
    assert res.returncode == 0, res.stderr
    lines = [ln for ln in res.stderr.splitlines() if ln.startswith("simulating blocks")]
    assert lines[0].startswith("simulating blocks: 0/2 (0 %)")
    assert lines[-1].startswith("simulating blocks: 2/2 (100 %)") and "done" in lines[-1]


def test_one_record_indicators_path_imports_no_heavy_package(small):
    code = (f"import sys; from gearshot.app import cli; from gearshot import Machine; "
            f"from gearshot.io import Recording; from gearshot.app.indicators import "
            f"record_indicators; m = Machine.from_toml({str(SPUR)!r}); "
            f"record_indicators([{str(small['spur2'])!r}], m, shaft='input'); "
            f"print(sorted(k for k in ('dask', 'xarray', 'zarr', 'matplotlib', 'numba', "
            f"'scipy.signal', 'h5py', 'sklearn', 'pandas') if k in sys.modules))")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "[]"


# --- 6. every option described; usage errors as one line --------------------------------

def test_every_cli_option_is_described():
    import typer

    from gearshot.app.cli import app

    missing = []

    def walk(command, path):
        for name, sub in getattr(command, "commands", {}).items():
            walk(sub, [*path, name])
        for param in getattr(command, "params", []):
            if not (getattr(param, "help", None) or "").strip():
                missing.append(f"{' '.join(path)} {param.opts}")

    walk(typer.main.get_command(app), ["gearshot"])
    assert missing == []


@pytest.mark.parametrize("args, words", [
    (["simulate", "--n-healthy", "many"], ["--n-healthy", "simulate --help"]),
    (["predict", "--database", "x"], ["Missing option", "predict --help"]),
    (["simulate", "--no-such-option"], ["--no-such-option"]),
    (["frobnicate"], ["frobnicate"]),
    (["report", "a.json", "b.json"], ["unexpected extra argument"]),
])
def test_usage_errors_are_one_line(args, words):
    err = one_line_error(run(*args))
    for w in words:
        assert w in err, err


# --- 8. indicator ranking from labels ------------------------------------------------------

def test_labels_rank_the_indicators_per_cell_and_overall(small, tmp_path):
    labels = tmp_path / "labels.csv"
    labels.write_text("file,label\nspur1_30hz_High_1.zip,good\nspur2_30hz_High_1.zip,"
                      "chipped\nspur3_30hz_High_1.zip,0\n")
    figs = tmp_path / "figs"
    res = run("indicators", "--machine", SPUR, "--shaft", "input", *small.values(),
              "--labels", labels, "--out", figs, "--json", tmp_path / "i.json")
    assert res.returncode == 0, res.stderr
    ranking = pd.read_csv(figs / "ranking.csv")
    assert list(ranking.columns) == ["sensor", "indicator", "direction", "separation",
                                     "auc_overall", "auc[30 Hz]", "n_healthy", "n_faulty"]
    # the ten condition indicators and the two extras (rms_raw, rms_residual), per sensor;
    # the estimator's order-band features are not indicators
    assert len(ranking) == 2 * 12 and not ranking["indicator"].str.startswith("band").any()
    assert (ranking["n_faulty"] == 1).all()
    row = ranking[(ranking["sensor"] == "acc_input")
                  & (ranking["indicator"] == "kurtosis_diff")].iloc[0]
    assert row["auc_overall"] == 1.0     # the chip raises the kurtosis above both good ones
    assert np.allclose(ranking["separation"], np.abs(2 * ranking["auc_overall"] - 1))
    assert (figs / "ranking.png").stat().st_size > 0
    assert "indicator ranking" in res.stdout
    assert json.loads((tmp_path / "i.json").read_text())["ranking"][0]["separation"] == 1.0


def test_labels_need_both_classes_and_every_file(small, tmp_path):
    from gearshot.app.ranking import read_labels

    path = tmp_path / "l.csv"
    path.write_text("file,label\nspur1_30hz_High_1.zip,good\n")
    with pytest.raises(GearshotError, match="no label for.*spur2"):
        read_labels(path, ["spur1_30hz_High_1.zip", "spur2_30hz_High_1.zip"])
    with pytest.raises(GearshotError, match="both classes"):
        read_labels(path, ["spur1_30hz_High_1.zip"])
    path.write_text("name,label\n")
    with pytest.raises(GearshotError, match="needs columns file and label"):
        read_labels(path)


# --- 9. figures ---------------------------------------------------------------------------

def test_figures_carry_units_spread_and_honest_titles():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gearshot import plotting

    fig, ax = plt.subplots()
    bars = plotting.plot_ablation({"before_da": 0.30, "rms_only_with_a_long_name": 0.20,
                                   "full": 0.11}, ax=ax,
                                  spread={"before_da": 0.05, "full": 0.02}, draws=5)
    assert "over 5 draws" in ax.get_ylabel()
    assert ax.get_ylim()[1] > 35.0 * 1.1          # room above the tallest bar + its error
    assert bars.errorbar is not None
    assert [t.get_text() for t in ax.texts][0] == "30.0 ± 5.0"
    fig.canvas.draw()
    labels_box = [t.get_window_extent() for t in ax.get_xticklabels()]
    assert all(b.x0 >= 0 for b in labels_box)     # rotated labels anchored at their end
    plt.close(fig)

    fig, ax = plt.subplots()
    spec = np.abs(np.fft.fft(np.random.default_rng(0).normal(size=4096)))
    plotting.plot_spectrum_background(spec, spec, ax=ax, samples_per_cycle=2048)
    assert "order" in ax.get_xlabel() and "[g]" in ax.get_ylabel()
    assert ax.lines[0].get_xdata()[-1] == pytest.approx(1024.0)   # orders, not bins
    plt.close(fig)

    fig, ax = plt.subplots()
    sa = np.sin(2 * np.pi * 17 * np.arange(256) / 256)
    plotting.plot_sa_and_difference(sa, 17, ax=ax, fault_size=0.66)
    assert "[g]" in ax.get_ylabel() and "0.66" in ax.get_title()
    plt.close(fig)

    fig, ax = plt.subplots()
    plotting.plot_predicted_vs_true([0.3, 0.6], [0.4, 0.6], ax=ax,
                                    title="draw 1 of 5: MAE {mae} %")
    assert ax.get_title() == "draw 1 of 5: MAE 5.0 %"
    plt.close(fig)

    fig, ax = plt.subplots()
    h = np.ones(64, complex)
    plotting.plot_tf_estimate(h, 2 * h * np.where(np.arange(64) < 16, 1.0, 0.5), ax=ax)
    assert "RMS difference" in ax.get_title() and "dB" in ax.get_title()
    plt.close(fig)
