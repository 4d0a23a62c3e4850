"""The real route (issue 40): a framework on a circle or torus solved by the branch and bound
over its body angles, checked against routes that share no code with it: an X-module's energy
written here in plain numpy (Newton from a grid), the paper's built-in model solved by Bertini,
the complex route, and interval arithmetic against 50-digit mpmath at sampled points."""

from __future__ import annotations

import json
import subprocess
import sys

import mpmath
import numpy as np
import pytest
from conftest import ROOT, lose_first_root

import cotm_bertini as cb
from cotm_bertini.cli.main import main as cli_main
from cotm_bertini.model.intervals import Interval

XMODULE = ROOT / "examples" / "xmodule.toml"
MATCH_DEG = 1e-8


# --- interval arithmetic ------------------------------------------------------------------------
def _random_intervals(rng, n, scale=3.0, positive=False):
    a, b = rng.normal(0, scale, n), rng.normal(0, scale, n)
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    if positive:
        lo, hi = np.abs(lo) + 1e-3, np.abs(lo) + 1e-3 + np.abs(hi - lo)
    # some degenerate and some tiny intervals, where rounding matters most
    lo[:20], hi[:20] = lo[:20], lo[:20]
    hi[20:40] = lo[20:40] + 1e-15
    return lo, hi


def _samples(lo, hi, rng):
    t = np.concatenate([[0.0, 1.0], rng.uniform(0, 1, 3)])
    return [np.clip(lo + s * (hi - lo), lo, hi) for s in t]  # a float sum may pass hi


@pytest.mark.parametrize(
    "name, op, exact, positive",
    [
        ("add", lambda a, b: a + b, lambda x, y: x + y, False),
        ("sub", lambda a, b: a - b, lambda x, y: x - y, False),
        ("mul", lambda a, b: a * b, lambda x, y: x * y, False),
        ("div", lambda a, b: a / b, lambda x, y: x / y, True),
        ("square", lambda a, b: a * a, lambda x, y: x * x, False),
        ("cube", lambda a, b: a**3, lambda x, y: x**3, False),
        ("sqrt", lambda a, b: b.sqrt(), lambda x, y: mpmath.sqrt(y), True),
        ("pow1.5", lambda a, b: b ** (3 / 2), lambda x, y: y ** mpmath.mpf(1.5), True),
        ("sin", lambda a, b: a.sin(), lambda x, y: mpmath.sin(x), False),
        ("cos", lambda a, b: a.cos(), lambda x, y: mpmath.cos(x), False),
        ("scalar", lambda a, b: 0.7 - 1.3 * a / 2.9, lambda x, y: 0.7 - 1.3 * x / 2.9, False),
    ],
)
def test_intervals_enclose_every_sampled_value(name, op, exact, positive):
    rng = np.random.default_rng(abs(hash(name)) % 2**32)
    alo, ahi = _random_intervals(rng, 400)
    blo, bhi = _random_intervals(rng, 400, positive=positive)
    out = op(Interval(alo, ahi), Interval(blo, bhi))
    mpmath.mp.dps = 50
    for xs, ys in zip(_samples(alo, ahi, rng), _samples(blo, bhi, rng), strict=True):
        for i in range(len(xs)):
            v = exact(mpmath.mpf(float(xs[i])), mpmath.mpf(float(ys[i])))
            assert mpmath.mpf(float(out.lo[i])) <= v <= mpmath.mpf(float(out.hi[i])), (name, i)
    # Not wider than needed: the enclosure of a degenerate input is within 1e-14 of the value.
    assert np.all(out.hi[:20] - out.lo[:20] <= 1e-13 * (1 + np.abs(out.lo[:20])))


def test_sin_sees_the_crest_inside_an_interval():
    box = Interval(np.array([1.0, 7.0, -2.0]), np.array([2.0, 8.0, -1.0]))  # pi/2, 5pi/2, -pi/2
    s = box.sin()
    assert s.hi[0] == 1.0 and s.hi[1] == 1.0 and s.lo[2] == -1.0


