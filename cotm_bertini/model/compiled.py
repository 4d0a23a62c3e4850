"""The derived equations as fast numeric code, cached on disk so a solve needs no sympy.

`equations` (sympy) is the source of truth. What it derives is kept in the cache folder: each
structure's ParametricSystem and the paper's tan-half system (whose Jacobian is its stability
criterion) as JSON, and the energy, its gradient and Hessian as a generated Python module. The
cache key is a hash of the derivation's source (equations.py, kinematics.py), so an edit of
either regenerates them.
"""

from __future__ import annotations

import json
import marshal
import sys
import types
from functools import cache, lru_cache
from pathlib import Path

import numpy as np

from ..fs import atomic_write_bytes, atomic_write_text, cache_root, files_hash
from ..params import Params
from .polynomial import ParametricSystem, PolySystem

_SOURCES = tuple(
    Path(__file__).resolve().parent / f
    for f in ("equations.py", "kinematics.py", "symbolic.py", "../literals.py")
)


@cache
def _source_hash() -> str:
    return files_hash(_SOURCES)


def _tag(zfl: tuple[bool, bool]) -> str:
    return "".join("T" if z else "F" for z in zfl)


def _write(path: Path, text: str) -> None:
    atomic_write_text(path, text)


@cache
def parametric_system(zfl: tuple[bool, bool]) -> ParametricSystem:
    """The structure's equations as numbers (from the disk cache, or derived with sympy)."""
    return _cached_system("system", zfl, "derive_parametric")


@cache
def tan_half_parametric(zfl: tuple[bool, bool]) -> ParametricSystem:
    """The paper's tan-half equations (F, tau, C1, C2 in x1, x2, d1, d2) as numbers."""
    return _cached_system("tanhalf", zfl, "derive_tan_half")


def _cached_system(kind: str, zfl: tuple[bool, bool], derive: str) -> ParametricSystem:
    path = cache_root() / "equations" / f"{kind}-{_source_hash()}-{_tag(zfl)}.json"
    if path.is_file():
        try:
            return ParametricSystem.from_json(json.loads(path.read_text()))
        except (ValueError, KeyError):
            pass  # damaged: derive again
    # equations imports sympy (~0.3 s): only a cache miss pays for it, by name so a hit never
    # reaches the module.
    from . import equations

    ps = getattr(equations, derive)(zfl)
    _write(path, json.dumps(ps.to_json()))
    return ps


@lru_cache(maxsize=16)
def polynomial_system(params: Params) -> PolySystem:
    """The equations with the parameter values substituted (the last few kept: a solve asks for
    the same normalised system in several places)."""
    ps = parametric_system(params.zfl)
    return ps.instantiate([getattr(params, n) for n in ps.parameters])


@cache
def _generated():
    path = cache_root() / "equations" / f"numeric-{_source_hash()}.py"
    if not path.is_file():
        from .equations import generated_source

        _write(path, generated_source())
    # The generated source is large: compiling it costs ~0.1 s a process, so the code object is
    # kept too (per Python version), whatever PYTHONDONTWRITEBYTECODE says.
    compiled = path.with_name(f"{path.stem}-{sys.implementation.cache_tag}.code")
    code = None
    if compiled.is_file():
        try:
            code = marshal.loads(compiled.read_bytes())
        except (ValueError, EOFError, TypeError):
            code = None  # damaged: compile again
    if code is None:
        code = compile(path.read_text(), str(path), "exec")
        atomic_write_bytes(compiled, marshal.dumps(code))
    module = types.ModuleType(f"cotm_numeric_{_source_hash()}")
    module.__file__ = str(path)
    exec(code, module.__dict__)
    return module


def _broadcast(value, shape: tuple[int, ...]) -> np.ndarray:
    # Generated code returns a bare scalar for a constant entry; give it the angles' shape.
    return np.broadcast_to(np.asarray(value, dtype=float), shape)


def _values(params: Params) -> list[float]:
    return list(params.as_dict().values())


def energy(params: Params, g1, g2) -> np.ndarray:
    """Potential energy V at angles (radians)."""
    g1, g2 = np.broadcast_arrays(np.asarray(g1, float), np.asarray(g2, float))
    return _broadcast(_generated().energy(g1, g2, *_values(params)), g1.shape)


def energy_gradient(params: Params, g1, g2) -> np.ndarray:
    """Gradient of V, shape (..., 2)."""
    g1, g2 = np.broadcast_arrays(np.atleast_1d(np.asarray(g1, float)), np.atleast_1d(g2))
    vals = _generated().gradient(g1, g2, *_values(params))
    return np.stack([_broadcast(v, g1.shape) for v in vals], axis=-1)


def energy_hessian(params: Params, g1, g2) -> np.ndarray:
    """Hessian of V, shape (..., 2, 2)."""
    g1, g2 = np.broadcast_arrays(np.atleast_1d(np.asarray(g1, float)), np.atleast_1d(g2))
    vals = _generated().hessian(g1, g2, *_values(params))
    flat = [_broadcast(v, g1.shape) for row in vals for v in row]
    return np.stack(flat, axis=-1).reshape(*g1.shape, 2, 2)


def tan_half_jacobian(params: Params, point: tuple) -> np.ndarray:
    """Jacobian of the paper's equations (F, tau, C1, C2) in (x1, x2, d1, d2): one point of
    scalars -> (m, m); or arrays of n points -> (n, m, m)."""
    ps = tan_half_parametric(params.zfl)
    system = ps.instantiate([getattr(params, n) for n in ps.parameters])
    arrays = np.broadcast_arrays(*(np.asarray(v, dtype=complex) for v in point))
    jac = system.jacobian(np.stack([a.ravel() for a in arrays], axis=-1))
    return jac.reshape(*arrays[0].shape, *jac.shape[1:])
