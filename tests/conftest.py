"""Shared fixtures: the ../shared folder beside the repository."""

import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import settings

# Property tests draw the same examples on every run (the project's determinism rule);
# GEARSHOT_HYPOTHESIS=explore draws fresh ones, for hunting new counter-examples locally.
settings.register_profile("deterministic", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile("explore" if os.environ.get("GEARSHOT_HYPOTHESIS") == "explore"
                      else "deterministic")

SHARED = Path(__file__).resolve().parents[1].parent / "shared"


@pytest.fixture(scope="session")
def shared_dir():
    if not SHARED.is_dir():
        pytest.skip(f"reference folder {SHARED} is absent; parity checks need ../shared")
    return SHARED


@pytest.fixture(scope="session")
def matlab_ref(shared_dir):
    path = shared_dir / "reference" / "matlab_dsp_vectors.npz"
    if not path.is_file():
        pytest.skip(f"{path} is absent")
    with np.load(path) as data:
        return {k: data[k] for k in data.files}
