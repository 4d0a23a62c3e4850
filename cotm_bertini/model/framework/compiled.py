"""A framework's equations as numbers: derived once per structure, cached on disk.

A structure is the framework's topology with a taut set of cables and its zero-free-length
springs; its parametric system (in the slots) and generated numpy code are kept under the cache
folder, keyed by a hash of the structure and of the derivation code, so a solve needs no sympy.
A planar framework on a circle or torus is derived without sympy at all (planar.py).
"""

from __future__ import annotations

import json
import types
from dataclasses import asdict, dataclass

import numpy as np

from ...errors import ParameterError
from ...fs import atomic_write_text, cache_root
from ..polynomial import ParametricSystem
from .spec import Framework
from .structure import Derived, structure_key
from .units import scale_of


@dataclass(frozen=True, eq=False)
class FrameworkSystem:
    """One structure's equations: the parametric system and the numeric helpers."""

    key: str
    taut: tuple[str, ...]
    ps: ParametricSystem
    kinds: tuple[str, ...]
    descriptions: tuple[str, ...]
    free: tuple[str, ...]
    points: tuple[str, ...]
    local_size: int
    constraints: int
    numeric: types.ModuleType  # positions, hessian, constraint_jacobian, first_order (X, P)
    active: tuple[str, ...]  # springs and taut cables, as first_order lists them
    cones: dict[str, ParametricSystem]  # zero-length poses of each spring (two-body torus)
    source: str = ""  # the generated code, kept: the ball and interval evaluations compile it
    # from here, not from the disk cache, which may be cleared while this process runs


_LOADED: dict[str, FrameworkSystem] = {}


def framework_system(fw: Framework, taut: tuple[str, ...], label: str = "") -> FrameworkSystem:
    """The structure's system, from memory, the disk cache, or derived with sympy (saying so
    every few seconds when that takes long; `label` names the taut set, e.g. "taut set 2/4")."""
    key = structure_key(fw, taut)
    if key in _LOADED:
        return _LOADED[key]

    def fresh() -> Derived:
        from .planar import derive_planar, planar_torus

        if planar_torus(fw):  # exact polynomials in a few ms, no sympy (derive's equations)
            return derive_planar(fw, tuple(sorted(taut)))
        from ...progress import Progress
        from .derive import derive

        names = " ".join(taut) or "none"
        stage = f"deriving the equations of {fw.name}, " + (
            f"{label} ({names})" if label else f"taut set {names}")  # fmt: skip
        with Progress(stage, None, "", heartbeat=True) as report:
            return derive(fw, tuple(sorted(taut)), step=lambda what: report.update(0, note=what))

    derived, module = cached_derivation(f"system-{key}", Derived, fresh)
    out = FrameworkSystem(
        key, tuple(sorted(taut)), ParametricSystem.from_json(derived.system),
        tuple(derived.kinds), tuple(derived.descriptions), tuple(derived.free),
        tuple(derived.points), derived.local_size, derived.constraints, module,
        tuple(derived.active),
        {k: ParametricSystem.from_json(v) for k, v in derived.cones.items()}, derived.source,
    )  # fmt: skip
    _LOADED[key] = out
    return out


def check_terms(fw: Framework, fs: FrameworkSystem, slots: dict[str, float]) -> None:
    """Refuse values (`slots`, normalized) at which an equation loses every term: what
    spec.check_geometry refuses and anything it does not foresee; solving would find a
    continuum, or a numpy traceback, not equilibria."""
    system = fs.ps.instantiate([slots[n] for n in fs.ps.parameters])
    for what, coeffs in zip(fs.descriptions, system.coefficients, strict=True):
        if not len(coeffs):
            values = ", ".join(f"{p} = {v:.15g}" for p, v in fw.parameters) or "its values"
            raise ParameterError(
                f"{values}: framework {fw.name!r}, equation {what}: every term is 0 there "
                "(nothing resists that motion at these values: a continuum of equilibria)"
            )


def cached_derivation(name: str, kind: type, derive) -> tuple:
    """A derivation (dataclass `kind` with generated `source`) from the disk cache, or derived
    and stored; with its generated code compiled into a module: (data, module)."""
    path = cache_root() / "frameworks" / f"{name}.json"
    data = None
    if path.is_file():
        try:
            data = kind(**json.loads(path.read_text()))
        except (ValueError, TypeError):
            data = None  # damaged: derive again
    if data is None:
        data = derive()
        atomic_write_text(path, json.dumps(asdict(data)))
    module = types.ModuleType(f"cotm_{name.replace('-', '_')}")
    exec(compile(data.source, str(path), "exec"), module.__dict__)
    return data, module


def variable_groups(fs: FrameworkSystem) -> list[list[str]]:
    """Variable groups of a multihomogeneous start: each body's rotation, all translations and
    node coordinates together, each pin's force, and each length, force density and bar
    multiplier on its own (on
    the paper's mechanism 224 paths instead of a total degree of 576)."""
    groups: dict[str, list[str]] = {}
    for v in fs.ps.variables:
        head, _, rest = v.partition("_")
        if head in ("c", "s") or head.startswith("q"):
            key = "rot " + rest
        elif head in ("t", "n"):
            key = "positions"
        elif head == "mu" and rest.startswith("pin"):
            key = "force " + rest.rsplit("_", 1)[0]  # a pin's force components together
        else:
            key = v
        groups.setdefault(key, []).append(v)
    return list(groups.values())


def variable_scale(fs: FrameworkSystem, unit: tuple[float, float]) -> np.ndarray:
    """The unit of each solver variable (multiply a normalised solution by it)."""
    return np.array([scale_of(k, *unit) for k in fs.kinds])


def slot_vector(slots: dict[str, float]) -> np.ndarray:
    """Every slot's value in the order the generated code reads them (the framework's order)."""
    return np.array(list(slots.values()), dtype=float)
