"""Gradient flow of a framework's energy on its constraint set, for the barriers driver
(analysis/barriers.py).

A state is the framework's configuration unknowns in its normalised units (each body's rotation
(c, s) or unit quaternion, free translations, free nodes). Steps are taken in the local
coordinates of the derivation (planar R0 R(delta), spatial q0 (sqrt(1 - |v|^2), v),
translations and nodes as themselves), so rotations stay exactly unit, then Gauss-Newton
returns the state to the bars' and closing pins' constraints; the gradient is projected onto
the constraints' tangent space. V = sum k/2 (d - L0)^2 over springs, k/2 max(d - L0, 0)^2 over
every cable (so the flow passes a cable's taut/slack switch), minus the loads' work; it is
evaluated from the structure with every cable taut, whose first_order lists every link. Newton's
step uses the Hessian of the Lagrangian of the cables taut at the state, with the constraint
multipliers from least squares.
"""

from __future__ import annotations

import copy
from collections.abc import Callable

import numpy as np
import pandas as pd

from ..model.framework.compiled import framework_system, slot_vector
from ..model.framework.spec import Framework
from ..model.framework.structure import layout
from ..model.framework.units import normalized_slots, units
from .barriers import ZERO_LENGTH
from .framework_classify import (
    local_hessian,
    pose_columns,
    positions,
    reduced_eigh,
    tangent_basis,
)

PROJECT_TOL = 1e-13  # constraint residual (normalised units) a state is returned to
PROJECT_ITERATIONS = 30


