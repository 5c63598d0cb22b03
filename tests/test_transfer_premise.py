"""The paper's premise on the real FRFs: the TF estimate from one healthy-like signal
(spectrum background + minimum phase) recovers the measured TF's magnitude shape."""

from pathlib import Path

import numpy as np
import pytest

from gearshot.transfer import TransferFunctionBank, estimate_transfer_function

SHARED = Path(__file__).resolve().parents[1].parent / "shared"
FRF_DIR = SHARED / "data" / "frf"

N_CYCLE = 2048
MESH_ORDER = 38


def gear_like_signal(n_cycles, rng):
    """Unit white noise plus the first five gear-mesh harmonics (cycle domain)."""
    n = N_CYCLE * n_cycles
    t = np.arange(n) / N_CYCLE
    x = rng.standard_normal(n)
    for k, amp in enumerate((3.0, 1.5, 1.0, 0.5, 0.3), start=1):
        x += amp * np.cos(2 * np.pi * MESH_ORDER * k * t + rng.uniform(0, 2 * np.pi))
    return x


def log_magnitude_correlation(tf, x):
    """Propagate ``x`` through ``tf`` (resampled to the whole signal's length), estimate the
    TF back, and correlate log-magnitudes on the shared one-sided 2048-point grid."""
    y = np.fft.ifft(np.fft.fft(x) * tf.to_signal_grid(x.size)).real
    est = estimate_transfer_function(y, N_CYCLE)
    true = tf.to_signal_grid(N_CYCLE)
    half = slice(0, N_CYCLE // 2 + 1)
    return float(np.corrcoef(np.log(np.abs(est[half])), np.log(np.abs(true[half])))[0, 1])


@pytest.fixture(scope="module")
def bank():
    if len(list(FRF_DIR.glob("*.uff"))) != 12:
        pytest.skip(f"the 12 real FRFs are not in {FRF_DIR}")
    return TransferFunctionBank.from_folder(FRF_DIR)


def test_tf_estimate_recovers_every_real_frf(bank):
    x = gear_like_signal(200, np.random.default_rng(0))
    corr = {name: log_magnitude_correlation(tf, x) for name, tf in bank.items()}
    assert len(corr) == 12
    low = {k: round(v, 3) for k, v in corr.items() if v < 0.8}
    assert not low, f"log-magnitude correlation below 0.8: {low}"


def test_premise_fails_without_the_estimate(bank):
    """Control: another FRF of the bank (a wrong transfer-path model) correlates far less
    with the true FRF than the estimate does, so the 0.8 criterion is discriminating."""
    x = gear_like_signal(200, np.random.default_rng(1))
    tf = bank["structure_b_h1"]
    other = bank["beam_h5"].to_signal_grid(N_CYCLE)[: N_CYCLE // 2 + 1]
    true = tf.to_signal_grid(N_CYCLE)[: N_CYCLE // 2 + 1]
    c_other = np.corrcoef(np.log(np.abs(other)), np.log(np.abs(true)))[0, 1]
    assert log_magnitude_correlation(tf, x) > c_other + 0.3
