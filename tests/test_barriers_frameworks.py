"""Energy barriers of frameworks (issue 19), each against a route that shares no code with the
gradient flow: a dense scan of an independent energy around Zeeman's wheel and along the
four-bar's loop (its position equations solved in closed form), and a mountain pass on a dense
grid of the double pendulum's torus (cells flooded in order of V, basins joined by union-find).
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from conftest import ROOT, run_cli
from framework_physics import (
    fourbar_branch,
    fourbar_energy,
    grid_minima,
    pendulum_energy,
    scan_critical_points,
    zeeman_energy,
)

import cotm_bertini as cb
from cotm_bertini.errors import ParameterError

# These share the cold generic sets of the costly examples (fourbar, double pendulum,
# cotm.toml): one xdist worker runs them in turn, so each set is solved once.
pytestmark = pytest.mark.xdist_group("framework_examples")

EXAMPLES = ROOT / "examples"
BISTABLE = (0.1, -0.25)  # u = (x, y) inside Zeeman's diamond: two minima, for springs and cables


def _gap_deg(a, b):
    return np.abs(np.mod(np.asarray(a, float) - np.asarray(b, float) + 180.0, 360.0) - 180.0)


def _arc_max(f, start: float, width: float, n: int = 400_001) -> float:
    """max of f on the arc from `start` (rad) over `width` (rad, increasing), by a dense scan
    refined by golden-section search around the best sample."""
    t = start + np.linspace(0.0, width, n)
    v = f(t)
    k = int(np.argmax(v))
    a, b = t[max(k - 1, 0)], t[min(k + 1, n - 1)]
    g = (np.sqrt(5) - 1) / 2
    for _ in range(80):
        c, d = b - g * (b - a), a + g * (b - a)
        if f(c) > f(d):
            b = d
        else:
            a = c
    return float(f((a + b) / 2))


def _check_monotone(paths, energy_of):
    """Along every descent V (the independent energy at the path's pose) never rises and equals
    the path's own `energy` column."""
    for path in paths:
        V = energy_of(path)
        assert np.allclose(V, path.energy, rtol=1e-10, atol=1e-12)
        assert np.all(np.diff(V) <= 1e-12 * max(1.0, np.abs(V).max()))


# ---- Zeeman: one degree of freedom ---------------------------------------------------------


@pytest.mark.parametrize("cables", [False, True])
def test_zeeman_barriers_are_the_highest_points_of_the_arcs(cables):
    name = "zeeman_cables" if cables else "zeeman"
    fw = cb.Framework.from_toml(EXAMPLES / f"{name}.toml").replace(x=BISTABLE[0], y=BISTABLE[1])
    res = cb.solve(fw)
    found = cb.barriers(res)
    assert found.warnings == []

    def V(t):
        return zeeman_energy(t, BISTABLE, cables)

    minima = [t for t, kind in scan_critical_points(V) if kind == "min"]
    assert len(minima) == 2
    arcs = [(minima[0], minima[1]), (minima[1], minima[0])]
    peaks = [_arc_max(V, a, np.mod(b - a, 2 * np.pi)) for a, b in arcs]
    stable = res.stable
    assert len(found.table) == 2
    for _, row in found.table.iterrows():
        ends = stable.loc[[row.min_a, row.min_b], "wheel.angle_deg"].to_numpy(float)
        assert set(np.argmin(_gap_deg(ends[:, None], np.degrees(minima)), axis=1)) == {0, 1}
        # The saddle (a maximum of V on the circle) lies on one arc: its barrier is that arc's
        # highest value above each minimum.
        t_s = np.radians(row["wheel.angle_deg"])
        on = [np.mod(t_s - a, 2 * np.pi) < np.mod(b - a, 2 * np.pi) for a, b in arcs]
        peak = peaks[on.index(True)]
        assert row.saddle_energy == pytest.approx(peak, rel=1e-6)
        for end, barrier in ((row.min_a, row.barrier_a), (row.min_b, row.barrier_b)):
            gap = _gap_deg(np.degrees(minima), stable.loc[end, "wheel.angle_deg"])
            t_min = minima[int(np.argmin(gap))]
            assert barrier == pytest.approx(peak - float(V(t_min)), rel=1e-6)
    (pair,) = found.pairs.itertuples()
    assert pair.saddle_energy == pytest.approx(min(peaks), rel=1e-6)
    paths = [p for pair in found.paths.values() for p in pair]
    _check_monotone(paths, lambda p: V(np.radians(p["wheel.angle_deg"].to_numpy())))


def test_a_capped_flow_reports_non_convergence():
    fw = cb.Framework.from_toml(EXAMPLES / "zeeman.toml").replace(x=BISTABLE[0], y=BISTABLE[1])
    res = cb.solve(fw)
    capped = cb.barriers(res, max_steps=3)
    assert not capped.table.converged.any()
    assert capped.table.min_a.isna().all() and capped.pairs.empty
    assert len(capped.warnings) == 2
    assert all("did not converge in 3 steps" in w for w in capped.warnings)
    for bad in (0, -2, 2.5, True):
        with pytest.raises(ParameterError, match="max_steps"):
            cb.barriers(res, max_steps=bad)


# ---- double pendulum: a torus ----------------------------------------------------------------


def _flooding_levels(V: np.ndarray, cells: list[tuple[int, int]]) -> dict:
    """For each pair of the given cells: the level of V at which their basins join when the
    periodic grid is flooded cell by cell in order of V (8 neighbours): the mountain pass."""
    n1, n2 = V.shape
    parent = np.arange(V.size)

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    flat = [i * n2 + j for i, j in cells]
    levels, wet = {}, np.zeros(V.size, dtype=bool)
    for idx in np.argsort(V, axis=None):
        wet[idx] = True
        i, j = divmod(int(idx), n2)
        for di in (-1, 0, 1):
            for dj in (-1, 0, 1):
                nb = ((i + di) % n1) * n2 + (j + dj) % n2
                if wet[nb]:
                    parent[root(nb)] = root(idx)
        for a in range(len(flat)):
            for b in range(a + 1, len(flat)):
                if (a, b) not in levels and root(flat[a]) == root(flat[b]):
                    levels[(a, b)] = float(V.flat[idx])
        if len(levels) == len(flat) * (len(flat) - 1) // 2:
            return levels
    return levels


def _bottleneck(table: pd.DataFrame, a: int, b: int) -> float:
    """The lowest level joining minima a and b through the barriers' saddles (a path may pass
    other minima): Kruskal's order until a and b are connected."""
    groups: dict[int, int] = {}

    def root(i):
        while groups.get(i, i) != i:
            i = groups[i]
        return i

    for _, r in table.dropna(subset=["min_a", "min_b"]).sort_values("saddle_energy").iterrows():
        groups[root(int(r.min_a))] = root(int(r.min_b))
        if root(a) == root(b):
            return float(r.saddle_energy)
    return np.inf


def test_double_pendulum_barriers_against_a_mountain_pass_on_the_torus():
    res = cb.solve(cb.Framework.from_toml(EXAMPLES / "double_pendulum.toml"))
    found = cb.barriers(res)
    assert found.warnings == []
    n = 400
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    V = pendulum_energy(*np.meshgrid(t, t, indexing="ij"))
    # The grid's resolution: how much V changes over a cell's second differences.
    resolution = max(np.abs(np.roll(V, 1, k) + np.roll(V, -1, k) - 2 * V).max() for k in (0, 1))
    minima = grid_minima(pendulum_energy)
    cells = [tuple(int(round(c / (2 * np.pi / n))) % n for c in m) for m in minima]
    levels = _flooding_levels(V, cells)
    stable = res.stable
    angles = stable[["link1.angle_deg", "link2.angle_deg"]].to_numpy(float)
    ids = [int(stable.index[np.argmin(_gap_deg(angles, np.degrees(m)).max(axis=1))])
           for m in minima]  # fmt: skip
    assert len(set(ids)) == len(minima) == len(stable) >= 2
    for (a, b), level in levels.items():
        ours = _bottleneck(found.table, ids[a], ids[b])
        assert abs(ours - level) <= resolution, (ids[a], ids[b], ours, level, resolution)
    assert resolution < 0.1 * np.ptp(found.table.saddle_energy)  # the check can tell saddles apart

    def along(path):
        th = np.radians(path[["link1.angle_deg", "link2.angle_deg"]].to_numpy(float))
        return pendulum_energy(th[:, 0], th[:, 1])

    _check_monotone([p for pair in found.paths.values() for p in pair], along)
    # The shortest spring along the paths, from the pendulum's own geometry.
    for sid, halves in found.paths.items():
        shortest = np.inf
        for path in halves:
            th = np.radians(path[["link1.angle_deg", "link2.angle_deg"]].to_numpy(float))
            e = np.stack([np.cos(th[:, 0]), np.sin(th[:, 0])], 1)
            tip = e + 0.8 * np.stack([np.cos(th[:, 1]), np.sin(th[:, 1])], 1)
            for point, anchor in ((e, (-0.6, 1.2)), (tip, (1.5, -0.8)), (tip, (-1.2, -1.0))):
                shortest = min(shortest, float(np.hypot(*(point - anchor).T).min()))
        assert found.table.loc[sid, "min_spring_length"] == pytest.approx(shortest, rel=1e-9)


# ---- four-bar: a closed loop (two assembly branches, each a circle) --------------------------


@pytest.mark.parametrize("values", [{}, {"ex": 2.5, "ey": 2.5, "L0": 0.5}])
def test_fourbar_barriers_against_the_loop_in_closed_form(values):
    """At the file's values (the lift cable goes slack on part of the loop the descents cross)
    each maximum joins its branch's only minimum to itself; at ex = ey = 2.5 one branch holds
    two minima, joined by two maxima."""
    fw = cb.Framework.from_toml(EXAMPLES / "fourbar.toml").replace(**values)
    res = cb.solve(fw)
    found = cb.barriers(res)
    assert found.warnings == []
    p = {"ex": 1.0, "ey": 2.0, "L0": 0.5, **values}
    stable = res.stable
    assert len(found.table) == int((res.physical.kind == "max").sum()) >= 2
    for _, row in found.table.iterrows():
        branch = fourbar_branch(row["crank.angle_deg"], row["coupler.angle_deg"])

        def V(t, b=branch):
            return fourbar_energy(t, b, **p)

        crit = scan_critical_points(V)
        minima = np.array([t for t, kind in crit if kind == "min"])
        t_s = np.radians(row["crank.angle_deg"])
        # The minima next to the saddle on its circle, up and down in crank angle.
        up = minima[np.argmin(np.mod(minima - t_s, 2 * np.pi))]
        down = minima[np.argmin(np.mod(t_s - minima, 2 * np.pi))]
        width = np.mod(up - down, 2 * np.pi) or 2 * np.pi  # one minimum: the whole circle
        peak = _arc_max(V, down, width)
        assert row.saddle_energy == pytest.approx(peak, rel=1e-6)
        got = stable.loc[[row.min_a, row.min_b]]
        pairs = zip(got["crank.angle_deg"], got["coupler.angle_deg"], strict=True)
        assert {fourbar_branch(c, f) for c, f in pairs} == {branch}
        expect = np.degrees([up, down])
        for end, barrier in ((row.min_a, row.barrier_a), (row.min_b, row.barrier_b)):
            gap = _gap_deg(stable.loc[end, "crank.angle_deg"], expect)
            assert gap.min() < 1e-6
            t_min = [up, down][int(np.argmin(gap))]
            assert barrier == pytest.approx(peak - float(V(t_min)), rel=1e-6)

        def along(path, b=branch):
            return fourbar_energy(np.radians(path["crank.angle_deg"].to_numpy(float)), b, **p)

        _check_monotone(found.paths[row.saddle_id], along)
    if not values:  # the descents pass the lift cable's switch between taut and slack
        lift = pd.concat([p.loc[:, "lift.length"] for pair in found.paths.values() for p in pair])
        assert (lift < 0.5).any() and (lift > 0.5).any()


# ---- the paper's mechanism as a framework ----------------------------------------------------


def test_cotm_framework_barriers_equal_the_built_in_models():
    """examples/cotm.toml at case 3 against the built-in model (its own energy code and
    angles): the same saddles join the same minima over the same barriers."""
    p = cb.Params.case("case3")
    fw = cb.Framework.from_toml(EXAMPLES / "cotm.toml").replace(L01=p.L01, L02=p.L02)
    ours, ref = cb.barriers(cb.solve(fw)), cb.barriers(cb.solve(p))
    assert ours.warnings == [] and ref.warnings == []
    assert len(ours.table) == len(ref.table) and len(ours.pairs) == len(ref.pairs)
    mine = ours.solutions[["rod.angle_deg", "top.angle_deg"]]
    theirs = ref.solutions[["gamma1_deg", "gamma2_deg"]].to_numpy(float)

    def paper_id(sid):
        """The built-in model's solution_id of the framework's solution `sid` (same pose)."""
        gaps = _gap_deg(theirs, mine.loc[int(sid)].to_numpy(float)).max(axis=1)
        assert gaps.min() < 1e-6
        return int(ref.solutions.index[int(np.argmin(gaps))])

    for _, row in ours.table.iterrows():
        other = ref.table.loc[paper_id(row.saddle_id)]
        assert row.saddle_energy == pytest.approx(other.saddle_energy, rel=1e-9)
        assert {paper_id(row.min_a), paper_id(row.min_b)} == {other.min_a, other.min_b}
        assert sorted([row.barrier_a, row.barrier_b]) == pytest.approx(
            sorted([other.barrier_a, other.barrier_b]), rel=1e-9, abs=1e-9
        )
        assert bool(row.lowest) == bool(other.lowest)


# ---- the command line ------------------------------------------------------------------------


def test_cli_barriers_of_a_framework(tmp_path):
    x, y = (f"{name}={value}" for name, value in zip("xy", BISTABLE, strict=True))
    run = run_cli("barriers", "--framework", str(EXAMPLES / "zeeman.toml"), "--set", x,
                  "--set", y, "--out", str(tmp_path))  # fmt: skip
    assert run.returncode == 0, run.stderr
    folder = tmp_path / "latest"
    table = pd.read_csv(folder / "barriers.csv")
    assert list(table.columns[:6]) == [
        "saddle_id", "min_a", "min_b", "barrier_a", "barrier_b", "wheel.angle_deg",
    ]  # fmt: skip
    assert table.lowest.sum() == 1 and table.converged.all()
    assert (folder / "barriers.png").is_file() and (folder / "barriers.svg").is_file()
    assert "barriers.csv of a framework" in (folder / "columns.md").read_text()
    record = json.loads((folder / "barriers.json").read_text())
    assert record["params"] == {"x": BISTABLE[0], "y": BISTABLE[1]}
    assert record["framework"]["name"] == "zeeman" and record["warnings"] == []


# ---- spatial: a rigid body on a ball joint (unit quaternions) ---------------------------------

TOP = """
name = "top"
dim = 3
nodes = []

[parameters]
k = 1.0

[ground]
o = [0.0, 0.0, 0.0]
a = [0.3, 0.2, 1.5]
b = [1.2, -0.4, 0.3]
c = [-0.5, 1.1, -0.2]

[bodies.top]
o = [0.0, 0.0, 0.0]
p = [1.0, 0.0, 0.0]
q = [0.0, 0.8, 0.0]
r = [0.1, 0.2, 0.6]

[[pins]]
a = "top.o"
b = "ground.o"
""" + "".join(
    f'\n[[springs]]\nname = "s{p}"\na = "top.{p}"\nb = "ground.{g}"\nk = {k}\nL0 = 0.0\n'
    for p, g, k in (("p", "a", '"k"'), ("q", "b", 1.3), ("r", "c", 0.7))
)
TOP_SPRINGS = [  # (body point, ground point, k), as in TOP
    ((1.0, 0.0, 0.0), (0.3, 0.2, 1.5), 1.0),
    ((0.0, 0.8, 0.0), (1.2, -0.4, 0.3), 1.3),
    ((0.1, 0.2, 0.6), (-0.5, 1.1, -0.2), 0.7),
]


def _rotation(q):
    w, x, y, z = np.asarray(q, float).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)  # fmt: skip


