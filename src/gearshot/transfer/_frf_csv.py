"""One FRF as a CSV file: columns ``freq_hz, re, im`` under ``# key = value`` metadata lines."""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from ._uff58 import check_dataset, check_readable, fail
from .function import TransferFunction


def _is_number_row(line: str) -> bool:
    try:
        [float(v) for v in line.split(",")]
    except ValueError:
        return False
    return True


def _split_csv(path: Path) -> tuple[dict[str, Any], list[str]]:
    """The ``# key = value`` metadata and the data rows (header line dropped) of a CSV file."""
    check_readable(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise fail(path, f"cannot read as UTF-8 text ({exc})") from None
    meta: dict[str, Any] = {}
    body: list[str] = []
    for line in text.splitlines():
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            key, sep, val = s[1:].partition("=")
            if sep:
                meta[key.strip()] = val.strip()
            continue
        body.append(s)
    if body and not _is_number_row(body[0]):
        body = body[1:]  # column header line, e.g. "freq_hz,re,im"
    return meta, body


def _csv_values(path: Path, body: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies and complex values of the data rows, checked as a UFF58 dataset is."""
    if not body:
        raise fail(path, "no data rows (expected columns freq_hz, re, im)")
    try:
        arr = np.loadtxt(io.StringIO("\n".join(body)), delimiter=",", dtype=float, ndmin=2)
    except ValueError as exc:
        raise fail(path, f"malformed CSV data ({exc})") from None
    if arr.shape[1] != 3:
        raise fail(path, f"expected 3 columns (freq_hz, re, im); got {arr.shape[1]}")
    x, y = arr[:, 0], arr[:, 1] + 1j * arr[:, 2]
    check_dataset(path, 0, {"x": x, "data": y, "num_pts": x.size})
    if x.size < 2:
        raise fail(path, f"only {x.size} frequency line(s); need >= 2")
    if x[0] < 0:
        raise fail(path, f"negative frequency {float(x[0])!r} Hz")
    return x, y


def read_frf_csv(path: Path) -> TransferFunction:
    """The FRF of a CSV file written by :func:`write_frf_csv` (or by hand, same layout)."""
    meta, body = _split_csv(path)
    x, y = _csv_values(path, body)

    def _int(key: str) -> int:
        try:
            return int(meta.pop(key, 0))
        except ValueError:
            raise fail(path, f"metadata {key!r} must be an integer") from None

    kw = dict(response_node=_int("response_node"), response_direction=_int("response_direction"),
              reference_node=_int("reference_node"),
              reference_direction=_int("reference_direction"))
    name = meta.pop("name", "") or path.stem
    return TransferFunction(
        freqs=x, values=y, name=name,
        response_quantity=meta.pop("response_quantity", "acceleration"),
        reference_quantity=meta.pop("reference_quantity", "force"),
        units=meta.pop("units", ""), metadata={**meta, "source": str(path)}, **kw)


def write_frf_csv(path: Path, tf: TransferFunction) -> None:
    """``tf`` as CSV: metadata lines, a header, then 17-significant-digit rows."""
    lines = [f"# name = {tf.name}", f"# response_node = {tf.response_node}",
             f"# response_direction = {tf.response_direction}",
             f"# reference_node = {tf.reference_node}",
             f"# reference_direction = {tf.reference_direction}",
             f"# response_quantity = {tf.response_quantity}",
             f"# reference_quantity = {tf.reference_quantity}", f"# units = {tf.units}"]
    for k, v in tf.metadata.items():
        if k != "source" and "\n" not in str(v) and "=" not in str(k):
            lines.append(f"# {k} = {v}")
    lines.append("freq_hz,re,im")
    body = np.column_stack([tf.freqs, tf.values.real, tf.values.imag])
    with open(path, "w", encoding="utf-8") as fh:
        fh.write("\n".join(lines) + "\n")
        np.savetxt(fh, body, fmt="%.17g", delimiter=",")
