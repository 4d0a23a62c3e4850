"""Scale-out: a generic set's paths split over Dask workers (our own start system, in chunks).

The evidence: our linear-product start system has exactly the multihomogeneous Bezout number of
roots (counted here independently, as a coefficient of a polynomial product) and every one
solves G; the split route finds the same generic set as Bertini's own ZeroDimSolver, which
starts from a different start system; a solve with a scheduler gives the table of one without.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import sympy
from conftest import ROOT, run_cli, same_sets

import cotm_bertini as cb
from cotm_bertini.backends import homotopy
from cotm_bertini.backends.start_system import linear_product_start
from cotm_bertini.model.framework.compiled import framework_system, variable_groups
from cotm_bertini.model.framework.taut_sets import taut_sets
from cotm_bertini.model.polynomial import PolySystem

ZEEMAN = ROOT / "examples" / "zeeman.toml"
CONNECT = "DASK_DISTRIBUTED__COMM__TIMEOUTS__CONNECT"  # Dask's own connect timeout
# Two bodies in an open chain (a torus of poses), springs of zero free length: 8 paths.
TINY_CHAIN = """
name = "tiny_chain"
dim = 2
[parameters]
k = 1.0
[ground]
o = [0.0, 0.0]
a = [-0.6, 1.2]
b = [1.5, -0.8]
[bodies.link1]
o = [0.0, 0.0]
e = [1.0, 0.0]
[bodies.link2]
o = [0.0, 0.0]
tip = [0.8, 0.0]
[[pins]]
a = "link1.o"
b = "ground.o"
[[pins]]
a = "link2.o"
b = "link1.e"
[[springs]]
name = "s1"
a = "link1.e"
b = "ground.a"
k = "k"
L0 = 0.0
[[springs]]
name = "s2"
a = "link2.tip"
b = "ground.b"
k = "2*k"
L0 = 0.0
"""


@pytest.fixture(scope="module")
def scheduler():
    """A two-process Dask cluster for this module (the workers import the package)."""
    from distributed import LocalCluster

    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as cluster:
        yield cluster.scheduler_address


def bezout(degrees: np.ndarray, sizes: list[int]) -> int:
    """The multihomogeneous Bezout number, independently: the coefficient of prod z_g^|g| in
    prod_i (sum_g d_ig z_g)."""
    z = sympy.symbols(f"z0:{len(sizes)}")
    terms = [sum(int(d) * zg for d, zg in zip(row, z, strict=True)) for row in degrees]
    product = sympy.Mul(*terms)
    poly = sympy.Poly(sympy.expand(product), *z)
    return int(poly.coeff_monomial(sympy.Mul(*[zg**s for zg, s in zip(z, sizes, strict=True)])))


def random_system(rng, sizes: list[int]) -> tuple[PolySystem, list[list[str]]]:
    """A square system whose equation i has random degree d_ig in group g (one monomial
    reaching each degree, plus a constant)."""
    names = [f"x{g}_{k}" for g, s in enumerate(sizes) for k in range(s)]
    groups, at = [], 0
    for s in sizes:
        groups.append(names[at : at + s])
        at += s
    exps, coefs = [], []
    for _ in names:
        deg = rng.integers(0, 3, size=len(sizes))
        deg[rng.integers(len(sizes))] += 1  # every equation of degree >= 1 somewhere
        rows = [np.zeros(len(names), dtype=int)]
        for g, d in enumerate(deg):
            if d:
                row = np.zeros(len(names), dtype=int)
                row[names.index(rng.choice(groups[g]))] = d
                rows.append(row)
        exps.append(np.array(rows))
        coefs.append(rng.normal(size=len(rows)))
    eqs = tuple(f"f{i}" for i in range(len(names)))
    return PolySystem(tuple(names), eqs, tuple(exps), tuple(coefs)), groups


def g_values(start, points: np.ndarray) -> np.ndarray:
    """G at each point from its rendered text (parsed by sympy; not start.evaluate)."""
    xs = sympy.symbols(start.variables)
    exprs = [sympy.sympify(t, locals={"I": sympy.I}) for t in start.texts()]
    f = sympy.lambdify(xs, exprs, "numpy")
    return np.array([f(*p) for p in points], dtype=complex)


def test_start_system_roots_count_and_solve_g():
    rng = np.random.default_rng(5)
    for sizes in ([2, 1, 1], [1, 2, 1, 1], [3]):
        system, groups = random_system(rng, sizes)
        start = linear_product_start(system, groups, seed=3)
        while not bezout(start.degrees, sizes):  # a group in too few equations: no roots
            assert start.count() == 0 and not list(start.points())
            system, groups = random_system(rng, sizes)
            start = linear_product_start(system, groups, seed=3)
        points = np.array(list(start.points()))
        assert len(points) == start.count() == bezout(start.degrees, sizes)
        assert np.abs(g_values(start, points)).max() < 1e-10
        assert max(np.abs(start.evaluate(p)).max() for p in points) < 1e-10
        chunks = list(start.chunks(5))
        assert np.array_equal(np.vstack(chunks), points) and max(map(len, chunks)) <= 5
        gaps = [np.abs(points[k + 1 :] - points[k]).max(axis=1).min(initial=1) for k in
                range(len(points))]  # fmt: skip
        assert min(gaps) > 1e-6  # distinct roots: the count is a count of solutions


def test_bezout_number_and_fewer_paths_by_merging_groups():
    """bezout_number (dynamic programming) against the sympy coefficient above on random degree
    matrices; fewest_paths_groups returns a partition of the variables whose count (sympy) is
    no larger than the given grouping's, and strictly smaller on Zeeman's fold system (200
    paths to 192; cotm.toml's, whose derivation takes 20 s, 2,688 to 1,408)."""
    from cotm_bertini.backends.start_system import (
        bezout_number,
        fewest_paths_groups,
        group_degrees,
    )
    from cotm_bertini.model.framework.folds import curve_system

    rng = np.random.default_rng(11)
    for _ in range(40):
        sizes = list(rng.integers(1, 4, size=rng.integers(1, 5)))
        degrees = rng.integers(0, 4, size=(sum(sizes), len(sizes)))
        assert bezout_number(degrees, sizes) == bezout(degrees, sizes)
        # sparse, as a framework's (most equations in a few groups): the dead-state cut acts
        sparse = degrees * (rng.random(degrees.shape) < 0.4)
        assert bezout_number(sparse, sizes) == bezout(sparse, sizes)
    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman.toml")
    cs = curve_system(fw, (), "x", "y")
    system = cs.ps.instantiate(rng.normal(size=4) + 1j * rng.normal(size=4))
    chosen = fewest_paths_groups(system, cs.groups)
    assert sorted(v for g in chosen for v in g) == sorted(v for g in cs.groups for v in g)

    def count(groups):
        return bezout(group_degrees(system, groups), [len(g) for g in groups])

    assert count(chosen) < count(cs.groups)


def test_generic_set_with_groups_out_of_variable_order_solves_the_system():
    """Bertini orders the variables group by group: with groups whose concatenation is not the
    system's variable order (a merged group, as fewest_paths_groups makes), the generic set's
    points are still in the system's order, so they solve it at the start parameters."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman.toml")
    fs = framework_system(fw, ())
    groups = variable_groups(fs)[::-1]
    groups = [groups[0] + groups[-1], *groups[1:-1]]
    assert [v for g in groups for v in g] != list(fs.ps.variables)
    gs = homotopy.generic_set(fs.ps, 7, centre=_centre(fw, fs), groups=groups, use_cache=False)
    system = fs.ps.instantiate([gs.start[n] for n in fs.ps.parameters])
    assert len(gs.points) > 0
    assert np.abs(system.evaluate(gs.points)).max() < 1e-8


def _centre(fw, fs) -> dict:
    from cotm_bertini.model.framework.units import normalized_slots

    centre = normalized_slots(fw.at_defaults())
    return {n: centre[n] for n in fs.ps.parameters}


def assert_same_generic_set(own, ps, groups=None, start: str = "multihomogeneous") -> None:
    """The package's generic set `own` of `ps` against Bertini's own ZeroDimSolver solve of the
    same system at the same start parameters (test_monodromy.total_degree, called here): the
    same finite and singular endpoint counts and the same nonsingular set."""
    from test_monodromy import total_degree

    assert own.route["method"].startswith(f"own {start}")
    points, finite, singular = total_degree(ps.instantiate([own.start[n] for n in ps.parameters]),
                                            groups)  # fmt: skip
    assert (own.finite_endpoints, own.singular_endpoints) == (finite, singular)
    assert len(own.points) > 0 and same_sets(own.points, points)


def test_split_generic_set_equals_bertinis_on_zeeman(scheduler):
    fw = cb.Framework.from_toml(ZEEMAN)
    fs = framework_system(fw, taut_sets(fw)[0])
    groups = variable_groups(fs)
    kw = {"centre": _centre(fw, fs), "groups": groups}
    own = homotopy.generic_set(fs.ps, 1, use_cache=False, scheduler=scheduler, **kw)
    assert_same_generic_set(own, fs.ps, groups)
    local = homotopy.generic_set(fs.ps, 1, use_cache=False, **kw)  # the same, in this process
    assert (
        local.key == own.key and local.route["chunks"] >= 1 and same_sets(local.points, own.points)
    )
    assert own.route["chunks"] >= 2 and sum(own.route["paths_per_chunk"]) == own.paths
    # Our path count is the Bezout number, counted independently, and Bertini's own count.
    start = linear_product_start(fs.ps.instantiate([1.0] * len(fs.ps.parameters)), groups, 1)
    assert own.paths == bezout(start.degrees, [len(g) for g in groups])


def _generic_files(folder: Path) -> dict[str, dict]:
    return {p.name: json.loads(p.read_text()) for p in folder.glob("generic-*.json")}


def test_solve_with_scheduler_equals_solve_without(scheduler, tmp_path, monkeypatch):
    path = tmp_path / "tiny_chain.toml"
    path.write_text(TINY_CHAIN)
    fw = cb.Framework.from_toml(path)  # two bodies: the split route on a torus framework
    solved = {}
    # Without a scheduler the total-degree route asked for: the same start, in this process.
    plain_route = {"settings": cb.Settings(generic="total-degree")}
    # The complex route asked for: by default a scheduler shares the real route's boxes.
    split_route = {"scheduler": scheduler, "route": "complex"}
    for name, options in (("split", split_route), ("bertini", plain_route)):
        monkeypatch.setenv("COTM_CACHE", str(tmp_path / name))  # generic sets solved afresh
        monkeypatch.setattr(homotopy, "_LOADED", {})
        solved[name] = cb.solve(fw, cache=False, **options)
    split, plain = solved["split"], solved["bertini"]
    route = split.record["details"]["taut_sets"]["none"]["generic_route"]
    assert route["scheduler_used"] and len(route["generic_sets"]) == 2
    assert all(g["method"].startswith("own") and g["chunks"] >= 2 for g in route["generic_sets"])
    assert split.record["settings"]["scheduler"] == scheduler
    # Same generic sets (same keys, same files' names), found from two different start systems.
    a, b = _generic_files(tmp_path / "split"), _generic_files(tmp_path / "bertini")
    assert sorted(a) == sorted(b) and len(a) == 2
    for name in a:
        own, theirs = (homotopy.GenericSet.from_json(x[name]) for x in (a, b))
        assert (own.paths, own.finite_endpoints) == (theirs.paths, theirs.finite_endpoints)
        assert same_sets(own.points, theirs.points)
    for view in ("physical", "stable"):
        x, y = getattr(split, view), getattr(plain, view)
        assert len(x) == len(y) > 0
        cols = [c for c in x.columns if "." in c]  # bodies' poses, nodes, lengths, tensions
        assert len(cols) >= 4 and list(x["kind"]) == list(y["kind"])
        assert np.allclose(x[cols].to_numpy(float), y[cols].to_numpy(float), atol=1e-9, rtol=0)
    # Asked again with the sets in memory: nothing is solved, and the record says so.
    again = cb.solve(fw, cache=False, **split_route)
    route = again.record["details"]["taut_sets"]["none"]["generic_route"]
    assert not route["scheduler_used"] and "not needed" in route["note"]


def test_old_generic_cache_without_route_loads():
    gs = homotopy.GenericSet("k", 1, {"a": 1j}, np.ones((1, 2), complex), 4, 2, 1, 0.5, "v")
    data = gs.to_json()
    del data["route"]
    old = homotopy.GenericSet.from_json(data)
    assert old.route == homotopy.EARLIER_ROUTE and old.paths == 4


def test_unreachable_scheduler_is_one_line_exit_2_nothing_written(tmp_path, monkeypatch):
    out, cache = tmp_path / "runs", tmp_path / "cache"
    env = {"COTM_CACHE": str(cache), CONNECT: "1s"}  # nothing listens on port 9
    res = run_cli("solve", "--framework", str(ZEEMAN), "--scheduler", "tcp://127.0.0.1:9",
                  "--no-cache", "--out", str(out), "--quiet", env=env)  # fmt: skip
    assert res.returncode == 2, res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and re.search(r"scheduler = '.*:9': no Dask scheduler", lines[0])
    assert not out.exists() and not list(cache.glob("**/generic-*.json"))
    monkeypatch.setenv("COTM_CACHE", str(cache))
    with pytest.raises(cb.ParameterError, match="scheduler = 'nonsense': no Dask scheduler"):
        cb.solve(cb.Framework.from_toml(ZEEMAN), scheduler="nonsense")
    assert not list(cache.glob("**/generic-*.json")) and not list(cache.glob("solves/*"))
    with pytest.raises(cb.ParameterError, match="scheduler = 'tcp://h:1': .* engine='homotopy'"):
        cb.Settings(engine="cli", scheduler="tcp://h:1")


@pytest.mark.slow
def test_double_pendulum_generic_set_split_equals_bertinis(scheduler):
    """128 paths by each route (about 40 s each on a quiet machine): `make stress`."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "double_pendulum.toml")
    fs = framework_system(fw, taut_sets(fw)[0])
    kw = {"use_cache": False, "centre": _centre(fw, fs), "groups": variable_groups(fs)}
    own = homotopy.generic_set(fs.ps, 1, scheduler=scheduler, **kw)
    assert_same_generic_set(own, fs.ps, kw["groups"])
    assert own.paths == 128 and own.route["failed_paths"] == 0


@pytest.mark.slow
def test_paper_generic_set_split_equals_bertinis(scheduler):
    """The built-in mechanism (one group: a total-degree count, 192 paths, 16 singular ends at
    the d = 0 artefacts) by both routes: `make stress`."""
    from cotm_bertini.model.compiled import parametric_system

    ps = parametric_system((False, False))
    own = homotopy.generic_set(ps, 1, use_cache=False, scheduler=scheduler)
    assert_same_generic_set(own, ps, None, "total-degree")
    assert own.paths == 192 and own.singular_endpoints > 0
