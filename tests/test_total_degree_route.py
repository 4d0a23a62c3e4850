"""The complex route's total-degree generic sets (issue 40, item 5): the route each taut set
takes by default (backends.generic.route_choice: total degree when its two seeds track at most
TOTAL_DEGREE_PATHS paths), and the total-degree start tracked on a projective patch.

References: the path counts are the Bezout numbers of the degrees read off the exponents,
expanded with sympy (test_progress.bezout); the roots of a hand-written system are found by
eliminating down to one polynomial in y solved by numpy (np.roots), and every root's residual is
evaluated here with numpy."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, same_sets
from test_progress import bezout

import cotm_bertini as cb
from cotm_bertini.backends import generic, homotopy
from cotm_bertini.model.polynomial import ParametricSystem

XMODULE = ROOT / "examples" / "xmodule.toml"


def _bezout_counts(fw) -> list[int]:
    """Each taut set's multihomogeneous Bezout number, in cost's order (framework_system's
    equations, counted here from their exponents)."""
    from cotm_bertini.model.framework.compiled import framework_system, variable_groups
    from cotm_bertini.model.framework.taut_sets import split_taut_sets

    out = []
    for taut in split_taut_sets(fw)[0]:
        fs = framework_system(fw, taut)
        groups = variable_groups(fs)
        system = fs.ps.instantiate([0.3 + 0.7j] * len(fs.ps.parameters))
        col = {v: k for k, v in enumerate(system.variables)}
        degrees = [[int(max(e[:, [col[v] for v in g]].sum(axis=1))) for g in groups]
                   for e in system.exponents]  # fmt: skip
        out.append(bezout(np.array(degrees), [len(g) for g in groups]))
    return out


def test_each_taut_set_takes_the_route_its_path_count_gives(monkeypatch):
    """cb.cost states per taut set the route the rule gives on its own Bezout number (two seeds
    of it against TOTAL_DEGREE_PATHS), and why; the solve's own choice (route_of on the set's
    system) is the same; an explicit generic wins."""
    from cotm_bertini.model.framework.compiled import framework_system, variable_groups

    fw = cb.Framework.from_toml(XMODULE)
    counts = _bezout_counts(fw)
    assert sorted(counts) == [48, 128, 128, 352]
    complex_route = cb.Settings(route="complex")
    for limit in (generic.TOTAL_DEGREE_PATHS, 2 * 200, 2 * 100):
        monkeypatch.setattr(generic, "TOTAL_DEGREE_PATHS", limit)
        c = cb.cost(fw, complex_route, sample=False)
        want = ["total-degree" if 2 * n <= limit else "monodromy" for n in counts]
        assert [s.paths for s in c.sets] == counts
        assert [s.route for s in c.sets] == want
        for s in c.sets:
            assert f"{s.paths:,} paths {'<=' if s.route == 'total-degree' else '>'}" in s.why
            assert len(s.seeds) == (2 if s.route == "total-degree" else 1)
            fs = framework_system(fw, s.taut)
            assert generic.route_of(complex_route, fs.ps, variable_groups(fs)) == s.route
        lines = "\n".join(c.lines())
        assert all(f"by {r} (" in lines for r in set(want))
    mono = cb.cost(fw, cb.Settings(route="complex", generic="monodromy"), sample=False)
    assert {s.route for s in mono.sets} == {"monodromy"} and np.isnan(mono.estimate)


# A hand-written system of total degree 2 x 2 x 3 = 12 with one parameter p: a sphere, a second
# quadric whose difference with it is the plane x + 2y = p - 1, and a cubic. Its finite roots
# lie on a circle (degree 2) and the cubic: 6; the other 6 paths go to infinity.
TERMS = (  # per function: (coefficient, exponents of x y z, exponent of p)
    ((1, (2, 0, 0), 0), (1, (0, 2, 0), 0), (1, (0, 0, 2), 0), (-1, (0, 0, 0), 0)),
    ((1, (2, 0, 0), 0), (1, (0, 2, 0), 0), (1, (0, 0, 2), 0), (1, (1, 0, 0), 0),
     (2, (0, 1, 0), 0), (-1, (0, 0, 0), 1)),
    ((1, (1, 1, 1), 0), (1, (0, 0, 2), 0), (-0.1, (1, 1, 0), 0), (-0.2, (0, 0, 0), 0)),
)  # fmt: skip


def _system() -> ParametricSystem:
    def column(k: int, width: int) -> tuple:
        return tuple(np.array([t[k] for t in f], dtype=np.int64).reshape(-1, width) for f in TERMS)

    return ParametricSystem(
        ("x", "y", "z"), ("f1", "f2", "f3"), ("p",), column(1, 3), column(2, 1),
        tuple(np.array([t[0] for t in f], dtype=float) for f in TERMS), (),
    )  # fmt: skip


def _residual(points: np.ndarray, p: complex) -> np.ndarray:
    x, y, z = points.T
    return np.abs(np.stack([
        x**2 + y**2 + z**2 - 1,
        x**2 + y**2 + z**2 + x + 2 * y - p,
        x * y * z + z**2 - 0.1 * x * y - 0.2,
    ])).max(axis=0)  # fmt: skip


def _roots(p: complex) -> np.ndarray:
    """The finite roots by elimination: x = p - 1 - 2y (f2 - f1), z^2 = 1 - x^2 - y^2 (f1), and
    f3 as z (xy) = 0.1 xy + 0.2 - z^2, squared: a polynomial of degree 6 in y; z from f3."""
    y = np.polynomial.Polynomial([0, 1])
    x = p - 1 - 2 * y
    z2 = 1 - x**2 - y**2
    rest = 0.1 * x * y + 0.2 - z2
    ys = (z2 * (x * y) ** 2 - rest**2).roots()
    xs, zs = p - 1 - 2 * ys, (0.1 * (p - 1 - 2 * ys) * ys + 0.2 - z2(ys)) / ((p - 1 - 2 * ys) * ys)
    return np.stack([xs, ys, zs], axis=1)


def test_projective_total_degree_solve_finds_the_affine_solves_roots(monkeypatch, tmp_path):
    """The generic set by the total-degree route (on a projective patch) of a system with paths
    to infinity: its roots are the 6 of the elimination, each with a residual below 1e-8 in
    the system written here; tracking the same start and homotopy affinely ends at the same
    roots; the paths to infinity ended in double precision on the patch (no adaptive retrack
    of them), while affinely they failed there and were tracked again."""
    monkeypatch.setenv("COTM_CACHE", str(tmp_path))
    ps = _system()
    gs = homotopy.generic_set(ps, 3, use_cache=False, centre={"p": 0.4})
    p = gs.start["p"]
    reference = _roots(p)
    assert len(reference) == 6 and _residual(reference, p).max() < 1e-8
    assert gs.paths == 12 and gs.route["method"].startswith("own total-degree")
    assert len(gs.points) == 6 and _residual(gs.points, p).max() < 1e-8  # the endgame's 1e-8
    assert same_sets(gs.points, reference)
    system = ps.instantiate([p])
    lp, texts = homotopy.own_start(system, None, 3)
    starts = np.array(list(lp.points()))[:, lp.declared]
    affine = homotopy.double_then_adaptive(texts, starts, {"projective": False})
    ok = [i for i, c in enumerate(affine["codes"]) if c == "Success" and affine["finite"][i]]
    assert len(ok) == 6 and same_sets(affine["points"][ok], gs.points)
    assert gs.route["retracked_adaptive"] < affine["retracked_adaptive"]


@pytest.mark.slow
def test_xmodule_complex_first_solve_equals_an_independent_newton_search(monkeypatch, tmp_path):
    """The X-module's first solve by the complex route (an empty cache; about 40 CPU s, every
    taut set by total degree on the patch, two seeds agreeing): status ok and the 12 physical
    rows of the Newton search on the energy written in test_real_route (`make stress`)."""
    from test_real_route import MATCH_DEG, _pair, _x_reference

    from cotm_bertini.model.framework import compiled

    monkeypatch.setenv("COTM_CACHE", str(tmp_path))
    monkeypatch.setattr(compiled, "_LOADED", {})
    monkeypatch.setattr(homotopy, "_LOADED", {})
    theta, V, eig = _x_reference()
    res = cb.solve(cb.Framework.from_toml(XMODULE), route="complex", cache=False)
    assert res.status == "ok", res.warnings
    for record in res.record["details"]["taut_sets"].values():
        sets = record["generic_route"]["generic_sets"]
        assert len(sets) == 2 and all(g["method"].startswith("own multihomogeneous") for g in sets)
    rows = res.physical
    pick, gap = _pair(rows[["bar1.angle_deg", "bar2.angle_deg"]].to_numpy(float),
                      np.degrees(theta))  # fmt: skip
    assert len(rows) == 12 and gap.max() < MATCH_DEG
    np.testing.assert_allclose(rows.iloc[pick]["energy"], V, atol=1e-10)
    assert int(res.counts["stable"]) == int((eig > 0).all(axis=1).sum())
