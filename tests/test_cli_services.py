"""The thin command line's pieces (issue #21 item 5): the Dask client context, the cached
rig campaign, the paper's rig defaults, and a start-up that imports nothing heavy."""

import json
import subprocess
import sys

import pytest

from gearshot import GearshotError, paper
from gearshot.app.campaigns import CACHE_MANIFEST, cached_campaign, folder_digest

HEAVY = ("dask", "distributed", "xarray", "zarr", "sklearn", "matplotlib", "scipy", "pandas",
         "numba", "h5py")


def _imported_after(code: str) -> list[str]:
    probe = (f"import sys\n{code}\n"
             f"print(sorted(k for k in {HEAVY!r} if k in sys.modules))")
    res = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                         timeout=120)
    assert res.returncode == 0, res.stderr
    return json.loads(res.stdout.strip().splitlines()[-1].replace("'", '"'))


def test_importing_the_cli_imports_no_heavy_library():
    assert _imported_after("import gearshot.app.cli") == []


@pytest.mark.parametrize("argv", [["--help"], ["indicators", "--help"],
                                  ["experiment", "rig", "--help"], ["predict", "--help"]])
def test_help_imports_no_heavy_library(argv):
    code = (f"from gearshot.app.cli import main\nsys.argv = ['gearshot', *{argv!r}]\n"
            f"try:\n    main()\nexcept SystemExit:\n    pass")
    assert _imported_after(code) == []