@pytest.mark.slow
def test_spatial_top_barrier_against_the_closed_form(tmp_path):
    """With zero-free-length springs V(R) = const - tr(M R), M = sum k a p^T: its critical
    values on SO(3) are const - (s1 + s2 + s3), const - (s1 - s2 - s3), ... (s: the singular
    values of M, s3 signed by det M), so the barrier over the index-1 saddle is 2 (s2 + s3)."""
    (tmp_path / "top.toml").write_text(TOP)
    res = cb.solve(cb.Framework.from_toml(tmp_path / "top.toml"))
    found = cb.barriers(res)
    assert found.warnings == [] and len(found.table) >= 1
    M = sum(k * np.outer(a, p) for p, a, k in TOP_SPRINGS)
    s = np.linalg.svd(M, compute_uv=False) * np.array([1, 1, np.sign(np.linalg.det(M))])
    const = sum(k / 2 * (np.dot(p, p) + np.dot(a, a)) for p, a, k in TOP_SPRINGS)
    lowest, saddle = const - s.sum(), const - (s[0] - s[1] - s[2])
    for _, row in found.table.iterrows():
        assert row.saddle_energy == pytest.approx(saddle, rel=1e-9)
        assert row.barrier_a == pytest.approx(saddle - lowest, rel=1e-9)
        assert row.barrier_b == pytest.approx(saddle - lowest, rel=1e-9)
    assert found.pairs.empty  # one minimum: each saddle joins it to itself

    def along(path):
        R = _rotation(path[["top.qw", "top.qx", "top.qy", "top.qz"]].to_numpy(float))
        return sum(k / 2 * ((R @ np.array(p) - a) ** 2).sum(-1) for p, a, k in TOP_SPRINGS)

    _check_monotone([p for pair in found.paths.values() for p in pair], along)
