"""The gear pair of a fit: mesh orders from the database's pair, declared teeth checked.

The pair is the source of tooth counts: a simulated database carries its pair as
attributes (:func:`gearshot.sim.load_database`), the SA cycle is one revolution of its
``gear_teeth`` wheel, so that is the mesh order the estimator removes, and target SAs
declared for another pair are refused.
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence
from typing import Any

import numpy as np

from .._errors import GearshotError
from ..paper import GEAR_TEETH

__all__ = ["database_teeth", "check_declared_teeth", "as_orders", "resolve_mesh_orders"]


def database_teeth(database: Any) -> tuple[int, int] | None:
    """(pinion, gear) teeth of a database's gear pair (attributes ``pinion_teeth`` and
    ``gear_teeth``, set by :func:`gearshot.sim.load_database`), or None without them."""
    attrs: Any = getattr(database, "attrs", None)
    try:
        return int(attrs["pinion_teeth"]), int(attrs["gear_teeth"])
    except (KeyError, TypeError, ValueError):
        return None


def check_declared_teeth(have: tuple[int, int] | None, gear_teeth: int | None,
                         pinion_teeth: int | None) -> None:
    """Refuse target SAs segmented for another pair than the database's."""
    for name, value in (("gear_teeth", gear_teeth), ("pinion_teeth", pinion_teeth)):
        if value is not None and (isinstance(value, bool)
                                  or not isinstance(value, numbers.Integral) or value < 1):
            raise GearshotError(f"{name} must be a whole number of teeth >= 1; got {value!r}")
    if have is None:
        return
    pinion, gear = have
    for name, value, wanted, wheel in (("gear_teeth", gear_teeth, gear, "gear"),
                                       ("pinion_teeth", pinion_teeth, pinion, "pinion")):
        if value is not None and int(value) != wanted:
            raise GearshotError(
                f"{name}={int(value)}: the target SAs are segmented for a "
                f"{int(value)}-tooth {wheel}, but the database was simulated for the "
                f"{pinion}/{gear} pair ({name}={wanted}); simulate a database of the "
                f"recordings' pair, or segment them for the {wanted}-tooth {wheel}")


def as_orders(mesh_order: int | Sequence[int] | None) -> tuple[int, ...]:
    """``mesh_order`` as a tuple of ints (``None``: the paper's gear)."""
    if mesh_order is None:
        return (GEAR_TEETH,)
    if isinstance(mesh_order, (int, np.integer)):
        return (int(mesh_order),)
    return tuple(int(v) for v in mesh_order)


def resolve_mesh_orders(mesh_order: int | Sequence[int] | None, database: Any,
                         gear_teeth: int | None, pinion_teeth: int | None) -> tuple[int, ...]:
    """The mesh orders a fit uses: ``mesh_order`` when given, else the database's gear
    teeth, else the declared ``gear_teeth``, else the paper's gear (38); declared teeth
    that differ from the database's pair are refused."""
    have = database_teeth(database)
    check_declared_teeth(have, gear_teeth, pinion_teeth)
    if mesh_order is not None:
        return as_orders(mesh_order)
    if have is not None:
        return (have[1],)
    return (int(gear_teeth) if gear_teeth is not None else GEAR_TEETH,)
