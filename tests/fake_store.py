"""A tiny database store built with a stand-in simulator, for the store-integrity and
store-repair tests: importing ``fast_simulator`` into a test module makes every build of
that module use it (the fixture is autouse)."""

from __future__ import annotations

import numpy as np
import pytest

#: The build arguments of the tiny store: 2 speeds x 1 load x 2 grades, 64-point signals.
KW = dict(speeds=[15, 20], loads=[10], grades=[7, 8], n_healthy=1, n_faulty=2, seed=3,
          n_points=64, client=False, progress=False)


def _fake_simulate_sa(pair, *, speed, load, grade, fault_sizes, n_points, rng,
                      fault_type="ftff"):
    return np.stack([np.random.default_rng(s).standard_normal(n_points) for s in rng])


@pytest.fixture(autouse=True)
def fast_simulator(monkeypatch):
    monkeypatch.setattr("gearshot.sim.database.simulate_sa", _fake_simulate_sa)
    monkeypatch.setattr("gearshot.sim.database.simulate_sa_paired",
                        lambda pair, **kw: (_fake_simulate_sa(pair, **kw),) * 2)


@pytest.fixture
def store(tmp_path):
    from gearshot.sim import build_database

    return build_database(tmp_path / "db", **KW)
