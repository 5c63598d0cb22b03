"""The trust columns of a predict table (issue #29): the fit's verdict in every row,
``trusted``, and the lines ``gearshot predict`` prints about them."""

from __future__ import annotations

import pandas as pd

__all__ = ["add_trust_columns", "fit_check_line", "trust_summary"]


def add_trust_columns(frame: pd.DataFrame, check) -> pd.DataFrame:
    """Add the fit's verdict and ``trusted`` to a predict table, in place.

    ``comparable``: false too where ``speed_check`` failed (the recording's speed lies
    outside what the fit's recordings showed: another operating condition,
    :func:`gearshot.app.conditions.fit_speed_check`) or ``path_check`` did (another
    transfer path: :func:`gearshot.app.conditions.fit_path_check`; ``comparability``, the
    p-value of its SA, is left as it is); ``fit_check``: ``check.verdict`` in every row
    ("passed" or the reason); ``trusted``:
    :func:`gearshot.estimator.trusted_column` (input check "ok" — a table without
    ``input_check`` counts as "ok" —, comparable and the fit check passed; with a
    ``recording`` column, only in a recording more than half of whose segments pass:
    :func:`gearshot.estimator.fit_check.recording_majority`);
    ``frame.attrs["fit_check"]``: ``check.as_dict()``.
    """
    from ..estimator.fit_check import recording_majority, trusted_column
    from ..estimator.trusted import comparable_at_speed

    if "comparable" in frame:
        frame["comparable"] = comparable_at_speed(frame)
    frame["fit_check"] = check.verdict
    frame["trusted"] = trusted_column(frame) if len(frame) else pd.Series(dtype=bool)
    if "recording" in frame and len(frame):
        frame["trusted"] &= recording_majority(frame["recording"], frame["trusted"])
    frame.attrs["fit_check"] = check.as_dict()
    return frame


def fit_check_line(frame: pd.DataFrame) -> str:
    """One line with the fit's verdict on its own hold-outs (printed before the
    estimates)."""
    check = frame.attrs.get("fit_check")
    if not check:
        verdict = str(frame["fit_check"].iloc[0]) if "fit_check" in frame and len(frame) \
            else "unknown"
        return f"fit check: {verdict}"
    parts = []
    if check.get("n_healthy"):
        parts.append(f"{check['n_healthy']} healthy hold-out(s) read "
                     f"{check['healthy_mean']:.3f} on average")
    if check.get("n_example"):
        parts.append(f"{check['n_example']} other segment(s) of the example record read "
                     f"{check['example_mean']:.3f} against the declared "
                     f"{check['declared_size']:g}")
    if check.get("example_self") is not None:
        parts.append(f"the example itself reads {check['example_self']:.3f}")
    line = f"fit check: {check['verdict']}"
    if parts:
        line += " (" + "; ".join(parts) + ")"
    if check["verdict"] != "passed":
        line += " — no estimate of this fit is trusted"
    ratio = check.get("drift_ratio")
    if ratio:
        from ..estimator.uncertainty import RUN_SPREAD, drift_run_spread

        line += (f"; its intervals take a later run's spread as {RUN_SPREAD:g} × "
                 f"√{ratio:.2f} = {drift_run_spread(ratio):.2f} (the drift)")
    return line


def trust_summary(frame: pd.DataFrame) -> str:
    """One line counting the trusted segments of a predict table."""
    if "trusted" not in frame or not len(frame):
        return "trusted: no segment estimated"
    n_yes = int(frame["trusted"].astype(bool).sum())
    return (f"trusted: {n_yes} of {len(frame)} segment(s) (input, speed and path checks ok, "
            f"comparable and fit check passed, in a recording most of whose segments pass)")