def test_an_unbounded_interval_warns_nothing_and_reads_as_not_finite():
    """Issue 46: a map printed numpy's raw `invalid value encountered in add` (the midpoint of
    [-inf, inf], a Krawczyk step's Hessian): the outcome, NaN, is "not finite" to its callers,
    so it is computed without a warning; so is 0 to a negative real power (unbounded)."""
    import warnings

    whole = Interval(np.array([-np.inf, 1.0]), np.array([np.inf, 3.0]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mid = whole.mid
        power = Interval(np.array([0.0, 1.0]), np.array([0.0, 4.0])) ** -0.5
    assert np.isnan(mid[0]) and mid[1] == 2.0 and not np.isfinite(mid).all()
    assert power.hi[0] == np.inf and not power.finite()[0] and power.finite()[1]


def test_a_number_per_box_is_exact_where_one_given_alone_is():
    """Numbers per box (a family's parameters, search_each) give each box the bounds the same
    number alone gives it: x * 1 and x + 0 stay exact (not widened by an ulp), any other
    number rounded outwards as alone."""
    x = Interval(np.array([0.1, 0.2, 0.3, -0.7]), np.array([0.25, 0.5, 0.9, 0.4]))
    for c in (np.array([1.0, 2.5, 0.0, -1.0]), np.array([0.0, 1.0, 1e-3, 3.0])):
        for op in (lambda u, v: u * v, lambda u, v: v * u, lambda u, v: u + v):
            per_box = op(x, c)
            for i, ci in enumerate(c):
                alone = op(Interval(x.lo[i], x.hi[i]), float(ci))
                assert (per_box.lo[i], per_box.hi[i]) == (alone.lo, alone.hi), (i, ci)
    assert (x * np.ones(4)).lo[0] == 0.1 and (x + np.zeros(4)).hi[2] == 0.9


# --- the X-module against an energy written here -------------------------------------------------
# examples/xmodule.toml: bars from a = (0, 0) and b = (1, 0), length 1.3; spring between the tips
# (k 1, L0s); cables bar1 tip - b and bar2 tip - a (k 2, L0c), tension only; load fy on bar1's tip.
def _x_energy(t, L1=1.3, L0s=0.6, L0c=1.2, fy=-0.05):
    """V and its exact gradient at angles t (N, 2)."""
    t1, t2 = t[:, 0], t[:, 1]
    p = np.stack([L1 * np.cos(t1), L1 * np.sin(t1)], axis=1)
    q = np.stack([1.0 + 1.3 * np.cos(t2), 1.3 * np.sin(t2)], axis=1)
    dp = np.stack([-L1 * np.sin(t1), L1 * np.cos(t1)], axis=1)
    dq = np.stack([-1.3 * np.sin(t2), 1.3 * np.cos(t2)], axis=1)
    zero = np.zeros_like(p)
    links = [  # (vector, its derivative in t1, in t2, k, L0, cable)
        (p - q, dp, -dq, 1.0, L0s, False),
        (p - np.array([1.0, 0.0]), dp, zero, 2.0, L0c, True),
        (q, zero, dq, 2.0, L0c, True),
    ]
    V, g = -fy * p[:, 1], np.stack([-fy * dp[:, 1], np.zeros(len(t))], axis=1)
    for r, r1, r2, k, L0, cable in links:
        d = np.linalg.norm(r, axis=1)
        stretch = np.maximum(d - L0, 0.0) if cable else d - L0
        V = V + 0.5 * k * stretch**2
        w = k * stretch / d
        g = g + w[:, None] * np.stack([(r * r1).sum(1), (r * r2).sum(1)], axis=1)
    return V, g


def _x_reference(**values):
    """Every critical point: Newton (finite-difference Hessian of the exact gradient) from a
    48 x 48 grid, ends with |grad| < 1e-11, one per point of the torus."""
    grid = np.linspace(0, 2 * np.pi, 48, endpoint=False) + 0.013
    t = np.array([(a, b) for a in grid for b in grid])
    h = 1e-6

    def hess(t):
        cols = [(_x_energy(t + h * e, **values)[1] - _x_energy(t - h * e, **values)[1]) / (2 * h)
                for e in np.eye(2)]  # fmt: skip
        return np.stack(cols, axis=2)

    for _ in range(60):
        _, g = _x_energy(t, **values)
        step = np.einsum("nij,nj->ni", np.linalg.pinv(hess(t)), g)
        t = t - step * np.minimum(1.0, 0.3 / np.maximum(np.abs(step).max(1), 1e-300))[:, None]
    _, g = _x_energy(t, **values)
    found = []
    for x in np.mod(t[np.abs(g).max(axis=1) < 1e-11], 2 * np.pi):
        if all(np.abs((x - f + np.pi) % (2 * np.pi) - np.pi).max() > 1e-7 for f in found):
            found.append(x)
    theta = np.array(found)
    return theta, _x_energy(theta, **values)[0], np.linalg.eigvalsh(hess(theta))


def _pair(found_deg, ref_deg):
    gap = np.abs((ref_deg[:, None, :] - found_deg[None] + 180.0) % 360.0 - 180.0).max(axis=2)
    pick = gap.argmin(axis=1)
    assert len(set(pick)) == len(pick) == len(found_deg), gap.min(axis=1)
    return pick, gap.min(axis=1)


@pytest.mark.parametrize("values", [{}, {"fy": -0.2, "L0c": 1.05}])
def test_xmodule_real_route_equals_an_independent_newton_search(values):
    theta, V, eig = _x_reference(**values)
    fw = cb.Framework.from_toml(XMODULE).replace(**values)
    res = cb.solve(fw, route="real", cache=False)
    assert res.status == "ok", res.warnings
    rows = res.physical
    pick, gap = _pair(rows[["bar1.angle_deg", "bar2.angle_deg"]].to_numpy(float),
                      np.degrees(theta))  # fmt: skip
    assert gap.max() < MATCH_DEG
    got = rows.iloc[pick]
    np.testing.assert_allclose(got["energy"], V, atol=1e-10)
    np.testing.assert_array_equal(got["index"].to_numpy(int), (eig < 0).sum(axis=1))
    assert int(res.counts["stable"]) == int((eig > 0).all(axis=1).sum())
    assert res.record["details"]["real_search"]["undecided"] == 0


def test_xmodule_random_geometries_against_the_independent_search():
    """Random free lengths, bar length and load (3 in `make test`, 20 with COTM_STRESS=full):
    the real route's equilibria and kinds equal Newton's on the energy written in the test,
    wherever no equilibrium sits within 1e-4 of a cable's free length (a switch: degenerate
    there by the package's rule, and Newton's finite differences straddle it)."""
    import os

    rng = np.random.default_rng(40)
    fw = cb.Framework.from_toml(XMODULE)
    done = 0
    for _ in range(20 if os.environ.get("COTM_STRESS") == "full" else 3):
        values = {"L1": rng.uniform(1.0, 1.6), "L0s": rng.uniform(0.2, 0.9),
                  "L0c": rng.uniform(0.9, 1.7), "fy": rng.uniform(-0.3, -0.01)}  # fmt: skip
        theta, V, eig = _x_reference(**values)
        res = cb.solve(fw.replace(**values), route="real", cache=False)
        rows = res.physical
        if (rows["kind"] == "degenerate").any():
            continue
        assert res.status == "ok", (values, res.warnings)
        got = np.radians(rows[["bar1.angle_deg", "bar2.angle_deg"]].to_numpy(float))
        # Every reference point is a row (the grid's Newton can miss a saddle next to a cone
        # point, where the tips nearly meet, so the rows may be more) ...
        gap = np.abs((theta[:, None, :] - got[None] + np.pi) % (2 * np.pi) - np.pi).max(axis=2)
        assert np.degrees(gap.min(axis=1)).max() < MATCH_DEG, values
        # ... and every row is a critical point of the energy written here, of its index.
        _, g = _x_energy(got, **values)
        assert np.abs(g).max() < 1e-9, values
        h = 1e-6
        H = np.stack([(_x_energy(got + h * e, **values)[1] - _x_energy(got - h * e, **values)[1])
                      / (2 * h) for e in np.eye(2)], axis=2)  # fmt: skip
        index = (np.linalg.eigvalsh(H) < 0).sum(axis=1)
        np.testing.assert_array_equal(rows["index"].to_numpy(int), index)
        done += 1
    assert done >= 2


def test_xmodule_solve_on_the_command_line_takes_the_real_route(tmp_path):
    out = subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", "solve", "--framework", str(XMODULE),
         "--out", str(tmp_path), "--no-plots"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    assert "by the real route" in out.stdout
    (run,) = {p.resolve() for p in tmp_path.glob("*/run.json")}  # the folder and 'latest'
    record = json.loads(run.read_text())
    assert record["engine"]["flavour"] == "real" and record["counts"]["physical"] == 12
    assert record["details"]["real_search"]["boxes"] > 0


# --- agreement with independent solvers ---------------------------------------------------------
@pytest.mark.parametrize("case", ["case1", "case2", "case3"])
def test_cotm_file_on_the_real_route_equals_the_papers_model(case):
    """examples/cotm.toml by the real route against the built-in model solved by Bertini."""
    p = cb.Params.case(case)
    paper = cb.solve(p).physical
    names = {"L01": p.L01, "L02": p.L02}
    fw = cb.Framework.from_toml(ROOT / "examples" / "cotm.toml").replace(**names)
    res = cb.solve(fw, route="real", cache=False)
    assert res.status == "ok", res.warnings
    got = res.physical
    assert len(got) == len(paper)
    ref = paper[["gamma1_deg", "gamma2_deg"]].to_numpy(float)
    mine = got[["rod.angle_deg", "top.angle_deg"]].to_numpy(float)
    pick, gap = _pair(mine, ref)
    assert gap.max() < 1e-6
    np.testing.assert_array_equal(got["stable"].to_numpy(bool)[pick],
                                  paper["stable"].to_numpy(bool))  # fmt: skip


@pytest.mark.parametrize(
    "name, values",
    [("zeeman", {"x": 0.1, "y": -0.25}), ("zeeman_cables", {"x": 1.45, "y": 0.2}),
     ("double_pendulum", {}), ("cotm", {})],
)  # fmt: skip
def test_real_and_complex_routes_give_the_same_physical_rows(name, values):
    """Every shipped torus example with an affordable complex solve (the X-module's, 27 s, is
    in `make stress`; chain3's is out of reach): the same rows, poses to 1e-8 deg."""
    fw = cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml").replace(**values)
    real, cplx = cb.solve(fw, route="real"), cb.solve(fw, route="complex")
    assert real.status == cplx.status == "ok"
    cols = [c for c in real.physical.columns if c.endswith(".angle_deg")] + ["energy", "index"]
    a, b = real.physical[cols].to_numpy(float), cplx.physical[cols].to_numpy(float)
    assert a.shape == b.shape
    gap = np.abs((a - b + 180.0) % 360.0 - 180.0)
    assert gap[:, :-2].max() < 1e-8 and np.abs(a[:, -2:] - b[:, -2:]).max() < 1e-8


# --- a sweep's points searched together -----------------------------------------------------------
def test_searches_together_equal_each_search_alone():
    """search_each over a family (a batch holding every member's step) gives each member its
    own search, box for box: at L0c = 1.3 (a free length of exactly 1 in the framework's
    units: a number per box kept exact, as one given alone is) and fy = 0 (a continuum of
    equilibria, boxes left undecided)."""
    from cotm_bertini.boxsearch.boxes import MIN_WIDTH, SHORT, search, search_each
    from cotm_bertini.boxsearch.families import TorusFamily
    from cotm_bertini.boxsearch.real_route import TorusFramework

    fw = cb.Framework.from_toml(XMODULE)
    lands = [TorusFramework(fw.replace(L0c=a, fy=b))
             for a, b in [(1.3, -0.05), (1.05, -0.2), (1.15, 0.0)]]  # fmt: skip
    together = search_each(TorusFamily(lands), SHORT, MIN_WIDTH)
    fields = ("roots", "root_boxes", "set_aside_boxes", "undecided", "boxes", "set_aside",
              "set_aside_bound", "shortest_length", "newton_failed")  # fmt: skip
    for land, got in zip(lands, together, strict=True):
        alone = search(land, SHORT, MIN_WIDTH)
        for name in fields:
            np.testing.assert_array_equal(getattr(got, name), getattr(alone, name), name)
    assert len(together[2].undecided) and len(together[0].roots) == 12


def test_a_sweeps_points_searched_together_equal_an_independent_newton_search():
    """A 2 x 2 sweep on the real route (its points' searches in one batch): each point's
    physical rows, energies and Morse indices equal Newton's on the energy written here."""
    fw = cb.Framework.from_toml(XMODULE)
    sw = cb.sweep(fw, "L0c", [1.05, 1.3], param2="fy", values2=[-0.2, -0.05], route="real")
    table = sw.table
    for (L0c, fy), rows in table[table["physical"]].groupby(["L0c", "fy"]):
        theta, V, eig = _x_reference(L0c=L0c, fy=fy)
        pick, gap = _pair(rows[["bar1.angle_deg", "bar2.angle_deg"]].to_numpy(float),
                          np.degrees(theta))  # fmt: skip
        assert gap.max() < MATCH_DEG, (L0c, fy)
        got = rows.iloc[pick]
        np.testing.assert_allclose(got["energy"], V, atol=1e-10)
        np.testing.assert_array_equal(got["index"].to_numpy(int), (eig < 0).sum(axis=1))
    assert table.groupby(["L0c", "fy"]).ngroups == 4 and set(table["status"]) == {"ok"}


# --- what the search cannot decide, and a sabotaged search -------------------------------------
def test_a_search_stopped_early_is_incomplete_never_ok(tmp_path):
    fw = cb.Framework.from_toml(XMODULE)
    res = cb.solve(fw, route="real", timeout=1e-6, cache=False)
    assert res.status == "incomplete"
    assert any("undecided" in w for w in res.warnings)
    out = subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", "solve", "--framework", str(XMODULE),
         "--timeout", "1e-6", "--out", str(tmp_path), "--no-plots", "--no-cache"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert out.returncode == 5, out.stdout + out.stderr


def test_a_lost_root_is_caught_by_the_morse_count(monkeypatch, tmp_path):
    """Sabotage: the search drops the first root it proves; the Morse count on the torus sees
    the hole. The search called itself complete, so that is a contradiction (a bug), not a set
    that may be incomplete: status contradiction, and the command line exits 4."""
    dropped = lose_first_root(monkeypatch)
    res = cb.solve(cb.Framework.from_toml(XMODULE), route="real", cache=False)
    assert dropped and len(res.physical) == 11
    assert res.status == "contradiction"
    assert res.warnings[0].startswith("contradiction: the real search proved its 11 critical")
    assert "Morse count" in res.warnings[0]
    assert not any("may be missing" in w for w in res.warnings)
    dropped.clear()  # the next search drops its first root too
    code = cli_main(["solve", "--framework", str(XMODULE), "--route", "real", "--no-cache",
                     "--no-plots", "--quiet", "--out", str(tmp_path)])  # fmt: skip
    assert code == 4 and dropped


def test_route_real_for_the_papers_mechanism_refuses_what_it_cannot_honour(tmp_path):
    """The paper's model solves on the real route (tests/test_paper_real.py); a sweep, map or
    verify of it (each follows or compares complex roots) and a Bertini-only setting with it
    are refused before any work or folder, on the API and the command line."""
    with pytest.raises(cb.ParameterError, match="final_tol = 1e-09 with route = 'real'"):
        cb.solve(cb.Params.case("case3"), route="real", final_tol=1e-9)
    with pytest.raises(cb.ParameterError, match="engine = 'cli' with route = 'real'"):
        cb.solve(cb.Params.case("case3"), route="real", engine="cli")
    out = subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", "sweep", "--param", "L01", "--route", "real",
         "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert out.returncode == 2 and "route = 'real': sweep" in out.stderr
    out = subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", "solve", "case1", "--route", "real",
         "--mptype", "0", "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert out.returncode == 2 and "mptype = 0 with route = 'real'" in out.stderr
    out = subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", "verify", "case1", "--route", "real",
         "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert out.returncode == 2 and "route = 'real': verify" in out.stderr
    with pytest.raises(cb.ParameterError, match="route = 'real': sweep"):  # before any folder
        cb.sweep(cb.Params(), "L01", [0.0, 1.0], route="real", out=tmp_path)
    with pytest.raises(cb.ParameterError, match="route = 'real': map"):
        cb.design_map(cb.Params(), (0, 14), (0, 14), 3, settings=cb.Settings(route="real"))
    fivebar = cb.Framework.from_toml(ROOT / "tests" / "fixtures" / "fivebar.toml")
    with pytest.raises(cb.ParameterError, match="route = 'real'.*1 closing pin over 4 bodies"):
        cb.sweep(fivebar, "L0", [0.4, 0.5], route="real", out=tmp_path)
    assert not list(tmp_path.iterdir())


def test_route_real_is_refused_where_it_does_not_cover_the_space():
    fw = cb.Framework.from_toml(ROOT / "tests" / "fixtures" / "fivebar.toml")
    with pytest.raises(cb.ParameterError, match="route = 'real'.*1 closing pin over 4 bodies"):
        cb.solve(fw, route="real")
    with pytest.raises(cb.ParameterError, match="route = 'bogus'"):
        cb.Settings(route="bogus")


@pytest.mark.parametrize("name", ["xmodule", "cotm"])
def test_cone_points_proved_by_the_search_equal_bertinis(name):
    """The zero-length poses the search proves critical (in Clarke's sense: the other
    elements' pull there weaker than k L0) against Bertini's ab-initio solve of the zero-length
    system and the pull computed there: the same poses, each a maximum (index 2)."""
    from cotm_bertini.analysis.framework_checks import cone_points
    from cotm_bertini.boxsearch.boxes import MIN_WIDTH, SHORT, search
    from cotm_bertini.boxsearch.real_route import TorusFramework

    fw = cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml")
    land = TorusFramework(fw)
    found = search(land, SHORT, MIN_WIDTH)
    assert found.set_aside == 0 and len(found.undecided) == 0
    ref = [c for c in cone_points(fw) if c["is_max"]]
    assert len(ref) == len(found.cones) > 0
    trig = np.stack([np.cos(found.cones[:, :2]), np.sin(found.cones[:, :2])], axis=2)
    for c in ref:
        gaps = np.abs(trig.reshape(-1, 4) - np.array(c["pose"])).max(axis=1)
        k = int(np.argmin(gaps))
        assert gaps[k] < 1e-9
        assert found.cones[k, 4] == 2  # index: a maximum
        assert abs(found.cones[k, 3] - c["pull"]) < 1e-8 * max(1.0, c["push"])


def test_unbounded_products_stay_sound():
    """0 times an unbounded interval is 0 (no nan); a reciprocal across 0 is unbounded."""
    inf = np.inf
    a = Interval(np.array([0.0, 0.0, -1.0]), np.array([0.0, 1.0, 2.0]))
    b = Interval(np.array([-inf, 1.0, -0.5]), np.array([inf, inf, 0.5])).reciprocal()
    p = Interval(np.array([0.0, 0.0, -1.0]), np.array([0.0, 1.0, 2.0])) * Interval(
        np.array([-inf, 1.0, 3.0]), np.array([inf, inf, 4.0])
    )
    assert not np.isnan(p.lo).any() and not np.isnan(p.hi).any()
    assert p.lo[0] <= 0.0 <= p.hi[0] and p.lo[1] <= 0.0 and p.hi[1] == inf
    assert p.lo[2] <= -4.0 and p.hi[2] >= 8.0
    assert b.lo[2] == -inf and b.hi[2] == inf  # 1 / [-0.5, 0.5]
    assert (a + Interval(np.full(3, -inf), np.full(3, inf))).hi[0] == inf


# --- a map on the real route ---------------------------------------------------------------------
@pytest.fixture(scope="module")
def xmodule_map(tmp_path_factory):
    """The X-module's 5 x 5 map over (L0c, fy) in a fresh cache: the real route's fold and
    switch seeds (no generic set is solved: none may appear in the cache)."""
    import os

    cache = tmp_path_factory.mktemp("cache")
    before = os.environ.get("COTM_CACHE")
    os.environ["COTM_CACHE"] = str(cache)
    try:
        fw = cb.Framework.from_toml(XMODULE)
        m = cb.design_map(fw, "L0c", (1.0, 1.6), "fy", (-0.2, -0.05), points=5)
    finally:
        if before is None:
            del os.environ["COTM_CACHE"]
        else:
            os.environ["COTM_CACHE"] = before
    return m, cache


def test_a_map_on_the_real_route_solves_no_generic_set(xmodule_map):
    m, cache = xmodule_map
    assert not list(cache.glob("generic-*"))
    assert m.record["status"] == "ok"
    kinds = set(m.folds["kind"])
    assert {"fold", "cable_switch"} <= kinds


def test_the_maps_folds_and_switches_against_the_independent_energy(xmodule_map):
    """Every fold point is critical for the energy written here, with a singular Hessian;
    every switch point has a cable exactly at its free length and is critical."""
    m, _ = xmodule_map
    f = m.folds
    h = 1e-6
    for kind in ("fold", "cable_switch"):
        rows = f[f["kind"] == kind].iloc[::25]
        assert len(rows)
        for _, r in rows.iterrows():
            values = {"L0c": r["L0c"], "fy": r["fy"]}
            t = np.radians([[r["bar1.angle_deg"], r["bar2.angle_deg"]]])
            _, g = _x_energy(t, **values)
            assert np.abs(g).max() < 1e-7, (kind, r["L0c"], r["fy"])
            tip1 = np.array([r["bar1.tip.x"], r["bar1.tip.y"]])
            tip2 = np.array([r["bar2.tip.x"], r["bar2.tip.y"]])
            gaps = [np.linalg.norm(tip1 - [1.0, 0.0]) - r["L0c"], np.linalg.norm(tip2) - r["L0c"]]
            if kind == "cable_switch":
                assert min(abs(v) for v in gaps) < 1e-8
            else:
                H = np.stack([(_x_energy(t + h * e, **values)[1] - _x_energy(t - h * e,
                              **values)[1])[0] / (2 * h) for e in np.eye(2)])  # fmt: skip
                assert abs(np.linalg.det(H)) < 1e-5 * np.abs(H).max() ** 2 + 1e-7


def test_a_seed_lines_branches_are_traced_once_for_a_taut_sets_curve_systems():
    """The sweep route's branches along a seed line depend on the taut set's equilibria, not on
    the curve system: a switch system given the fold system's branches finds the seeds (and
    line records) it finds tracing its own; another taut set's lines never share them."""
    from cotm_bertini.catastrophe.curve_trace import Window
    from cotm_bertini.catastrophe.fold_sweep import branch_key, sweep_seeds
    from cotm_bertini.catastrophe.framework_folds import _line_specs
    from cotm_bertini.model.framework.folds import curve_system

    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman_cables.toml")
    both, one = ("band_p", "band_u"), ("band_p",)
    fold, switch = (curve_system(fw, both, "x", "y", c) for c in ("", "band_u"))
    sx, sy = fold.scales
    n = len(fold.variables)
    win = Window(n, n + 1, (-0.6 / sx, -0.8 / sy), (0.8 / sx, 0.2 / sy), (sx, sy))
    specs = [_line_specs(win)[k] for k in (0, 4, 8, 9, 13, 17)]  # edges and middles
    args = (("x", "y"), cb.Settings(), lambda fn, tasks: [fn(t) for t in tasks])
    shared: dict = {}
    sweep_seeds(fw, fold, specs, *args, branches=shared)
    assert len(shared) == len(specs)
    got = sweep_seeds(fw, switch, specs, *args, branches=shared)
    alone = sweep_seeds(fw, switch, specs, *args, branches={})
    assert len(shared) == len(specs)  # every line's branches were the fold system's
    assert len(got[0]) == len(alone[0]) > 0 and got[1] == alone[1]
    np.testing.assert_array_equal(np.array(got[0]), np.array(alone[0]))
    other = curve_system(fw, one, "x", "y", "band_p")
    ts = np.linspace(0.0, 1.0, 3)
    assert branch_key(other, specs[0], ts, []) != branch_key(switch, specs[0], ts, [])


def test_a_family_covered_together_proves_each_point_as_alone():
    """search_frameworks excludes what no point of a family can have a critical point in once,
    over their hull (every number an interval holding each point's), then searches each point
    from what is left: each point's proved roots equal its own search's (4-link chain, 20
    values of a free length, a cable-free chain where one point would take 125k boxes)."""
    from cotm_bertini.boxsearch.boxes import MIN_WIDTH, SHORT, search
    from cotm_bertini.boxsearch.families import search_frameworks
    from cotm_bertini.boxsearch.real_route import TorusFramework

    fw = cb.Framework.from_toml(ROOT / "tests" / "fixtures" / "chain4.toml")
    fws = [fw.replace(L0=v) for v in np.linspace(1.6, 2.0, 20)]
    lands = [TorusFramework(f) for f in fws]
    found = search_frameworks(fws, lands=lands)
    for k in (0, 7, 19):
        alone = search(lands[k], SHORT, MIN_WIDTH)
        got = found[k]
        assert not got.budget_hit and len(got.undecided) == 0 == len(alone.undecided)
        a, b = (r[np.lexsort(r.T[::-1])] for r in (got.roots, alone.roots))
        assert len(a) == len(b) > 0 and np.abs(a - b).max() < 1e-9
        assert got.boxes < alone.boxes and "together first" in got.notes[-1]


def test_params_states_the_real_route_s_pace_from_a_sample_search():
    """cb.cost (params --framework) on the real route runs the search for up to 2 s: a small
    file's whole search (its time and boxes), a large one's share decided and a lower bound;
    a solve's own announcement does not sample (sample=None)."""
    small = cb.cost(cb.Framework.from_toml(ROOT / "examples" / "fourbar.toml"))
    assert small.search["done"] and small.search["boxes"] > 0
    assert "a whole search took" in small.headline()
    big = cb.cost(cb.Framework.from_toml(ROOT / "examples" / "tower.toml"))
    assert not big.search["done"] and 0 <= big.search["decided"] < 0.05
    assert "at least about" in big.headline() or "far beyond" in big.headline()
    quiet = cb.cost(cb.Framework.from_toml(ROOT / "examples" / "tower.toml"), sample=None)
    assert quiet.search is None
