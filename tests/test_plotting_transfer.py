"""Tests of gearshot.plotting.transfer."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from gearshot import GearshotError
from gearshot.plotting import plot_transfer_function, plot_transfer_functions
from gearshot.transfer import TransferFunction

mpl = pytest.importorskip("matplotlib")
mpl.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def _tf():
    f = np.linspace(0, 100, 101)
    return TransferFunction(f, 10 * np.exp(-1j * np.pi * f / 50), name="delay", units="g/N")


def test_plot_returns_lines_with_db_and_phase():
    l_mag, l_ph = plot_transfer_function(_tf())
    assert_allclose(l_mag.get_ydata(), 20.0)                     # |H| = 10 -> 20 dB
    assert np.all(np.abs(l_ph.get_ydata()) <= 180.0 + 1e-9)      # wrapped phase
    _, l_ph90 = plot_transfer_function(_tf(), phase_center=90.0)
    y = l_ph90.get_ydata()
    assert y.min() >= -90.0 and y.max() < 270.0
    assert_allclose(np.exp(1j * np.radians(y)), np.exp(1j * np.radians(l_ph.get_ydata())),
                    atol=1e-12)
    assert l_mag.get_label() == "delay"
    assert "g/N" in l_mag.axes.get_ylabel()
    plt.close("all")


def test_plot_into_given_axes_unwrapped_and_linear():
    fig, axes = plt.subplots(2, 1)
    l_mag, l_ph = plot_transfer_function(_tf(), axes, db=False, wrap_phase=False, label="x")
    assert l_mag.axes is axes[0] and l_ph.axes is axes[1]
    assert_allclose(l_mag.get_ydata(), 10.0)
    assert l_ph.get_ydata()[-1] == pytest.approx(-360.0)
    lines = plot_transfer_functions([_tf(), _tf()], axes, offset_db=10)
    assert len(lines) == 2
    plt.close(fig)
    with pytest.raises(GearshotError, match="pair of Axes"):
        plot_transfer_function(_tf(), ax=object())
    with pytest.raises(GearshotError, match="TransferFunction"):
        plot_transfer_function(np.ones(3))


def test_offset_db_shifts_successive_curves():
    fig, axes = plt.subplots(2, 1)
    lines = plot_transfer_functions([_tf(), _tf(), _tf()], axes, offset_db=10)
    assert_allclose(lines[2][0].get_ydata(), 0.0, atol=1e-12)  # 20 dB − 2 × 10 dB
    plt.close(fig)
