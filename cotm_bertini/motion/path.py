"""An actuator path: waypoints of one or more parameters, followed piecewise linearly."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError


@dataclass(frozen=True)
class ActuatorPath:
    """Waypoints (one row each) of the parameters `names`; position s runs from 0 at the first
    waypoint to len(waypoints) - 1 at the last, linearly within each segment."""

    names: tuple[str, ...]
    waypoints: np.ndarray

    @property
    def segments(self) -> int:
        """The number of straight pieces."""
        return len(self.waypoints) - 1

    def at(self, s: float) -> dict[str, float]:
        """The parameter values at position s (0 <= s <= segments)."""
        k = min(int(math.floor(s)), self.segments - 1)
        a, b = self.waypoints[k], self.waypoints[k + 1]
        return {n: float(v) for n, v in zip(self.names, a + (s - k) * (b - a), strict=True)}

    def as_dict(self) -> dict[str, list[float]]:
        """{name: waypoints} (run.json)."""
        return {n: self.waypoints[:, j].tolist() for j, n in enumerate(self.names)}

    def text(self) -> str:
        """The path as a person reads it: `L0c: 1.2 -> 1.6 -> 1.2` (`; ` between parameters)."""
        return "; ".join(f"{n}: " + " -> ".join(f"{v:g}" for v in self.waypoints[:, j])
                         for j, n in enumerate(self.names))  # fmt: skip

    def values_text(self, s: float) -> str:
        """The parameter values at position s: `y = -0.14462` (5 significant digits)."""
        return ", ".join(f"{n} = {v:.5g}" for n, v in self.at(s).items())


def actuator_path(path: Mapping[str, Sequence[float]], known: Mapping[str, float]) -> ActuatorPath:
    """The path {name: [v0, v1, ...]} checked against the model's parameter values `known`
    (names known, numbers finite, the same number of waypoints >= 2 for every name, the
    first waypoint at the model's values); a one-line ParameterError otherwise. A table (a plan's
    `path`: a column a parameter, a row a waypoint) is read as {column: its values}."""
    if hasattr(path, "columns") and hasattr(path, "to_dict"):
        path = {str(c): path[c].tolist() for c in path.columns}
    if not isinstance(path, Mapping) or not path:
        raise ParameterError(f"path = {path!r}: expected {{name: [v0, v1, ...]}} with a name")
    columns, size = [], None
    for name, values in path.items():
        if name not in known:
            raise ParameterError(f"path: {name!r} is no parameter (known: {' '.join(known)})")
        try:
            vals = [float(v) for v in values]
        except (TypeError, ValueError):
            raise ParameterError(f"path {name} = {values!r}: expected numbers") from None
        bad = [v for v in vals if not math.isfinite(v)]
        if bad:
            raise ParameterError(f"path {name}: {bad[0]!r} is not a finite number")
        if len(vals) < 2:
            raise ParameterError(f"path {name} = {vals}: a path needs at least 2 waypoints")
        if size is not None and len(vals) != size:
            raise ParameterError(
                f"path {name}: {len(vals)} waypoints, but the path's other names have {size}"
            )
        if not math.isclose(vals[0], float(known[name]), rel_tol=1e-12, abs_tol=1e-12):
            raise ParameterError(
                f"path {name} starts at {vals[0]:g}, but the solve is at {name} = "
                f"{known[name]:g}: a move starts where its state was solved"
            )
        columns.append(vals)
        size = len(vals)
    return ActuatorPath(tuple(path), np.array(columns, dtype=float).T)
