"""Tests of gearshot.transfer.modal (modal synthesis and the synthetic bank)."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from gearshot import GearshotError
from gearshot.transfer import (
    Mode,
    TransferFunction,
    antiresonances,
    attenuation_db,
    modal_frf,
    synthetic_bank,
)


def test_single_mode_accelerance_analytic():
    f = np.linspace(0, 200, 2001)
    m = Mode(frequency=50.0, damping=0.02, residue=3.0)
    tf = modal_frf(f, [m])
    w, wr = 2 * np.pi * f, 2 * np.pi * 50.0
    assert_allclose(tf.values, -(w**2) * 3.0 / (wr**2 - w**2 + 2j * 0.02 * wr * w), rtol=1e-12)
    k = np.argmin(np.abs(f - 50))
    assert abs(tf.values[k]) == pytest.approx(3.0 / (2 * 0.02), rel=1e-12)   # A/(2ζ)
    assert np.angle(tf.values[k]) == pytest.approx(np.pi / 2, abs=1e-12)      # +90° at ω_r
    assert tf.values[0] == 0                                                    # no mass line
    assert abs(tf.values[-1]) == pytest.approx(3.0, rel=0.1)                    # mass line A


def test_quantities_are_related_by_jw():
    f = np.linspace(1, 300, 500)
    modes = [Mode(40, 0.03, 1.0), Mode(170, 0.01, -0.5)]
    acc = modal_frf(f, modes).values
    mob = modal_frf(f, modes, quantity="mobility").values
    rec = modal_frf(f, modes, quantity="receptance").values
    w = 2 * np.pi * f
    assert_allclose(mob, 1j * w * rec, rtol=1e-12)
    assert_allclose(acc, 1j * w * mob, rtol=1e-12)


def test_drive_point_residues_give_antiresonances_sign_change_removes_them():
    f = np.linspace(0, 400, 4001)
    same = modal_frf(f, [Mode(100, 0.01, 1.0), Mode(250, 0.01, 1.0)])
    flip = modal_frf(f, [Mode(100, 0.01, 1.0), Mode(250, 0.01, -1.0)])
    ar = antiresonances(same)
    assert ar.size == 1 and 100 < ar[0] < 250
    assert antiresonances(flip).size == 0


def test_allpass_and_delay_change_phase_only():
    f = np.linspace(0, 1000, 1001)
    modes = [Mode(120, 0.02, 1.0), Mode(480, 0.03, 0.7)]
    base = modal_frf(f, modes, rigid_body=0.5)
    nmp = modal_frf(f, modes, rigid_body=0.5, delay=1e-3, allpass=[(300.0, 0.1)])
    assert_allclose(np.abs(nmp.values), np.abs(base.values), rtol=1e-12)
    extra = np.unwrap(np.angle(nmp.values / base.values))
    # delay: -2π f τ ; all-pass pair: -2·atan2(2ζω0ω, ω0² − ω²) (0 → −2π)
    w, w0 = 2 * np.pi * f, 2 * np.pi * 300.0
    expected = -w * 1e-3 - 2 * np.arctan2(2 * 0.1 * w0 * w, w0**2 - w**2)
    assert_allclose(extra, expected, atol=1e-9)
    assert abs(base.values[0]) == pytest.approx(0.5)   # rigid-body mass line at DC


def _excess_phase_span(tf):
    """Spread of (phase − minimum phase) over the band, minimum phase by the real cepstrum."""
    h = tf.values
    full = np.concatenate([h, np.conj(h[-2:0:-1])])
    c = np.fft.ifft(np.log(np.abs(full))).real
    n = full.size
    fold = np.zeros(n)
    fold[0] = c[0]
    fold[1:n // 2] = 2 * c[1:n // 2]
    fold[n // 2] = c[n // 2]
    h_mp = np.exp(np.fft.fft(fold))[: h.size]
    excess = np.unwrap(np.angle(h / h_mp))
    return excess.max() - excess.min()


def test_minimum_phase_check_recognises_delay():
    f = np.linspace(0, 1000, 2001)
    modes = [Mode(150, 0.02, 1.0), Mode(420, 0.02, 1.0), Mode(800, 0.02, 1.0)]
    assert _excess_phase_span(modal_frf(f, modes, rigid_body=0.3)) < 0.3   # drive point: min-phase
    assert _excess_phase_span(modal_frf(f, modes, rigid_body=0.3, delay=1e-3)) > 5


def test_synthetic_bank_properties():
    bank = synthetic_bank(24, rng=7)
    assert len(bank) == 24
    n_nmp = 0
    for tf in bank:
        assert isinstance(tf, TransferFunction)
        assert tf.band == (0.0, 1000.0) and tf.n_lines == 1001
        assert 4 <= len(tf.metadata["modes"]) <= 12
        zetas = [m[1] for m in tf.metadata["modes"]]
        assert 0.01 <= min(zetas) and max(zetas) <= 0.05
        assert attenuation_db(tf) >= 10.0 - 1e-9
        assert attenuation_db(tf) == pytest.approx(tf.metadata["attenuation_db"])
        assert antiresonances(tf, min_depth_db=10).size >= 1
        assert abs(tf.values[0]) > 0            # finite log-magnitude at DC
        signs = np.sign([m[2] for m in tf.metadata["modes"]])
        assert (signs > 0).any() and ((signs < 0).any() or len(signs) >= 4)
        if tf.metadata["nonminimum_phase_added"]:
            n_nmp += 1
            assert _excess_phase_span(tf) > 1.0
    assert n_nmp == 12
    assert any(np.any(np.sign([m[2] for m in tf.metadata["modes"]]) < 0) for tf in bank)


def test_synthetic_bank_seeded_and_reproducible():
    a = synthetic_bank(5, rng=123)
    b = synthetic_bank(5, rng=np.random.default_rng(123))
    c = synthetic_bank(5, rng=124)
    assert all(x == y for x, y in zip(a, b))
    assert not all(x == y for x, y in zip(a, c))


def test_synthetic_bank_options():
    bank = synthetic_bank(3, band=(10.0, 5000.0), n_lines=512, rng=1, n_modes=(4, 4),
                          attenuation=(20.0, 20.0), nonminimum_fraction=0.0)
    for tf in bank:
        assert tf.band == (10.0, 5000.0) and tf.n_lines == 512
        assert len(tf.metadata["modes"]) == 4
        assert attenuation_db(tf) == pytest.approx(20.0)
        assert tf.metadata["delay_s"] == 0 and not tf.metadata["nonminimum_phase_added"]


@pytest.mark.parametrize("kwargs, match", [
    ({"rng": None}, "rng must be given"),
    ({"band": (100.0, 10.0)}, "band"),
    ({"n_modes": (5, 4)}, "n_modes"),
    ({"damping": (0.0, 0.05)}, "damping"),
    ({"nonminimum_fraction": 2.0}, "nonminimum_fraction"),
])
def test_synthetic_bank_bad_options(kwargs, match):
    kw = {"rng": 0, **kwargs}
    with pytest.raises(GearshotError, match=match):
        synthetic_bank(2, **kw)


def test_mode_and_modal_frf_validation():
    with pytest.raises(GearshotError, match="frequency"):
        Mode(-1.0, 0.01, 1.0)
    with pytest.raises(GearshotError, match="damping"):
        Mode(10.0, 1.5, 1.0)
    with pytest.raises(GearshotError, match="residue"):
        Mode(10.0, 0.01, float("nan"))
    f = np.linspace(0, 100, 11)
    with pytest.raises(GearshotError, match="modes"):
        modal_frf(f, [])
    with pytest.raises(GearshotError, match="quantity"):
        modal_frf(f, [Mode(10, 0.01, 1)], quantity="inertance")
    with pytest.raises(GearshotError, match="infinite at 0 Hz"):
        modal_frf(f, [Mode(10, 0.01, 1)], quantity="receptance", rigid_body=1.0)
    with pytest.raises(GearshotError, match="allpass"):
        modal_frf(f, [Mode(10, 0.01, 1)], allpass=[(10.0,)])
