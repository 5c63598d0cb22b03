"""plot_fault_signatures: one panel per fault type, the reference in each."""
import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from gearshot import GearshotError  # noqa: E402
from gearshot.plotting import plot_fault_signatures  # noqa: E402


def test_panels_and_window():
    n = 2048
    ref = np.zeros(n)
    ref[700] = 5.0
    sig = {"ftff": ref, "breakage": np.roll(ref, 10), "destruction": -ref}
    lines = plot_fault_signatures(sig, 38, n_mesh=2)
    assert len(lines) == 2 and all(len(p) == 2 for p in lines)
    x, y = lines[0][0].get_data()
    assert x[np.argmax(y)] == 0.0 and x[-1] == pytest.approx(1.0, abs=0.02)
    import matplotlib.pyplot as plt
    plt.close("all")


def test_errors_name_the_problem():
    with pytest.raises(GearshotError, match="reference"):
        plot_fault_signatures({"breakage": np.zeros(64)}, 38)
    with pytest.raises(GearshotError, match="shape"):
        plot_fault_signatures({"ftff": np.zeros(64), "breakage": np.zeros(32)}, 4)
