"""Which sensor a machine-file fit estimates with when ``--sensor`` is not given.

The machine's first sensor, unless its fit cannot read its own example
(:mod:`gearshot.estimator.fit_check`: the example record's other segments, or the example
itself, far from the declared size, or an example that does not stand out from the
healthy segments in this sensor's signal). Then the machine's other sensors are fitted in
their order, and the first whose fit passes is used. When none passes, the first of them
that reads its example (its fit fails only on its healthy hold-outs) is used, else the
first sensor's fit is kept; either way every estimate stays untrusted, but a sensor in
whose signal the fault stands out at least orders the segments by it. A first fit that
fails only because its healthy hold-outs read high (or is unchecked) is kept as it is:
the healthy recordings vary more than the fit covers, a property of the recordings that
another sensor shares
(the README journey, spur1 + spur3 High healthy at 30 Hz: the input sensor's hold-outs
read 0.16 on average; the output sensor's pass at 0.115 only as the mean of spur1's 0.21
and spur3's 0.03, and that fit then trusted the chipped gear's Low-load record, a load it
never saw). A named ``--sensor`` is always used as it is.

Why: a sensor whose fit refuses itself gives no trusted number at all, while the same
fault may stand clearly in another sensor's signal. On the PHM09 spur gearbox at 40 Hz
High load the input-shaft accelerometer's fit fails (healthy hold-outs 0.16; the example
itself reads 0.19 and its record 0.24 against 0.5: no grade reproduces it there) and the
output-shaft one's passes (0.08 / 0.44), and then reads the healthy gear's run 2 at 0.10
and the chipped one's at 0.43, every chipped segment above every healthy one
(``benchmarks/RESULTS.md``, "Trust: fit check, intervals and run-to-run"). Only the
fit's own check chooses: a passing fit is never swapped for another sensor's (at 40 Hz
Low the output sensor's fit also passes, and its run 2 reads the healthy gear at 0.21,
where the input sensor's reads 0.10).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["fit_with_sensor_choice"]


def fit_with_sensor_choice(fit: Callable[[str | None], Any], machine,
                           sensor: str | None) -> tuple[Any, str, str]:
    """Fit with ``sensor``, or choose it (module docstring).

    Parameters
    ----------
    fit : callable
        ``fit(sensor_name)`` → a result whose first item is the fitted estimator (with
        ``fit_check_``): :func:`gearshot.app.predict_machine.fit_machine` passes its fit
        on one sensor (the files read once for all).
    machine : gearshot.Machine
    sensor : str or None
        A named sensor (used as it is) or None (chosen).

    Returns
    -------
    result
        The chosen fit's.
    name : str
        The sensor it used.
    note : str
        "" when the first sensor (or the named one) was used; else why another was.
    """
    if sensor is not None or len(machine.sensors) < 2:
        return fit(sensor), machine.sensor(sensor).name, ""
    kept = None
    refused: list[tuple[str, str]] = []
    for candidate in machine.sensors:
        result = fit(candidate.name)
        check = getattr(result[0], "fit_check_", None)
        if check is not None and check.passed:
            return result, candidate.name, _note(candidate.name, refused)
        refused.append((candidate.name, "unchecked" if check is None else check.verdict))
        if kept is None:
            kept = (result, candidate.name)
        elif check is not None and not check.example_failed:
            # none passes; this one reads its example, where the first did not
            return result, candidate.name, _note(candidate.name, refused[:-1])
        if check is None or not check.example_failed:
            break   # healthy hold-outs read high (or too few): so would another sensor's
    assert kept is not None
    return kept[0], kept[1], ""


def _note(used: str, refused: list[tuple[str, str]]) -> str:
    """Why ``used`` and not the sensors ``refused`` before it ("" when none was)."""
    if not refused:
        return ""
    return f"sensor {used}: the fit on " + "; on ".join(
        f"{name} did not pass its check ({verdict})" for name, verdict in refused)
