"""Events of a sweep of a three-link chain (issue 27 item 6): a fold where a minimum and an
index-1 saddle are born, away from any length limit. It was reported as a `physical_change`
("a degenerate appears"), with another equilibrium's pose and no stability change, because a
bisection probe next to the fold saw the merging pair as one degenerate root; and of two events
between neighbouring sweep points only the first was found. Checked against an independent
numpy energy of the chain (Newton on its gradient from a grid of starts on the 3-torus; no
package code)."""

from __future__ import annotations

import itertools
from functools import cache
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cotm_bertini.cli.main import main

# Three links pinned in series to the ground at the origin (lengths LINKS, angles measured from
# the x axis); spring s01 (k = 1, free length L01, swept) from the end of link 1 to A, springs
# of zero free length from the end of link 2 to B (K2) and from the tip to C (K3), and a
# downward force W at the tip. Zero free lengths keep the first solve cheap (128 paths).
A, B, C = (1.36, 0.038), (0.054, 1.265), (-1.76, 1.598)
K2, K3, W = 1.43, 1.617, 0.096
LINKS = (1.0, 1.062, 0.515)
LO, HI = 0.55, 0.6  # the sweep points on either side of the fold

CHAIN = f"""
name = "chain3"
dim = 2

[parameters]
L01 = 1.0

[ground]
o = [0.0, 0.0]
a = [{A[0]}, {A[1]}]
b = [{B[0]}, {B[1]}]
c = [{C[0]}, {C[1]}]

[bodies.link1]
o = [0.0, 0.0]
e = [{LINKS[0]}, 0.0]

[bodies.link2]
o = [0.0, 0.0]
e = [{LINKS[1]}, 0.0]

[bodies.link3]
o = [0.0, 0.0]
tip = [{LINKS[2]}, 0.0]

[[pins]]
a = "link1.o"
b = "ground.o"

[[pins]]
a = "link2.o"
b = "link1.e"

[[pins]]
a = "link3.o"
b = "link2.e"

[[springs]]
name = "s01"
a = "link1.e"
b = "ground.a"
k = 1.0
L0 = "L01"

[[springs]]
name = "s2"
a = "link2.e"
b = "ground.b"
k = {K2}
L0 = 0.0

[[springs]]
name = "s3"
a = "link3.tip"
b = "ground.c"
k = {K3}
L0 = 0.0

[[loads]]
name = "weight"
point = "link3.tip"
force = [0.0, {-W}]
"""
ANGLES = ["link1.angle_deg", "link2.angle_deg", "link3.angle_deg"]


def _grad_hess(th: np.ndarray, L01: float) -> tuple[np.ndarray, np.ndarray]:
    """Gradient (n, 3) and Hessian (n, 3, 3) of V at link angles th (n, 3), rad."""
    u = np.stack([np.cos(th), np.sin(th)], axis=-1) * np.array(LINKS)[:, None]  # link vectors
    du = np.stack([-u[..., 1], u[..., 0]], axis=-1)  # their derivatives by their own angle
    ends = np.cumsum(u, axis=1)  # end of link 1, end of link 2, tip
    g, H = np.zeros(th.shape), np.zeros((len(th), 3, 3))
    for j, (anchor, k, free) in enumerate(((A, 1.0, L01), (B, K2, 0.0), (C, K3, 0.0))):
        r = ends[:, j] - np.array(anchor)
        d = np.linalg.norm(r, axis=1)
        force = k * (1 - free / d)[:, None] * r  # dV/d(end)
        hp = k * ((1 - free / d)[:, None, None] * np.eye(2) + (free / d**3)[:, None, None]
                  * r[:, :, None] * r[:, None, :])  # fmt: skip
        jac = np.zeros((len(th), 2, 3))
        jac[:, :, : j + 1] = du[:, : j + 1].transpose(0, 2, 1)
        g += np.einsum("ni,nij->nj", force, jac)
        H += np.einsum("nji,njk,nkl->nil", jac, hp, jac)
        for i in range(j + 1):
            H[:, i, i] -= np.einsum("ni,ni->n", force, u[:, i])
    g += W * du[:, :, 1]  # V += W tip_y
    H[:, range(3), range(3)] -= W * u[:, :, 1]
    return g, H


