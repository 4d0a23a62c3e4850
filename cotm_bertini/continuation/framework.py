"""Sweeps of a framework (cb.Framework): what differs from the paper's model.

A sweep spec holds the framework as JSON (`encode`, `decode`: every element and expression, so
a worker, a resumed sweep and the folder's key see exactly the framework the user gave). Points
are solved by `point.solve_framework_point`, each taut set continued from the neighbouring
point by Newton (accepted only with as many distinct nonsingular roots as its generic set,
backends.target.solve_parameters). Branches join rows by their pose and link lengths; events
(framework_events.py) are read from the physical and stable counts and refined by bisection.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import ParameterError
from ..model.framework.expressions import Expr
from ..model.framework.spec import Framework, Link, Load

_TYPES = {cls.__name__: cls for cls in (Framework, Link, Load, Expr)}


def encode(fw: Framework) -> dict:
    """The framework as JSON-able data (see `decode`)."""
    return _encode(fw)


def _encode(value):
    if dataclasses.is_dataclass(value):
        out = {"__type__": type(value).__name__}
        # Fields outside equality (an expression's text, for messages) stay out: the data
        # is part of a sweep's key, which they must not change.
        out.update({f.name: _encode(getattr(value, f.name))
                    for f in dataclasses.fields(value) if f.compare})  # fmt: skip
        return out
    if isinstance(value, tuple | list):
        return [_encode(v) for v in value]
    return value


def decode(data: dict) -> Framework:
    """Inverse of `encode` (every sequence of a framework is a tuple)."""
    return _decode(data)


def _decode(value):
    if isinstance(value, dict):
        cls = _TYPES.get(value.get("__type__"))
        if cls is None:
            raise ParameterError(f"framework data: unknown element {value.get('__type__')!r}")
        return cls(**{k: _decode(v) for k, v in value.items() if k != "__type__"})
    if isinstance(value, list):
        return tuple(_decode(v) for v in value)
    return value


def check_param(fw: Framework, name: str | None, option: str) -> None:
    """Refuse a swept name that is not a parameter of the framework, naming it."""
    if name is not None and name not in fw.values:
        raise ParameterError(
            f"{option} = {name!r}: unknown parameter of framework {fw.name!r} "
            f"(known: {' '.join(fw.values) or 'none'})"
        )


def point_method(details: dict) -> str:
    """How a framework point was solved: its taut sets' methods, each once."""
    if "real_search" in details:
        return "real route (branch and bound)"
    methods = [r["method"] for r in details.get("taut_sets", {}).values() if "method" in r]
    return "; ".join(dict.fromkeys(methods)) or "no taut set solved (continuum only)"


def sweep_names(fw: Framework, swept: list[str]) -> list[str]:
    """The columns of a framework's sweep.csv before `branch`."""
    from ..analysis.framework_classify import column_names

    return ["point", *swept, *column_names(fw), "method", "lost_paths", "status"]


def pose_names(fw: Framework) -> list[str]:
    """The columns that place every body and node: planar angles, quaternions, node positions."""
    axes = "xyz"[: fw.dim]
    names = []
    for body, _ in fw.bodies:
        names += [f"{body}.angle_deg"] if fw.dim == 2 else [f"{body}.q{c}" for c in "wxyz"]
    for node in fw.nodes:
        names += [f"{node}.{a}" for a in axes]
    return names


def match_coordinates(fw: Framework, table) -> np.ndarray:
    """Coordinates of each row for joining branches: its `pose_coordinates` and its distance
    from the real plane, signed to tell a complex-conjugate pair apart."""
    coords = pose_coordinates(fw, table)
    cols = list(coords.T)
    cols.append(_pair_sides(table, cols))
    return np.stack(cols, axis=1).astype(complex)


def pose_coordinates(fw: Framework, table) -> np.ndarray:
    """(rows, coordinates): (cos, sin) of every planar body's angle, the products q_i q_j of
    every spatial body's quaternion (the same for q and -q: a pose whose shown sign flips
    where qw crosses 0 stays on its branch), node positions and link lengths in units of the
    framework's largest length (real parts: a framework's table holds no imaginary parts)."""
    from ..analysis.framework_classify import quaternion_products
    from ..model.framework.units import units

    length = units(fw)[0]
    cols = []
    for name in pose_names(fw):
        values = np.asarray(table[name], dtype=float)
        if name.endswith(".angle_deg"):
            cols += [np.cos(np.radians(values)), np.sin(np.radians(values))]
        elif name.endswith(".qw"):
            body = name[: -len(".qw")]
            q = np.stack([np.asarray(table[f"{body}.q{c}"], float) for c in "wxyz"], axis=1)
            cols += list(quaternion_products(q).T)
        elif not name.endswith((".qx", ".qy", ".qz")):  # those went in with qw
            cols.append(values / length)
    for link in fw.links:
        cols.append(np.asarray(table[f"{link.name}.length"], dtype=float) / length)
    return np.stack(cols, axis=1)


def _pair_sides(table, cols: list[np.ndarray]) -> np.ndarray:
    """+max_imag, and -max_imag for the second row of a complex-conjugate pair (the rows that
    follow each other in a point with equal real parts): the pair's two members then continue
    to their own branches, and the assignment rarely meets a tie."""
    imag = np.asarray(table["max_imag"], dtype=float)
    if len(imag) < 2:
        return imag
    coords = np.stack(cols, axis=1)
    point = np.asarray(table["point"])
    real = np.asarray(table["is_real"], dtype=bool)
    twin = (point[1:] == point[:-1]) & ~real[1:] & ~real[:-1]
    twin &= np.abs(coords[1:] - coords[:-1]).max(axis=1, initial=0.0) < 1e-9
    return imag * np.concatenate([[1.0], np.where(twin, -1.0, 1.0)])


def warm_generic_sets(fw_at, indices: list[int], settings) -> None:
    """Load (or solve) the generic sets of every taut set at the given grid points, once, so
    worker processes start with them (by the route of `settings`: a total-degree set solved
    now is split over its scheduler, if given)."""
    from ..backends.generic import evidence_sets
    from ..model.framework.compiled import framework_system, variable_groups
    from ..model.framework.taut_sets import taut_sets
    from ..model.framework.units import normalized_slots

    for index in indices:
        fw = fw_at(index)
        centre = normalized_slots(fw.at_defaults())
        for taut in taut_sets(fw):
            fs = framework_system(fw, taut)
            if fs.free:
                continue
            middle = {n: centre[n] for n in fs.ps.parameters}
            evidence_sets(fs.ps, settings, middle, variable_groups(fs))
