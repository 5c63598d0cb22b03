"""The gearshot command: help everywhere, one-line errors without tracebacks."""

import subprocess
import sys

import pytest

SUBCOMMANDS = [[], ["demo"], ["simulate"], ["rig"], ["experiment"], ["experiment", "simulated"],
               ["experiment", "rig"], ["experiment", "rig-family"], ["predict"], ["report"]]


def run(*args, env=None):
    return subprocess.run([sys.executable, "-m", "gearshot.app.cli", *args], capture_output=True,
                          text=True, timeout=120, env=env)


@pytest.mark.parametrize("sub", SUBCOMMANDS, ids=lambda s: " ".join(s) or "root")
def test_help_on_every_subcommand(sub):
    res = run(*sub, "--help")
    assert res.returncode == 0, res.stderr
    assert "Usage" in res.stdout


def test_version():
    res = run("--version")
    assert res.returncode == 0 and res.stdout.startswith("gearshot ")


@pytest.mark.parametrize(
    "args, words",
    [
        (["report", "/nonexistent/results.json"], ["results.json", "does not exist"]),
        (["rig", "/tmp/x", "--frf-folder", "/nonexistent/frfs"], ["--frf-folder"]),
        (["rig", "/tmp/x", "--rig-grade", "13"], ["--rig-grade", "13"]),
        (["rig", "/tmp/x", "--variation", "0.5"], ["--variation", "0.5"]),
        (["experiment", "simulated", "--frf-folder", "/nonexistent"], ["--frf-folder"]),
        (["predict", "--database", "/nonexistent/db", "--healthy", "/nonexistent/h.h5",
          "--faulty", "/nonexistent/f.h5", "--faulty-size", "0.5", "--recordings", "/tmp",
          "--speed", "15", "--load", "10"], ["h.h5", "does not exist"]),
        (["simulate", "--speed", "-3", "--grade", "7", "--store", "/tmp/gs-never"],
         ["speed", "-3"]),
        (["simulate", "--fault-type", "rust", "--grade", "7", "--store", "/tmp/gs-never"],
         ["fault_type", "rust"]),
        (["experiment", "rig-family", "--range", "test"], ["--range", "'test'"]),
        (["experiment", "rig-family", "--variant", "magic"], ["--variant", "'magic'"]),
        (["experiment", "rig-family", "--draws", "0"], ["--draws", "0"]),
        (["experiment", "rig-family", "--n-rigs", "25"], ["--n-rigs", "25"]),
        (["experiment", "rig-family", "--param", "tf_exponent=0.5"], ["--param",
                                                                      "'tf_exponent'"]),
        (["experiment", "rig-family", "--param", "model_discrepancy=-1"],
         ["--param", "model_discrepancy", "-1"]),
        (["experiment", "rig-family", "--param", "simulated_reference"],
         ["--param", "NAME=VALUE"]),
        (["experiment", "rig", "--param", "nope=1", "--store", "/tmp/gs-never"],
         ["--param", "'nope'"]),
    ],
)
def test_user_errors_are_one_line_without_traceback(args, words, tmp_path):
    res = run(*args)
    assert res.returncode != 0
    assert "Traceback" not in res.stderr
    err = res.stderr.strip()
    assert err.startswith("gearshot: error:"), err
    assert len(err.splitlines()) == 1, err
    for word in words:
        assert word in err, err


def test_bad_option_value_is_a_usage_error():
    res = run("simulate", "--n-healthy", "many")
    assert res.returncode == 2
    assert "Traceback" not in res.stderr