def _energy(th: np.ndarray, L01: float) -> np.ndarray:
    ends = np.cumsum(np.stack([np.cos(th), np.sin(th)], -1) * np.array(LINKS)[:, None], axis=1)
    d = [np.linalg.norm(ends[:, j] - np.array(p), axis=1) for j, p in enumerate((A, B, C))]
    return (d[0] - L01) ** 2 / 2 + K2 / 2 * d[1] ** 2 + K3 / 2 * d[2] ** 2 + W * ends[:, 2, 1]


@cache
def _critical_points(L01: float, n: int = 8) -> list[tuple[np.ndarray, int]]:
    """Every critical point Newton on grad V reaches from an n^3 grid of starts on the torus:
    (angles in rad, Hessian index), each once."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    th = np.array(list(itertools.product(t, t, t)))
    for _ in range(100):
        g, H = _grad_hess(th, L01)
        th = th - np.clip(np.linalg.solve(H, g[..., None])[..., 0], -0.5, 0.5)
    g, H = _grad_hess(th, L01)
    done = np.abs(g).max(axis=1) < 1e-11
    out: list[tuple[np.ndarray, int]] = []
    for x, h in zip(np.mod(th[done], 2 * np.pi), H[done], strict=True):
        if all(_angle_gap(x, y) > 1e-7 for y, _ in out):
            out.append((x, int((np.linalg.eigvalsh(h) < 0).sum())))
    return out


def _angle_gap(x: np.ndarray, y: np.ndarray) -> float:
    return float(np.abs(np.angle(np.exp(1j * (np.asarray(x) - np.asarray(y))))).max())


def _minima(L01: float) -> int:
    return sum(index == 0 for _, index in _critical_points(L01))


def _all(L01: float) -> int:
    return len(_critical_points(L01))


@cache
def _fold(lo: float, hi: float, count) -> float:
    """Where count(L01) changes between lo and hi, bisected to 1e-8."""
    start = count(lo)
    while hi - lo > 1e-8:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if count(mid) == start else (lo, mid)
    return 0.5 * (lo + hi)


def _born(value: float) -> list[tuple[np.ndarray, int]]:
    """The critical points just past the fold at `value` that are not there just before it."""
    before = _critical_points(value - 2e-8)
    return [(x, i) for x, i in _critical_points(value + 2e-8)
            if all(_angle_gap(x, y) > 1e-3 for y, _ in before)]  # fmt: skip


def _middle(born: list[tuple[np.ndarray, int]]) -> np.ndarray:
    return np.angle(sum(np.exp(1j * x) for x, _ in born))


def _continued(th: np.ndarray, start: float, stop: float, steps: int = 50) -> np.ndarray:
    """Critical points th (n, 3) at L01 = start followed to stop by Newton in small steps."""
    for value in np.linspace(start, stop, steps + 1)[1:]:
        for _ in range(8):
            g, H = _grad_hess(th, value)
            th = th - np.linalg.solve(H, g[..., None])[..., 0]
    return np.mod(th, 2 * np.pi)


def _sweep(root: Path, start: float, stop: float, points: int, *more: str):
    """`sweep --framework` of the chain: (exit code, events.csv, sweep.csv)."""
    path = root / "chain3.toml"
    path.write_text(CHAIN)
    code = main(["sweep", "--framework", str(path), "--param", "L01", "--from", str(start),
                 "--to", str(stop), "--points", str(points), "--workers", "1", "--quiet",
                 "--no-plots", "--out", str(root / "out"), *more])  # fmt: skip
    folder = next((root / "out").glob("sweep-*"))
    return code, pd.read_csv(folder / "events.csv"), pd.read_csv(folder / "sweep.csv")


def test_the_independent_energy_is_right():
    """Its gradient and Hessian are those of V (central differences)."""
    th, h = np.random.default_rng(3).uniform(0, 2 * np.pi, (5, 3)), 1e-6
    g, H = _grad_hess(th, 0.7)
    steps = np.eye(3) * h
    assert np.allclose(
        g, [[(_energy(th + s, 0.7) - _energy(th - s, 0.7))[r] / (2 * h) for s in steps]
            for r in range(5)], atol=1e-7)  # fmt: skip
    dg = np.stack([(_grad_hess(th + s, 0.7)[0] - _grad_hess(th - s, 0.7)[0]) / (2 * h)
                   for s in steps], axis=1)  # fmt: skip
    assert np.allclose(H, dg, atol=1e-7)


@pytest.fixture(scope="module")
def chain_events(tmp_path_factory):
    """The sweep over LO, HI and neighbours: (exit code, events.csv, sweep.csv)."""
    return _sweep(tmp_path_factory.mktemp("chain"), 0.4, 0.8, 9)


def test_the_sweep_counts_match_the_energy(chain_events):
    """Physical and stable equilibria at the sweep points around the fold: every critical point
    and minimum of the independent energy (1 - 3 + 3 - 1 and 2 - 4 + 3 - 1: the Euler
    characteristic of the 3-torus)."""
    code, _, table = chain_events
    assert code == 0
    for value, n_all, n_min in ((LO, 8, 1), (HI, 10, 2)):
        points = _critical_points(value)
        assert (len(points), _minima(value)) == (n_all, n_min)
        rows = table[np.isclose(table["L01"], value) & table["physical"]]
        assert (len(rows), int(rows["stable"].sum())) == (n_all, n_min)


def test_a_fold_birth_is_a_fold_with_its_pose_and_a_stability_change(chain_events):
    """The birth of a minimum and an index-1 saddle: one refined `fold` at the independent
    bisection's value (1e-6), at the pose of the born pair, and a `stability_change` there."""
    _, events, table = chain_events
    value = _fold(LO, HI, _minima)
    near = events[np.abs(events["L01"] - value) < 1e-6]
    assert sorted(near["kind"]) == ["fold", "stability_change"], events.to_string()
    assert "physical_change" not in set(events["kind"])  # no length or cable at a limit here
    fold = near[near["kind"] == "fold"].iloc[0]
    assert bool(fold["refined"]) and fold["bracket"] < 5e-9  # 1e-9, and the unresolved probes
    assert fold["description"].startswith("a min and a saddle are born")
    born = _born(value)
    assert sorted(i for _, i in born) == [0, 1]
    pose = np.radians(fold[ANGLES].to_numpy(float))
    assert _angle_gap(pose, _middle(born)) < np.radians(1e-4)
    # The branches named are the born pair's at HI: the two critical points there that the
    # ones at LO, continued to HI by Newton, do not reach.
    reached = _continued(np.array([x for x, _ in _critical_points(LO)]), LO, HI)
    born_hi = [x for x, _ in _critical_points(HI) if all(_angle_gap(x, y) > 1e-6 for y in reached)]
    assert len(born_hi) == 2
    ids = [int(b) for b in fold["branches"].split("+")]
    rows = table[np.isclose(table["L01"], HI) & table["branch"].isin(ids)]
    assert sorted(rows["kind"]) == ["min", "saddle"]
    for _, row in rows.iterrows():
        here = np.radians(row[ANGLES].to_numpy(float))
        assert min(_angle_gap(here, x) for x in born_hi) < 1e-6


