"""The fault signature over the mesh cycle, per fault type, against the FTFF's (#13)."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from .._errors import GearshotError

__all__ = ["plot_fault_signatures"]


def plot_fault_signatures(signatures: Mapping, mesh_order: int, *, reference: str = "ftff",
                          n_mesh: float = 4.0, axes=None):
    """Plot each fault type's signature over a few mesh periods against the reference's.

    Parameters
    ----------
    signatures : mapping name -> ndarray (n,)
        Signature of each fault type over one SA cycle (e.g. faulty minus healthy SA of the
        same gear, at equal size); must hold ``reference``.
    mesh_order : int
        Mesh periods per SA cycle (the gear's tooth count).
    reference : str
        Key of the signature drawn in every panel (default the FTFF).
    n_mesh : float
        Width of the window, mesh periods, centred on the reference's peak |value|.
    axes : sequence of Axes, optional
        One per non-reference signature; a new figure when omitted.

    Returns
    -------
    list of list of Line2D
        The lines of each panel (reference first).
    """
    if reference not in signatures:
        raise GearshotError(f"reference={reference!r} is not among the signatures "
                            f"{sorted(signatures)}")
    ref = np.asarray(signatures[reference], dtype=float)
    if ref.ndim != 1 or ref.size < 8:
        raise GearshotError(f"signatures must be 1-D cycles; {reference!r} has shape "
                            f"{ref.shape}")
    others = [k for k in signatures if k != reference]
    if not others:
        raise GearshotError("signatures holds only the reference; nothing to compare")
    n = ref.size
    if axes is None:
        import matplotlib.pyplot as plt
        _, axes = plt.subplots(len(others), 1, sharex=True,
                               figsize=(7, 1.9 * len(others)), squeeze=False)
        axes = axes[:, 0]
    if len(axes) != len(others):
        raise GearshotError(f"axes must hold {len(others)} axes; got {len(axes)}")
    per_mesh = n / mesh_order
    centre = int(np.argmax(np.abs(ref)))
    half = int(round(0.5 * n_mesh * per_mesh))
    idx = (centre + np.arange(-half, half + 1)) % n
    x = np.arange(-half, half + 1) / per_mesh
    out = []
    for ax, name in zip(axes, others):
        sig = np.asarray(signatures[name], dtype=float)
        if sig.shape != ref.shape:
            raise GearshotError(f"signature {name!r} has shape {sig.shape}; the reference "
                                f"{ref.shape}")
        lines = ax.plot(x, ref[idx], color="0.6", lw=1.0, label=reference)
        lines += ax.plot(x, sig[idx], lw=1.0, label=name)
        ax.set_ylabel("g")
        ax.legend(loc="upper right", fontsize=8)
        out.append(lines)
    axes[-1].set_xlabel("mesh periods from the reference's peak")
    return out
