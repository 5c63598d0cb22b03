"""DIN 3962 profile errors per tooth."""
import numpy as np
import pytest

from gearshot import GearshotError
from gearshot.sim import DIN_PROFILE_TOLERANCES, draw_profile_errors


def test_table_matches_design():
    assert DIN_PROFILE_TOLERANCES[7] == (9, 11, 0.3)
    assert DIN_PROFILE_TOLERANCES[1] == (1, 1.5, 0.02)
    assert DIN_PROFILE_TOLERANCES[12] == (71, 90, 2.3)
    fh = [DIN_PROFILE_TOLERANCES[g][0] for g in range(1, 13)]
    assert np.all(np.diff(fh) > 0)


@pytest.mark.parametrize("grade", [1, 7, 12])
def test_draws_within_tolerances(grade):
    fh, ff, c = (v * 1e-6 for v in DIN_PROFILE_TOLERANCES[grade])
    e = draw_profile_errors(38, grade, np.random.default_rng(0))
    assert e.slope.shape == (38,) and e.noise.shape[0] == 38
    assert np.all((e.slope >= 0.9 * fh) & (e.slope <= 1.1 * fh))
    assert np.all((e.waviness >= 0.9 * ff) & (e.waviness <= 1.1 * ff))
    assert np.all(np.abs(e.noise) <= c) and np.all(np.abs(e.phase) <= np.pi)
    assert e.n_waves == 3.5
    assert draw_profile_errors(17, grade, np.random.default_rng(0)).n_waves == 2.5


def test_seeded_and_evaluated():
    a = draw_profile_errors(17, 5, np.random.default_rng(3))
    b = draw_profile_errors(17, 5, np.random.default_rng(3))
    np.testing.assert_array_equal(a.noise, b.noise)
    s = np.linspace(0, 1, 11)
    e0 = a(0, s)
    expected = (a.slope[0] * s + 0.5 * a.waviness[0] * np.sin(2 * np.pi * 2.5 * s + a.phase[0])
                + np.interp(s, np.linspace(0, 1, a.noise.shape[1]), a.noise[0]))
    np.testing.assert_allclose(e0, expected, rtol=1e-12, atol=1e-18)


def test_mean_tooth_is_exact_average():
    e = draw_profile_errors(17, 9, np.random.default_rng(1))
    s = np.linspace(0, 1, 101)
    avg = np.mean([e(t, s) for t in range(17)], axis=0)
    np.testing.assert_allclose(e.mean_tooth()(0, s), avg, rtol=1e-10, atol=1e-16)


@pytest.mark.parametrize("grade", [0, 13, 2.5])
def test_bad_grade(grade):
    with pytest.raises(GearshotError, match="grade"):
        draw_profile_errors(17, grade, np.random.default_rng(0))


def test_one_formula_pieces():
    """The pieces of ``tooth_error``: the waviness's sine/cosine amplitudes reproduce the
    phase form, and the noise cell puts s = 1 at the end of the last cell."""
    from gearshot.sim.profile_errors import noise_cell, tooth_error, wave_amplitudes

    rng = np.random.default_rng(7)
    wav, phase, s = rng.uniform(1, 2, 5), rng.uniform(-np.pi, np.pi, 5), rng.uniform(0, 1, 5)
    wa, wb = wave_amplitudes(wav, phase)
    ang = 2 * np.pi * 3.5 * s
    np.testing.assert_allclose(wa * np.sin(ang) + wb * np.cos(ang),
                               0.5 * wav * np.sin(ang + phase), rtol=1e-13)
    i0, frac = noise_cell(np.array([0.0, 0.5, 1.0]), 16)
    np.testing.assert_array_equal(i0, [0, 7, 14])
    np.testing.assert_allclose(frac, [0.0, 0.5, 1.0])
    # slope, waves and noise add: 2 * 0.25 + 1 * sin + 0 * cos + knot interpolation
    assert tooth_error(0.25, 2.0, 1.0, 0.0, 0.5, 0.3, 4.0, 8.0, 0.25) == pytest.approx(
        0.5 + 0.5 + 5.0)