def test_two_events_between_neighbouring_points_are_both_found(tmp_path):
    """Sweep points 0.5 and 1.7 only (8 critical points, 1 minimum; then 12 and 2): between
    them a minimum and an index-1 saddle are born, then a saddle pair (index 1 and 2). Both
    folds are found, each at the independent value (1e-6) and at the born pair's pose."""
    assert (_all(0.5), _minima(0.5), _all(1.7), _minima(1.7)) == (8, 1, 12, 2)
    code, events, _ = _sweep(tmp_path, 0.5, 1.7, 2)
    assert code == 0
    assert sorted(events["kind"]) == ["fold", "fold", "stability_change"], events.to_string()
    folds = events[events["kind"] == "fold"].sort_values("L01")
    expected = ((_fold(LO, HI, _minima), [0, 1]), (_fold(HI, 1.7, _all), [1, 2]))
    for (_, fold), (value, indices) in zip(folds.iterrows(), expected, strict=True):
        assert abs(fold["L01"] - value) < 1e-6 and bool(fold["refined"])
        born = _born(value)
        assert sorted(i for _, i in born) == indices
        pose = np.radians(fold[ANGLES].to_numpy(float))
        assert _angle_gap(pose, _middle(born)) < np.radians(1e-4)
    stable = events[events["kind"] == "stability_change"]
    assert abs(stable["L01"].iloc[0] - expected[0][0]) < 1e-6


