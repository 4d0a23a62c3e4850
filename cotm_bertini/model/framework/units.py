"""The units a framework is solved in: every number of order one, whatever the user's units.

Lengths are divided by the largest length of the file and stiffnesses by the largest stiffness,
both taken at the file's own parameter values, so the units (and the equations, in which the
numbers that depend on no parameter are written as constants) stay the same across a sweep.
"""

from __future__ import annotations

from functools import lru_cache

# Defined next to the framework (its values are checked against them); used from here.
from .spec import Framework, scale_of, slot_kind, units

__all__ = ["constants", "normalized_slots", "scale_of", "slot_kind", "units"]


def normalized_slots(fw: Framework) -> dict[str, float]:
    """Every slot in the framework's units (a fresh dict: callers may keep or change it)."""
    return dict(_normalized(fw))


@lru_cache(maxsize=256)
def _normalized(fw: Framework) -> tuple[tuple[str, float], ...]:
    length, stiffness = units(fw)
    return tuple((n, v / scale_of(slot_kind(n), length, stiffness)) for n, v in fw.slots().items())


def constants(fw: Framework) -> dict[str, float]:
    """The slots that depend on no parameter, in the framework's units: folded into the
    equations as numbers (zeros drop terms), so they are not homotopy parameters."""
    fixed = fw.constant_slots()
    return {n: v for n, v in normalized_slots(fw).items() if n in fixed}