class FrameworkFlow:
    """The barriers driver's model of a framework (see the module docstring)."""

    newton_tol = 1e-12
    hessian_unit = 1.0  # the reduced Hessian is in normalised units already

    def __init__(self, fw: Framework, pose_names: list[str],
                 match: Callable[[pd.DataFrame], int | None]):  # fmt: skip
        self.pose_names, self._match = list(pose_names), match
        self.length, self.stiffness = units(fw)
        self.zero_length = ZERO_LENGTH * self.length
        self.length_unit = self.length
        self.lay = layout(fw)
        self.every = framework_system(fw, tuple(c.name for c in fw.cables))
        names = self.every.ps.variables
        self.width = len(names)
        self.config = sum(not v.startswith(("d_", "w_", "mu_")) for v in names)
        self.m = self.every.local_size
        self.links = [x for x in fw.links if x.kind != "bar"]  # as first_order lists them
        self.cable = np.array([x.kind == "cable" for x in self.links], dtype=bool)
        self.index = {p: k for k, p in enumerate(self.every.points)}
        self.ends = (np.array([self.index[x.a] for x in self.links], dtype=int),
                     np.array([self.index[x.b] for x in self.links], dtype=int))  # fmt: skip
        self._systems: dict[tuple[str, ...], object] = {}  # shared by the copies `at` makes
        self._values(fw)

    def _values(self, fw: Framework) -> None:
        """What depends on the parameter values (in the units of the file's own values)."""
        self.fw = fw
        slots = normalized_slots(fw)
        self.P = slot_vector(slots)
        self.k = np.array([slots[f"k_{x.name}"] for x in self.links])
        self.L0 = np.array([slots[f"L0_{x.name}"] for x in self.links])
        axes = "xyz"[: fw.dim]
        self.forces = [(self.index[ld.point], np.array([slots[f"f_{ld.name}_{a}"] for a in axes]))
                       for ld in fw.loads]  # fmt: skip
        self._memo = (b"", np.zeros(0))

    def at(self, fw: Framework) -> FrameworkFlow:
        """The same framework at other parameter values (`fw`: self.fw.replace(...)): the
        structure, units and states are shared, so a state carries over."""
        out = copy.copy(self)
        out._values(fw)
        return out

    # -- evaluation -------------------------------------------------------------------------

    def _full(self, x: np.ndarray, width: int | None = None) -> np.ndarray:
        """Solver variables (rows) with the configuration `x` and zeros elsewhere."""
        x = np.atleast_2d(x)
        X = np.zeros((len(x), width or self.width))
        X[:, : self.config] = x
        return X

    def _call(self, name: str, x: np.ndarray) -> np.ndarray:
        """A generated function of the every-cable-taut structure at one state, as floats."""
        return np.array(getattr(self.every.numeric, name)(self._full(x)[0], self.P), dtype=float)

    def _coords(self, x: np.ndarray) -> np.ndarray:
        """(points, dim) coordinates of every point at one state (normalised units)."""
        key = x.tobytes()
        if self._memo[0] != key:
            self._memo = (key, self._call("positions", x).reshape(-1, self.fw.dim))
        return self._memo[1]

    def _lengths(self, pts: np.ndarray) -> np.ndarray:
        """Spring and cable lengths (normalised) from (..., points, dim) coordinates."""
        return np.linalg.norm(pts[..., self.ends[0], :] - pts[..., self.ends[1], :], axis=-1)

    def _energies(self, pts: np.ndarray) -> np.ndarray:
        """V (J) from (..., points, dim) coordinates."""
        V = np.zeros(pts.shape[:-2])
        if self.links:
            stretch = self._lengths(pts) - self.L0
            stretch = np.where(self.cable, np.maximum(stretch, 0.0), stretch)
            V = V + (self.k / 2 * stretch**2).sum(axis=-1)
        for index, f in self.forces:
            V = V - pts[..., index, :] @ f
        return V * self.stiffness * self.length**2

    def energy(self, x: np.ndarray) -> float:
        """V (J)."""
        return float(self._energies(self._coords(x)))

    def _jacobian(self, x: np.ndarray) -> np.ndarray:
        """The constraint Jacobian (c, m) in local coordinates."""
        if not self.every.constraints:
            return np.zeros((0, self.m))
        return self._call("constraint_jacobian", x).reshape(-1, self.m)

    def _full_gradient(self, x: np.ndarray) -> np.ndarray:
        """dV/dlocal (normalised units), before projection onto the constraints."""
        m, dim = self.m, self.fw.dim
        fo = self._call("first_order", x)
        per = dim + dim * m
        grad = fo[len(self.links) * per :].copy()
        for i, (k, L0, cable) in enumerate(zip(self.k, self.L0, self.cable, strict=True)):
            block = fo[i * per : (i + 1) * per]
            r, J = block[:dim], block[dim:].reshape(dim, m)
            d = float(np.linalg.norm(r))
            stretch = max(d - L0, 0.0) if cable else d - L0
            if L0 == 0:
                coef = k if (stretch > 0 or not cable) else 0.0
            else:
                coef = k * stretch / d if d > 0 else 0.0  # a cone point: no direction
            grad += coef * (r @ J)
        return grad

    def gradient(self, x: np.ndarray) -> np.ndarray:
        """dV/dlocal projected onto the constraints' tangent space (normalised units)."""
        N = tangent_basis(self._jacobian(x), self.m)
        return N @ (N.T @ self._full_gradient(x))

    def newton(self, x: np.ndarray, grad: np.ndarray) -> np.ndarray | None:
        """Newton's step on the constraint set where the reduced Hessian is positive definite."""
        eig, vec = self._reduced_hessian(x)
        if not len(eig) or eig.min() <= 0:
            return None
        return -vec @ ((vec.T @ grad) / eig)

    def eigh(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Eigenvalues (ascending, normalised units) and eigenvectors (local coordinates) of
        the reduced Hessian at x; none where the structure taut at x moves freely."""
        return self._reduced_hessian(x)

    def cable_gap(self, x: np.ndarray) -> float:
        """The smallest |d - L0| over the cables (user length units): 0 at a switch."""
        if not self.cable.any():
            return np.inf
        d = self._lengths(self._coords(x))
        return float(np.abs(d - self.L0)[self.cable].min()) * self.length

    def _reduced_hessian(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Eigenpairs of the Lagrangian's Hessian on the tangent space, for the cables taut at
        x (normalised units); none where that structure moves freely."""
        lengths = self._lengths(self._coords(x))
        taut = tuple(link.name for link, d, L0 in zip(self.links, lengths, self.L0, strict=True)
                     if link.kind == "cable" and d > L0)  # fmt: skip
        fs = self._systems.get(taut)
        if fs is None:  # one lookup a taut set (the structure key costs more than the rest)
            fs = self._systems[taut] = framework_system(self.fw, taut)
        if fs.free:
            return np.zeros(0), np.zeros((self.m, 0))
        X = self._full(x, len(fs.ps.variables))
        G = self._jacobian(x)
        if len(G):
            mu = np.linalg.lstsq(G.T, -self._full_gradient(x), rcond=None)[0]
            X[0, [k for k, v in enumerate(fs.ps.variables) if v.startswith("mu_")]] = mu
        H, G = local_hessian(fs, X, self.P)
        return reduced_eigh(H[0], G[0])

    # -- steps --------------------------------------------------------------------------------

    def _retract(self, x: np.ndarray, step: np.ndarray) -> np.ndarray:
        """The state moved by `step` in local coordinates (rotations stay unit)."""
        y = x.copy()
        width, local = (2, 1) if self.fw.dim == 2 else (4, 3)
        nrot = len(self.lay.rotations)
        for i in range(nrot):
            q, v = x[i * width : (i + 1) * width], step[i * local : (i + 1) * local]
            if self.fw.dim == 2:
                c, s = np.cos(v[0]), np.sin(v[0])
                new = np.array([q[0] * c - q[1] * s, q[1] * c + q[0] * s])
            else:
                from ..model.framework.derive import quaternion_product

                w = np.sqrt(max(1.0 - float(v @ v), 0.0))
                new = np.array(quaternion_product(list(q), [w, *v]), dtype=float)
            y[i * width : (i + 1) * width] = new / np.linalg.norm(new)
        y[nrot * width : self.config] += step[nrot * local :]
        return y

    def move(self, x: np.ndarray, step: np.ndarray) -> np.ndarray:
        """The state moved by `step`, then returned to the constraint set (Gauss-Newton)."""
        y = self._retract(x, np.asarray(step, dtype=float))
        if not self.every.constraints:
            return y
        for _ in range(PROJECT_ITERATIONS):
            g = self._call("constraint_values", y)
            if np.abs(g).max() < PROJECT_TOL:
                break
            y = self._retract(y, -np.linalg.lstsq(self._jacobian(y), g, rcond=None)[0])
        return y

    def shortest(self, x: np.ndarray) -> float:
        """The shortest spring or cable (user length units)."""
        if not self.links:
            return np.inf
        return float(self._lengths(self._coords(x)).min()) * self.length

    # -- the solutions table ------------------------------------------------------------------

    def saddles(self, solutions: pd.DataFrame) -> pd.DataFrame:
        """The physical critical points of index 1 (in one degree of freedom: the maxima)."""
        phys = solutions[solutions.physical.astype(bool)]
        return phys[phys.kind.isin(["saddle", "max"]) & (phys["index"] == 1)]

    def saddle(self, row) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The saddle's state (from its pose columns, on the constraint set), the reduced
        Hessian's eigenvalues (normalised units) and the unstable eigenvector (local)."""
        x0 = self.state(row)
        eig, vec = self._reduced_hessian(x0)
        return x0, eig, vec[:, 0]

    def state(self, row) -> np.ndarray:
        """A solutions row's state, on the constraint set."""
        return self.move(self._pose_state(row), np.zeros(self.m))

    def _pose_state(self, row) -> np.ndarray:
        parts, axes = [], "xyz"[: self.fw.dim]
        for body in self.lay.rotations:
            if self.fw.dim == 2:
                angle = np.radians(float(row[f"{body}.angle_deg"]))
                parts += [np.cos(angle), np.sin(angle)]
            else:
                parts += [float(row[f"{body}.q{c}"]) for c in "wxyz"]
        for ent in self.lay.translations + self.lay.free_nodes:
            parts += [float(row[f"{ent}.{a}"]) / self.length for a in axes]
        return np.array(parts, dtype=float)

    def pose(self, row) -> dict:
        """The saddle's pose columns, as in solutions.csv."""
        return {name: float(row[name]) for name in self.pose_names}

    def rows(self, path: np.ndarray) -> pd.DataFrame:
        """States as solutions.csv-style rows: pose columns, every link's length, each spring's
        and cable's tension (and whether a cable is taut), V (J)."""
        return pd.DataFrame(self.columns(path))

    def columns(self, path: np.ndarray) -> dict[str, np.ndarray]:
        """The columns of `rows`, as numpy arrays."""
        X = self._full(path)
        var = {name: X[:, k] for k, name in enumerate(self.every.ps.variables)}
        pts = positions(self.every, X, self.P, self.fw.dim, self.length)
        cols = pose_columns(self.fw, self.every, var, pts)
        force = self.stiffness * self.length  # the file's force unit
        for x in self.fw.links:
            d = np.linalg.norm(pts[x.a].real - pts[x.b].real, axis=1)
            cols[f"{x.name}.length"] = d
            if x.kind == "bar":
                continue
            slot = self.links.index(x)
            stretch = d / self.length - self.L0[slot]
            if x.kind == "cable":
                cols[f"{x.name}.taut"] = stretch > 0
                stretch = np.maximum(stretch, 0.0)
            cols[f"{x.name}.tension"] = force * self.k[slot] * stretch
        cols["energy"] = self._energies(
            np.stack([pts[p].real for p in self.every.points], axis=1) / self.length
        )
        return cols

    def match(self, end: np.ndarray) -> int | None:
        """The solution_id of the minimum the descent ended at (None: not a listed minimum)."""
        return self._match(self.rows(end))

    def record(self, path: np.ndarray) -> pd.DataFrame:
        """A path as rows: `arc` (length along it in the configuration unknowns: rad for
        rotations, length units for positions), `energy` (J), pose columns, link lengths."""
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
        return self.rows(path).assign(arc=arc)
