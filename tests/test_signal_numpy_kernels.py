"""The NumPy FFTs and splines of the one-record path against the SciPy routines they
replace, and the one-record `gearshot indicators` call importing no SciPy at all."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import scipy.fft
import scipy.ndimage
from scipy.interpolate import CubicSpline

from gearshot.signal import angle_to_time
from gearshot.signal._fft import fft, ifft, next_fast_len
from gearshot.signal._splines import NotAKnotSpline, bspline_read


@pytest.mark.parametrize("n", [2, 3, 100, 777, 1023, 2048, 79872])
def test_fft_bit_identical_to_scipy(n):
    rng = np.random.default_rng(n)
    x = rng.standard_normal((3, n))
    z = x + 1j * rng.standard_normal((3, n))
    for a in (x, z):
        for axis in (-1, 0):
            assert np.array_equal(fft(a, axis=axis), scipy.fft.fft(a, axis=axis))
            assert np.array_equal(ifft(a, axis=axis), scipy.fft.ifft(a, axis=axis))


def test_next_fast_len_is_scipys_real_one():
    rng = np.random.default_rng(0)
    for n in [*range(1, 3000), *rng.integers(3000, 10**8, 500).tolist()]:
        assert next_fast_len(n) == scipy.fft.next_fast_len(n, real=True), n


@pytest.mark.parametrize("n, ppr", [(4, 1), (5, 3), (7, 1), (121, 1), (400, 60), (5000, 7)])
def test_not_a_knot_spline_matches_cubicspline(n, ppr):
    rng = np.random.default_rng(n * ppr)
    knots = np.arange(n) / ppr
    values = np.cumsum(0.03 + 0.01 * rng.random(n))
    ref, mine = CubicSpline(knots, values), NotAKnotSpline(knots, values)
    x = np.concatenate([rng.uniform(-0.3, knots[-1] + 0.3, 2000), knots,
                        knots[:-1] + 0.5 / ppr])
    for nu in (0, 1):
        want = ref(x, nu)
        assert np.max(np.abs(mine(x, nu) - want)) <= 1e-12 * np.max(np.abs(want))


def test_angle_to_time_falls_back_to_pchip_when_the_spline_turns_back():
    # a pulse train whose spline overshoots backwards between pulses 2 and 3
    pulses = np.array([0.0, 0.1, 0.2, 0.2001, 0.2002, 0.3, 0.4])
    times = angle_to_time(pulses, np.linspace(0, 6, 601))
    assert np.all(np.diff(times) >= 0)
    assert CubicSpline(np.arange(7.0), pulses)(np.linspace(0, 6, 601), 1).min() < 0


@pytest.mark.parametrize("n", [4, 5, 41, 100, 20_000])
def test_bspline_read_matches_ndimage_mirror(n):
    rng = np.random.default_rng(n)
    x = rng.standard_normal(n)
    pos = np.concatenate([rng.uniform(0, n - 1, 3000), np.arange(min(n, 50)), [0.0, n - 1.0],
                          rng.uniform(-3 * n, 3 * n, 300)])   # inside, knots, folded back
    coeffs = scipy.ndimage.spline_filter1d(x, order=3, mode="mirror")
    want = scipy.ndimage.map_coordinates(coeffs, pos[None], order=3, mode="mirror",
                                         prefilter=False)
    assert np.max(np.abs(bspline_read(x, pos) - want)) <= 1e-12 * np.max(np.abs(x))


def test_one_record_indicators_imports_no_scipy(shared_dir, tmp_path):
    record = shared_dir / "data" / "phm09" / "spur2_30hz_High_1.zip"
    out = tmp_path / "i.json"
    argv = ["gearshot", "indicators", "--machine", "examples/machines/phm09_spur.toml",
            "--shaft", "idler", "--sensor", "acc_input", str(record), "--json", str(out)]
    code = (
        "import runpy, sys\n"
        f"sys.argv = {argv!r}\n"
        "try:\n"
        "    runpy.run_module('gearshot.app.cli', run_name='__main__', alter_sys=True)\n"
        "except SystemExit as exc:\n"
        "    assert not exc.code, exc.code\n"
        "print('SCIPY', sorted(m for m in sys.modules if m.split('.')[0] == 'scipy'))\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=Path(__file__).resolve().parents[1], check=True)
    assert done.stdout.strip().splitlines()[-1] == "SCIPY []", done.stdout[-2000:]
    table = json.loads(out.read_text())
    assert table["shaft"] == "idler" and table["kind"]