def test_a_fold_is_located_on_its_system_and_proved_by_two_solves(tmp_path, monkeypatch):
    """Between the sweep points LO and HI the fold is located by Newton on the fold system
    (grad V = 0, H v = 0) from the pair that meets there, then proved by one full solve on each
    side of it, 1e-9 apart: two solves, not a bisection's thirty; at the independent value."""
    import cotm_bertini.point as point

    calls = []
    solve = point.solve_framework_point
    monkeypatch.setattr(
        point, "solve_framework_point", lambda *a, **k: calls.append(1) or solve(*a, **k)
    )
    code, events, _ = _sweep(tmp_path, LO, HI, 2)
    assert code == 0
    fold = events[events["kind"] == "fold"]
    assert len(fold) == 1 and len(calls) == 2, events.to_string()
    assert bool(fold["refined"].iloc[0]) and fold["bracket"].iloc[0] < 2e-9
    assert abs(fold["L01"].iloc[0] - _fold(LO, HI, _minima)) < 1e-6


def test_a_sweep_of_the_stable_states_alone_finds_the_fold_where_a_minimum_is_born(tmp_path):
    """`--only stable`: the points hold their minima alone (1 at LO, 2 at HI); the fold where a
    minimum is born (with a saddle, not looked for) is located from that one minimum, proved on
    both sides, at the independent value, and named a fold."""
    code, events, table = _sweep(tmp_path, LO, HI, 2, "--only", "stable")
    assert code == 0
    assert sorted(table.groupby("L01")["stable"].sum()) == [1, 2]
    assert set(table["kind"]) == {"min"}
    fold = events[events["kind"] == "fold"]
    assert len(fold) == 1, events.to_string()
    assert bool(fold["refined"].iloc[0]) and fold["bracket"].iloc[0] < 2e-9
    assert abs(fold["L01"].iloc[0] - _fold(LO, HI, _minima)) < 1e-6
    assert fold["description"].iloc[0].startswith("a min is born at a fold")


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 3, 4])
def test_random_chains_folds_located_on_their_systems_are_the_bisection_s(seed, tmp_path,
                                                                       monkeypatch):  # fmt: skip
    """(make stress) A random three-link chain, one spring's free length swept over 41 points:
    the events with folds located on their systems are the bisection's (kind, value to 1e-6),
    a route that shares neither the fold system nor its two probes."""
    import re

    import random_mechanisms as rm

    import cotm_bertini as cb
    import cotm_bertini.continuation.framework_events as fe

    text = rm.planar_chain(seed, 3).toml(f"chain_{seed}")
    m = re.search(r"\[\[springs\]\][^\[]*?L0 = ([0-9.eE+-]+)", text, re.S)
    v = float(m.group(1))
    text = text[: m.start(1)] + '"P"' + text[m.end(1) :]
    path = tmp_path / "chain.toml"
    path.write_text(text.replace("dim = 2\n", f"dim = 2\n\n[parameters]\nP = {v}\n", 1))
    fw = cb.Framework.from_toml(path)
    values = np.linspace(0.3 * v, 2.0 * v, 41)
    located = cb.sweep(fw, "P", values, out=tmp_path / "a").events
    monkeypatch.setattr(fe, "_pinned", lambda *a, **k: None)
    bisected = cb.sweep(fw, "P", values, out=tmp_path / "b").events
    assert len(located) == len(bisected) > 0
    assert list(located["kind"]) == list(bisected["kind"])
    assert np.abs(located["P"].to_numpy() - bisected["P"].to_numpy()).max() < 1e-6
