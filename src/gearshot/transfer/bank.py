"""A bank of transfer functions: measured (a folder of UFF58/CSV files) or synthetic."""

from __future__ import annotations

import os
from collections.abc import Iterable, Iterator
from pathlib import Path

import numpy as np

from .._errors import GearshotError
from .._validation import check_int
from .function import TransferFunction
from .modal import synthetic_tfs
from .uff import FRF_SUFFIXES, read_frf

__all__ = ["TransferFunctionBank", "synthetic_bank"]


class TransferFunctionBank:
    """An ordered, immutable collection of :class:`TransferFunction` objects.

    The paper propagates simulated signals through a bank of measured TFs and keeps one TF
    out of every other use for feature selection; :meth:`hold_out` does that split.

    Parameters
    ----------
    tfs : iterable of TransferFunction
        At least one.
    names : iterable of str, optional
        Short unique keys (default: each TF's ``name``, or ``tf_<i>`` when empty or repeated).

    Examples
    --------
    A bank of measured TFs is read with ``TransferFunctionBank.from_folder(folder)``
    (e.g. ``"../shared/data/frf"``); a seeded synthetic one works alike:

    >>> from gearshot.transfer import TransferFunctionBank
    >>> bank = TransferFunctionBank.synthetic(4, rng=0)
    >>> selection_tf, rest = bank.hold_out(0)
    >>> selection_tf.name == bank.names[0], len(rest)
    (True, 3)
    >>> rest.to_signal_grid(2048).shape       # complex, on the SA's DFT grid
    (3, 2048)
    """

    def __init__(self, tfs: Iterable[TransferFunction], *, names: Iterable[str] | None = None):
        tfs = tuple(tfs)
        if not tfs:
            raise GearshotError("tfs must hold at least one TransferFunction; got none")
        for i, tf in enumerate(tfs):
            if not isinstance(tf, TransferFunction):
                raise GearshotError(f"tfs[{i}] must be a TransferFunction; got "
                                    f"{type(tf).__name__}")
        if names is None:
            raw = [tf.name for tf in tfs]
            names = [nm if nm and raw.count(nm) == 1 else f"tf_{i}" for i, nm in enumerate(raw)]
        names = tuple(str(n) for n in names)
        if len(names) != len(tfs):
            raise GearshotError(f"names must have one entry per TF ({len(tfs)}); got {len(names)}")
        if len(set(names)) != len(names):
            raise GearshotError(f"names must be unique; got {names!r}")
        self._tfs = tfs
        self._names = names

    # ------------------------------------------------------------------ constructors
    @classmethod
    def from_folder(cls, path: str | os.PathLike, *, suffixes: tuple[str, ...] = FRF_SUFFIXES
                    ) -> TransferFunctionBank:
        """Read every FRF file in ``path`` (not recursive), sorted by file name.

        Each file contributes its first FRF; the bank's names are the file stems.

        Raises
        ------
        GearshotError
            If the folder does not exist or holds no file with one of ``suffixes``, or if a
            file is unreadable (the error names the file).
        """
        folder = Path(os.fspath(path))
        if not folder.is_dir():
            raise GearshotError(f"{folder}: not a folder")
        wanted = tuple(s.lower() for s in suffixes)
        files = sorted(p for p in folder.iterdir()
                       if p.is_file() and p.suffix.lower() in wanted and not p.name.startswith("."))
        if not files:
            raise GearshotError(f"{folder}: no FRF files with suffix in {wanted}")
        return cls([read_frf(p) for p in files], names=[p.stem for p in files])

    @classmethod
    def synthetic(cls, n: int, *, rng: np.random.Generator | int, **kwargs) -> TransferFunctionBank:
        """A seeded bank of modal accelerance FRFs; see :func:`synthetic_bank`."""
        return cls(synthetic_tfs(n, rng=rng, **kwargs))

    # ------------------------------------------------------------------ container protocol
    def __len__(self) -> int:
        return len(self._tfs)

    def __iter__(self) -> Iterator[TransferFunction]:
        return iter(self._tfs)

    def __getitem__(self, key: int | str) -> TransferFunction:
        if isinstance(key, str):
            try:
                return self._tfs[self._names.index(key)]
            except ValueError:
                raise GearshotError(f"no TF named {key!r}; names are {self._names!r}") from None
        i = check_int(key, "key")
        if not -len(self) <= i < len(self):
            raise GearshotError(f"key must index one of {len(self)} TFs; got {i}")
        return self._tfs[i]

    def __repr__(self) -> str:
        shown = ", ".join(self._names[:4]) + (", ..." if len(self) > 4 else "")
        return f"TransferFunctionBank({len(self)} TFs: {shown})"

    @property
    def names(self) -> tuple[str, ...]:
        """Keys of the TFs, in order."""
        return self._names

    def items(self) -> Iterator[tuple[str, TransferFunction]]:
        """``(name, tf)`` pairs in order."""
        return zip(self._names, self._tfs)

    # ------------------------------------------------------------------ operations
    def hold_out(self, which: int | str | None = None, *,
                 rng: np.random.Generator | int | None = None
                 ) -> tuple[TransferFunction, TransferFunctionBank]:
        """Reserve one TF (for feature selection, as the paper does) and return the rest.

        Parameters
        ----------
        which : int or str, optional
            Index or name of the TF to reserve. If omitted, one is drawn with ``rng``.
        rng : numpy.random.Generator or int, optional
            Required when ``which`` is omitted.

        Returns
        -------
        held : TransferFunction
        rest : TransferFunctionBank
            The other TFs, in their original order.
        """
        if len(self) < 2:
            raise GearshotError("hold_out needs a bank of at least 2 TFs; this one has "
                                f"{len(self)}")
        if which is None:
            if rng is None:
                raise GearshotError("hold_out needs which= (index or name) or rng= to draw one")
            i = int(np.random.default_rng(rng).integers(len(self)))
        elif isinstance(which, str):
            if which not in self._names:
                raise GearshotError(f"which={which!r} is not a TF name; names are {self._names!r}")
            i = self._names.index(which)
        else:
            i = check_int(which, "which")
            if not -len(self) <= i < len(self):
                raise GearshotError(f"which must index one of {len(self)} TFs; got {i}")
            i %= len(self)
        keep = [j for j in range(len(self)) if j != i]
        return self._tfs[i], TransferFunctionBank([self._tfs[j] for j in keep],
                                                  names=[self._names[j] for j in keep])

    def normalized(self) -> TransferFunctionBank:
        """Every TF scaled to unit RMS magnitude (:meth:`TransferFunction.normalized`)."""
        return TransferFunctionBank([tf.normalized() for tf in self._tfs], names=self._names)

    def to_signal_grid(self, n: int) -> np.ndarray:
        """All TFs resampled to an ``n``-point signal grid; shape (n_tf, n), complex."""
        return np.stack([tf.to_signal_grid(n) for tf in self._tfs])


def synthetic_bank(n: int, **kwargs) -> TransferFunctionBank:
    """A seeded bank of realistic accelerance FRFs (stand-ins for measured hammer-test TFs).

    The FRFs of :func:`gearshot.transfer.modal.synthetic_tfs` (same arguments: ``band``,
    ``n_lines``, ``rng`` — required —, ``n_modes``, ``damping``, ``attenuation``,
    ``nonminimum_fraction``) as a :class:`TransferFunctionBank`.

    Examples
    --------
    >>> from gearshot.transfer import synthetic_bank
    >>> bank = synthetic_bank(3, rng=0)
    >>> bank.names
    ('synthetic_000', 'synthetic_001', 'synthetic_002')
    >>> bank["synthetic_000"].n_lines
    1001
    """
    return TransferFunctionBank(synthetic_tfs(n, **kwargs))
