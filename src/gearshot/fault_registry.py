"""The fault types gearshot knows: one record per type, read by every layer.

Each :class:`FaultTypeRecord` says, once, everything the layers need to agree on:

=========  ========================================================================
field      used by
=========  ========================================================================
name       everyone: ``simulate_sa(fault_type=...)``, ``build_database(fault_types=
           ...)``, the estimator's ``fault_type``, ``gearshot simulate --fault-type``
class_     the simulator: the class (in :mod:`gearshot.sim`) whose ``size`` a
           signal's fault size sets (:func:`gearshot.sim.fault_types.fault_class`)
code       the database: the type's number in each block's seed (``SeedSequence(seed,
           spawn_key=(i, j, k, code))``, the FTFF (code 0) keeping ``(i, j, k)``)
version    the database: the model version recorded in a store's manifest; a store of
           an older model of a type is refused rather than mixed with new SAs
options    the simulator: which of ``simulate_sa``'s shared fault options (``center``,
           ``depth``) the type takes
=========  ========================================================================

The codes are written out, never derived from an order: they are the values every store
and seed built so far carry (0 ... 3 in the order the types were added), and a new type
takes the next free code. Bump ``version`` when a type's geometry or physics changes
(breakage 2: the growth path over the face share).

This module imports nothing of the simulator (nor numba), so the estimator and the command
line may import it::

    from gearshot.fault_registry import FAULT_TYPE_NAMES, fault_type_record

Examples
--------
>>> from gearshot.fault_registry import FAULT_TYPE_NAMES, fault_type_record
>>> FAULT_TYPE_NAMES
('ftff', 'partial_face', 'breakage', 'destruction')
>>> rec = fault_type_record("breakage")
>>> rec.class_, rec.code, rec.version, rec.options
('ToothBreakage', 2, 2, ())
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from ._errors import GearshotError

__all__ = ["FaultTypeRecord", "FAULT_TYPE_RECORDS", "FAULT_TYPE_NAMES", "fault_type_record",
           "check_fault_type"]


@dataclass(frozen=True)
class FaultTypeRecord:
    """One fault type (see the module docstring for who reads which field).

    Parameters
    ----------
    name : str
        The type's name (``"ftff"``, ...).
    class_ : str
        Name of its fault class in :mod:`gearshot.sim`.
    code : int
        Its number in database seeds (stable: never reused, never moved).
    version : int
        Version of its model in database manifests.
    options : tuple of str
        The shared simulator options (``center``, ``depth``) it takes.
    """

    name: str
    class_: str
    code: int
    version: int
    options: tuple[str, ...] = ()


_RECORDS = (
    FaultTypeRecord("ftff", "FullToothFaceFault", code=0, version=1,
                    options=("center", "depth")),
    FaultTypeRecord("partial_face", "PartialFaceFault", code=1, version=1,
                    options=("center", "depth")),
    FaultTypeRecord("breakage", "ToothBreakage", code=2, version=2),
    FaultTypeRecord("destruction", "ToothDestruction", code=3, version=1,
                    options=("center",)),
)

#: name -> :class:`FaultTypeRecord`, in code order (read-only).
FAULT_TYPE_RECORDS: Mapping[str, FaultTypeRecord] = MappingProxyType(
    {r.name: r for r in sorted(_RECORDS, key=lambda r: r.code)})

#: The fault type names, in code order.
FAULT_TYPE_NAMES: tuple[str, ...] = tuple(FAULT_TYPE_RECORDS)


def check_fault_type(name: object) -> str:
    """``name`` if it names a fault type, else a :class:`~gearshot.GearshotError`.

    Examples
    --------
    >>> check_fault_type("ftff")
    'ftff'
    """
    if not isinstance(name, str) or name not in FAULT_TYPE_RECORDS:
        raise GearshotError(f"fault_type must be one of {sorted(FAULT_TYPE_RECORDS)}; "
                            f"got {name!r}")
    return name


def fault_type_record(name: object) -> FaultTypeRecord:
    """The record of fault type ``name`` (a :class:`~gearshot.GearshotError` naming the
    known types when there is none).

    Examples
    --------
    >>> fault_type_record("ftff").code
    0
    """
    return FAULT_TYPE_RECORDS[check_fault_type(name)]
