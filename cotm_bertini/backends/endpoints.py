"""The endpoint table every backend produces and classification consumes.

One row per finite path endpoint (a root reached by several paths appears once per path), with
the solver's own diagnostics. Bertini 2 (command or in-process), Bertini 1.x and PHCpack fill it
from their outputs; the closed-form d = 0 roots are rows with `closed_form` set. Where a solver
does not report a field it is NaN.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

# name -> (dtype, meaning); the frame() columns, in this order, before the variables.
FIELDS = {
    "path_number": (np.int64, "the solver's path number; -1 for a root computed in closed form"),
    "condition_number": (float, "the solver's condition-number estimate at the endpoint"),
    "function_residual": (float, "|f| at the endpoint as the solver reports it"),
    "newton_residual": (float, "the last Newton step's size"),
    "final_t": (float, "the path variable where tracking stopped (0: at the target)"),
    "max_precision": (float, "the largest precision used on the path, bits"),
    "accuracy_estimate": (float, "the endgame's accuracy estimate of the endpoint"),
    "cycle_number": (float, "the endgame's cycle number (winding of a singular endpoint)"),
    "bertini_multiplicity": (np.int64, "how many paths the solver says reached this point"),
    "closed_form": (bool, "computed in closed form (a d = 0 root), not tracked"),
}
METADATA_COLUMNS = tuple(FIELDS)


@dataclass(frozen=True, eq=False)
class Endpoints:
    """Finite path endpoints: one entry per path, coordinates in `variables` order."""

    variables: tuple[str, ...]
    points: np.ndarray  # (n, len(variables)), complex
    path_number: np.ndarray
    condition_number: np.ndarray
    function_residual: np.ndarray
    newton_residual: np.ndarray
    final_t: np.ndarray
    max_precision: np.ndarray
    accuracy_estimate: np.ndarray
    cycle_number: np.ndarray
    bertini_multiplicity: np.ndarray
    closed_form: np.ndarray

    def __post_init__(self) -> None:
        n = self.points.shape[0] if self.points.ndim == 2 else 0
        pts = np.asarray(self.points, dtype=complex).reshape(n, len(self.variables))
        object.__setattr__(self, "points", pts)
        for name, (dtype, _) in FIELDS.items():
            col = np.asarray(getattr(self, name), dtype=dtype).reshape(-1)
            if len(col) != n:
                raise ValueError(f"endpoint field {name} has {len(col)} entries, expected {n}")
            object.__setattr__(self, name, col)

    def __len__(self) -> int:
        return self.points.shape[0]

    @classmethod
    def from_records(cls, variables: tuple[str, ...], records: list[dict]) -> Endpoints:
        """From dicts holding any of FIELDS (missing: NaN, 0 or False) and `coords`."""
        n = len(records)
        cols = {}
        for name, (dtype, _) in FIELDS.items():
            missing = {np.int64: 0, bool: False}.get(dtype, np.nan)
            if name == "bertini_multiplicity":
                missing = 1
            cols[name] = np.array([r.get(name, missing) for r in records], dtype=dtype)
        pts = np.array([r["coords"] for r in records], dtype=complex).reshape(n, len(variables))
        return cls(tuple(variables), pts, **cols)

    @classmethod
    def empty(cls, variables: tuple[str, ...]) -> Endpoints:
        """No endpoints."""
        return cls.from_records(variables, [])

    def select(self, index) -> Endpoints:
        """The endpoints at `index` (a boolean mask or integer positions)."""
        cols = {name: getattr(self, name)[index] for name in FIELDS}
        return Endpoints(self.variables, self.points[index], **cols)

    def concat(self, other: Endpoints) -> Endpoints:
        """These endpoints followed by `other`'s (same variables)."""
        if other.variables != self.variables:
            raise ValueError(f"variables differ: {self.variables} vs {other.variables}")
        cols = {n: np.concatenate([getattr(self, n), getattr(other, n)]) for n in FIELDS}
        return Endpoints(self.variables, np.vstack([self.points, other.points]), **cols)

    def with_points(self, points: np.ndarray) -> Endpoints:
        """The same endpoints with other coordinates (e.g. rescaled)."""
        return replace(self, points=np.asarray(points, dtype=complex))

    @property
    def tracked(self) -> int:
        """Endpoints that paths reached (not computed in closed form)."""
        return int((~self.closed_form).sum())

    def frame(self):
        """As a pandas DataFrame: METADATA_COLUMNS, then one complex column per variable."""
        import pandas as pd

        frame = pd.DataFrame({name: getattr(self, name) for name in FIELDS})
        for k, v in enumerate(self.variables):
            frame[v] = self.points[:, k]
        return frame
