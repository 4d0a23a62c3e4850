"""A design map of the stable states alone of a framework in space (`only="stable"`): every grid
point searched for its minima and proved, the fold curves traced from the grid edges where a
minimum vanishes (catastrophe/edge_folds.py). Checked against a statics written here in numpy
(no package code): its minima at every grid point, and at every fold point a vanishing
gradient and a singular Hessian on the sphere; and by sabotage of the curves."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import cotm_bertini as cb
from cotm_bertini.catastrophe import edge_folds

FIXTURE = ROOT / "tests" / "fixtures" / "sphere_three_springs.toml"
WINDOW = ("x", (-1.0, 0.0), "y", (0.0, 1.0))
# The fixture's springs (anchor at x = y = 0, stiffness, free length); x moves the first
# anchor's first coordinate, y the second anchor's third. The node is on the unit sphere.
SPRINGS = (((-0.186, -1.464, -0.388), 0.915, 2.412), ((-1.186, -0.951, 1.001), 0.741, 1.867),
           ((-0.878, -0.059, 1.923), 1.955, 1.445))  # fmt: skip


def _anchors(x, y) -> list[np.ndarray]:
    """The anchors at parameter values x, y (arrays of m): three (m, 3) arrays."""
    x, y = np.broadcast_arrays(np.asarray(x, float), np.asarray(y, float))
    a = [np.tile(np.array(p, dtype=float), (x.size, 1)) for p, _, _ in SPRINGS]
    a[0][:, 0] += x.ravel()
    a[1][:, 2] += y.ravel()
    return a


def _gradient_hessian(R: np.ndarray, x, y) -> tuple[np.ndarray, np.ndarray]:
    """The springs' energy's gradient and Hessian in space at points R (m, 3), each at its own
    parameter values x, y (scalars or arrays of m)."""
    g, H = np.zeros_like(R), np.zeros((len(R), 3, 3))
    for a, (_, k, L0) in zip(_anchors(x, y), SPRINGS, strict=True):
        d = R - a
        n = np.linalg.norm(d, axis=1, keepdims=True)
        g += k * (n - L0) * d / n
        u = d / n
        outer = u[:, :, None] * u[:, None, :]
        H += k * (outer + ((n - L0) / n)[:, :, None] * (np.eye(3) - outer))
    return g, H


def _basis(R: np.ndarray) -> np.ndarray:
    """(m, 3, 2): an orthonormal basis of the tangent plane of the unit sphere at each R."""
    e1 = np.cross(R, np.where(np.abs(R[:, :1]) < 0.9, [[1.0, 0, 0]], [[0, 1.0, 0]]))
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return np.stack([e1, np.cross(R, e1)], axis=2)


def _on_sphere(R: np.ndarray, x, y) -> tuple[np.ndarray, np.ndarray]:
    """The gradient on the unit sphere (tangent part) and the 2 x 2 Riemannian Hessian in a
    tangent basis: E^T H E - (g . R) I."""
    g, H = _gradient_hessian(R, x, y)
    radial = (g * R).sum(axis=1)
    E = _basis(R)
    h = np.einsum("mia,mij,mjb->mab", E, H, E) - radial[:, None, None] * np.eye(2)
    return g - radial[:, None] * R, h


def _minima(xs: np.ndarray, ys: np.ndarray, starts: int = 120) -> np.ndarray:
    """The number of the statics' strict local minima at each grid point (len(ys), len(xs)):
    projected gradient descents from points spread over the sphere, finished by Newton in the
    tangent plane, kept where the Hessian is positive definite, each once."""
    k = np.arange(starts) + 0.5
    z = 1 - 2 * k / starts
    phi = np.pi * (1 + 5**0.5) * k
    S = np.stack([np.sqrt(1 - z * z) * np.cos(phi), np.sqrt(1 - z * z) * np.sin(phi), z], 1)
    X, Y = np.meshgrid(xs, ys)
    x, y = np.repeat(X.ravel(), starts), np.repeat(Y.ravel(), starts)
    R = np.tile(S, (X.size, 1))
    for _ in range(1500):
        t, _ = _on_sphere(R, x, y)
        R = R - 0.05 * t
        R /= np.linalg.norm(R, axis=1, keepdims=True)
    for _ in range(30):
        t, h = _on_sphere(R, x, y)
        E = _basis(R)
        step = np.linalg.solve(h, np.einsum("mia,mi->ma", E, t)[:, :, None])[:, :, 0]
        R = R - np.einsum("mia,ma->mi", E, step)
        R /= np.linalg.norm(R, axis=1, keepdims=True)
    t, h = _on_sphere(R, x, y)
    ok = (np.linalg.norm(t, axis=1) < 1e-10) & (np.linalg.eigvalsh(h)[:, 0] > 1e-9)
    counts = np.zeros(X.size, dtype=int)
    for i in range(X.size):
        found: list[np.ndarray] = []
        for p in R[i * starts : (i + 1) * starts][ok[i * starts : (i + 1) * starts]]:
            if all(np.linalg.norm(p - q) > 1e-6 for q in found):
                found.append(p)
        counts[i] = len(found)
    return counts.reshape(X.shape)


@pytest.fixture(scope="module")
def stable_map():
    fw = cb.Framework.from_toml(FIXTURE)
    return cb.design_map(fw, *WINDOW, points=7, settings=cb.Settings(only="stable"))


def test_a_spatial_map_of_the_stable_states_has_the_statics_minima_at_every_point(stable_map):
    """Each grid point's stable count is the number of minima the numpy statics finds; both
    counts (1 and 2) occur; the map is proved at every point and its check passes."""
    m = stable_map
    grid = m.regions.pivot(index="y", columns="x", values="stable").sort_index()
    xs, ys = grid.columns.to_numpy(float), grid.index.to_numpy(float)
    expected = _minima(xs, ys)
    np.testing.assert_array_equal(grid.to_numpy(int), expected)
    assert set(expected.ravel()) == {1, 2}
    assert m.record["sweep_status"] == "ok" and m.status == "ok"
    assert m.record["unexplained_changes"] == 0 and m.record["count_changes"] > 0


def test_every_fold_point_of_the_spatial_stable_map_is_a_fold_of_the_statics(stable_map):
    """At every traced point the statics' gradient on the sphere vanishes and its Hessian
    there is singular: a fold, where a minimum meets its saddle; the seeds were located by
    Newton on the fold system, on the grid's edges."""
    m = stable_map
    assert len(m.folds) > 10 and set(m.folds["kind"]) <= {"fold", "cusp"}
    for _, row in m.folds.iterrows():
        R = row[["R.x", "R.y", "R.z"]].to_numpy(float)[None, :]
        t, h = _on_sphere(R, row["x"], row["y"])
        assert np.linalg.norm(t) < 1e-8
        assert np.abs(np.linalg.eigvalsh(h[0])).min() < 1e-6
    record = m.record["fold_record"]
    assert record["seeds_located_by_fold_newton"] == record["seeds"] > 0


def test_a_spatial_stable_map_without_its_curves_says_what_it_cannot_explain(monkeypatch):
    """Sabotage: no curve traced from the seeds. The count changes stay, none is explained,
    and the map is incomplete."""
    real = edge_folds.chart_fold_curves

    def none(plane, seeds, xr, yr):
        return real(plane, [], xr, yr)

    monkeypatch.setattr(edge_folds, "chart_fold_curves", none)
    fw = cb.Framework.from_toml(FIXTURE)
    m = cb.design_map(fw, *WINDOW, points=5, settings=cb.Settings(only="stable"))
    assert m.record["count_changes"] > 0
    assert m.record["unexplained_changes"] == m.record["count_changes"]
    assert m.status == "incomplete"
