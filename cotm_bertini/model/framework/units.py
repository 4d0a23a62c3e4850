"""The units a framework is solved in: every number of order one, whatever the user's units.

Lengths are divided by the largest length of the file and stiffnesses by the largest stiffness,
both taken at the file's own parameter values, so the units (and the equations, in which the
numbers that depend on no parameter are written as constants) stay the same across a sweep.
"""

from __future__ import annotations

from functools import lru_cache

from .spec import Framework

# How each slot scales with the length unit L and the stiffness unit k.
_SLOT_KINDS = {"g_": "len", "b_": "len", "len_": "len", "L0_": "len", "k_": "k", "f_": "force"}


def slot_kind(name: str) -> str:
    """len, k or force: how a slot scales."""
    return next(kind for prefix, kind in _SLOT_KINDS.items() if name.startswith(prefix))


def scale_of(kind: str, length: float, stiffness: float) -> float:
    """The unit of a quantity of this kind: rot 1, len L, k k, force k L."""
    return {"rot": 1.0, "len": length, "k": stiffness, "force": stiffness * length}[kind]


@lru_cache(maxsize=256)
def units(fw: Framework) -> tuple[float, float]:
    """(length unit, stiffness unit): the largest length and the largest k at the file's values."""
    slots = fw.at_defaults().slots()
    lengths = [abs(v) for n, v in slots.items() if slot_kind(n) == "len" and v != 0]
    ks = [v for n, v in slots.items() if n.startswith("k_")]
    return (max(lengths) if lengths else 1.0), (max(ks) if ks else 1.0)


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