def test_python_dash_m_gearshot_is_the_command():
    res = subprocess.run([sys.executable, "-m", "gearshot", "--version"], capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 0 and res.stdout.startswith("gearshot ")
    res = subprocess.run([sys.executable, "-m", "gearshot", "rig", "/tmp/x", "--rig-grade",
                          "13"], capture_output=True, text=True, timeout=120)
    assert res.returncode == 2
    assert res.stderr.strip() == "gearshot: error: --rig-grade must be 1 … 12; got 13"


def test_rig_defaults_are_the_papers():
    """`gearshot rig` and `experiment rig` default to Table 1's campaign at the first rig
    condition, read from gearshot.paper (not re-typed in the CLI)."""
    import typer

    from gearshot.app.cli import app

    cmd = typer.main.get_command(app)
    rig = {p.name: p.default for p in cmd.commands["rig"].params}
    assert (rig["speed"], rig["load"]) == paper.RIG_CONDITIONS[0] == (15.0, 10.0)
    assert rig["duration"] == paper.RIG_DURATION == 60.0
    assert rig["healthy"] == paper.RIG_HEALTHY_RECORDINGS == 6
    assert rig["repetitions"] == paper.RIG_REPETITIONS == 6
    assert tuple(rig["size"]) == paper.TABLE1_SIZES
    exp = {p.name: p.default for p in cmd.commands["experiment"].commands["rig"].params}
    assert (exp["speed"], exp["load"], exp["duration"]) == (15.0, 10.0, 60.0)


def test_dask_client_in_process_without_a_cluster():
    from gearshot._cluster import dask_client

    with dask_client(None, workers=1) as client:
        assert client is None
    with dask_client(None, workers=4, needed=False) as client:
        assert client is None


def test_dask_client_closes_its_local_cluster():
    from gearshot._cluster import dask_client

    with dask_client(None, workers=2) as client:
        assert client.submit(sum, [1, 2, 3]).result() == 6
        cluster = client.cluster
        assert len(cluster.workers) == 2
    assert client.status == "closed"
    assert cluster.status.name == "closed"


def test_dask_client_closes_on_error():
    from gearshot._cluster import dask_client

    with pytest.raises(GearshotError, match="boom"):
        with dask_client(None, workers=2) as client:
            raise GearshotError("boom")
    assert client.status == "closed" and client.cluster.status.name == "closed"


def test_cached_campaign_reuses_refuses_and_trusts_user_campaigns(tmp_path):
    calls = []

    def record(folder):
        calls.append(folder)
        folder.mkdir(parents=True)
        (folder / "index.csv").write_text("path,speed,load,fault_size,repetition\n")

    inputs = {"seed": 3, "speed": 15.0, "load": 10.0, "duration": 8.0}
    where = cached_campaign(tmp_path / "camp", inputs, record)
    assert where == tmp_path / "camp" and calls == [where]
    assert json.loads((where / CACHE_MANIFEST).read_text()) == inputs
    assert cached_campaign(where, dict(inputs), record) == where and len(calls) == 1
    with pytest.raises(GearshotError, match=r"--campaign .*camp.* other inputs "
                                            r"\(differs in duration, seed\)"):
        cached_campaign(where, {**inputs, "seed": 4, "duration": 9.0}, record)
    (where / CACHE_MANIFEST).write_text("{not json")
    with pytest.raises(GearshotError, match="unreadable"):
        cached_campaign(where, inputs, record)
    (where / CACHE_MANIFEST).unlink()    # a campaign the user recorded: used as it is
    assert cached_campaign(where, {**inputs, "seed": 9}, record) == where and len(calls) == 1


def test_folder_digest_follows_names_and_bytes(tmp_path):
    (tmp_path / "a.csv").write_text("1,2\n")
    first = folder_digest(tmp_path)
    assert folder_digest(tmp_path) == first and folder_digest(None) is None
    (tmp_path / "a.csv").write_text("1,3\n")
    assert folder_digest(tmp_path) != first
    (tmp_path / "a.csv").write_text("1,2\n")
    assert folder_digest(tmp_path) == first
    (tmp_path / "a.csv").rename(tmp_path / "b.csv")
    assert folder_digest(tmp_path) != first


def test_small_builds_run_in_process_large_ones_on_a_cluster(monkeypatch, tmp_path):
    """`gearshot simulate`: up to IN_PROCESS_BLOCKS blocks in-process (no LocalCluster
    start-up), more on the cluster; the build gets the client dask_client yields."""
    from contextlib import contextmanager

    import gearshot.app.simulate as service
    import gearshot.sim
    from gearshot._cluster import IN_PROCESS_BLOCKS

    asked, given = [], []

    @contextmanager
    def fake_client(scheduler, workers, *, needed):
        asked.append(needed)
        yield "client" if needed else None

    monkeypatch.setattr(service, "dask_client", fake_client)
    monkeypatch.setattr(gearshot.sim, "build_database",
                        lambda store, pair, **kw: given.append(kw["client"]))
    kw = dict(loads=[10.0], n_healthy=2, n_faulty=2, seed=0)
    service.simulate_database(tmp_path / "a", speeds=[15.0], grades=range(1, 13), **kw)
    assert 12 <= IN_PROCESS_BLOCKS
    service.simulate_database(tmp_path / "b", speeds=[10.0, 15.0], grades=range(1, 13), **kw)
    assert asked == [False, True] and given == [None, "client"]


def test_the_paper_s_rig_experiment_fits_the_paper_s_estimator(monkeypatch, tmp_path):
    """`gearshot experiment rig` reproduces Fig. 14: its variants fit the paper's KNN, as
    the demo's ablation table does, unless --param names another estimator."""
    from typer.testing import CliRunner

    from gearshot.app import experiment_runs
    from gearshot.app.cli import app

    seen = []

    def capture(*args, params, **kwargs):
        seen.append(params)
        raise SystemExit(0)

    monkeypatch.setattr(experiment_runs, "run_rig_experiment", capture)
    runner = CliRunner()
    runner.invoke(app, ["experiment", "rig", "--store", str(tmp_path / "db")])
    runner.invoke(app, ["experiment", "rig", "--store", str(tmp_path / "db"),
                        "--param", 'estimator="boosting"', "--param", "model_discrepancy=0.1"])
    assert seen == [{"estimator": "paper"},
                    {"estimator": "boosting", "model_discrepancy": 0.1}]
