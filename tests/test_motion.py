"""Quasi-static moves (cb.move) against routes that share no code with the follower: dense scans
and walks down independent energies (tests/framework_physics.py, tests/physics.py), small
parameter steps each followed by a descent from the previous pose, and closed-form geometry."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import run_cli
from framework_physics import scan_critical_points, zeeman_energy
from physics import energy as paper_energy

import cotm_bertini as cb
from cotm_bertini.api.motion import move

ROOT = Path(__file__).resolve().parent.parent
SLACK = ROOT / "tests" / "fixtures" / "zeeman_slack.toml"
PAPER_FOLD_L01 = 11.0128  # case 2's fold on L01 (the paper, Fig. 5)
# One xdist worker for the moves and the explorer: both map Zeeman's machine over one window, and
# a worker's cache then solves its fold curves and 2-D sweep once.
pytestmark = pytest.mark.xdist_group("zeeman-map")


# --- an independent quasi-static simulation in one angle ----------------------------------------


def _slope(f, t: float, h: float = 1e-6) -> float:
    return (f(t + h) - f(t - h)) / (2 * h)


def walk_down(f, t: float) -> float:
    """The minimum of f(theta) reached by walking downhill from t in steps of 1e-3 rad, then
    bisecting the sign change of the central-difference slope to 1e-13 rad."""
    step = -np.sign(_slope(f, t)) * 1e-3
    if step == 0:
        return t
    while np.sign(_slope(f, t + step)) == np.sign(_slope(f, t)):
        t += step
    a, b = t, t + step
    sa = np.sign(_slope(f, a))
    while abs(b - a) > 1e-13:
        m = (a + b) / 2
        if np.sign(_slope(f, m)) == sa:
            a = m
        else:
            b = m
    return (a + b) / 2


def quasi_static_1d(energy_at, values: np.ndarray, t0: float) -> np.ndarray:
    """The angle after each parameter value: a walk down from the previous one."""
    out, t = [], walk_down(energy_at(values[0]), t0)
    for v in values:
        t = walk_down(energy_at(v), t)
        out.append(t)
    return np.array(out)


def _deg_gap(a, b) -> float:
    return float(abs((np.asarray(a) - np.asarray(b) + 180.0) % 360.0 - 180.0).max())


def _fold_between(energy_at, v_lo: float, v_hi: float, t_lo: float) -> float:
    """The parameter where the minimum followed from t_lo (at v_lo) stops existing, by bisection
    on whether a walk down from it stays within 0.3 rad."""
    while abs(v_hi - v_lo) > 1e-11:
        m = (v_lo + v_hi) / 2
        t = walk_down(energy_at(m), t_lo)
        if abs(t - t_lo) < 0.3:
            v_lo, t_lo = m, t
        else:
            v_hi = m
    return (v_lo + v_hi) / 2


# --- Zeeman's hysteresis loop ------------------------------------------------------------------


@pytest.fixture(scope="module")
def zeeman_move():
    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman.toml").replace(x=0.1, y=-0.8)
    res = cb.solve(fw)
    (sid,) = res.stable.solution_id  # one stable state at (0.1, -0.8)
    return res, move(res, state=int(sid), path={"y": [-0.8, 0.2, -0.8]})


def _zeeman_energy_at(y):
    return lambda t: zeeman_energy(t, (0.1, y), cables=False)


@pytest.fixture(scope="module")
def zeeman_simulated(zeeman_move):
    """The independent simulation of the loop: (ys, angles, the two fold values of y)."""
    res, _ = zeeman_move
    start = np.radians(float(res.stable["wheel.angle_deg"].iloc[0]))
    ys = np.concatenate([np.linspace(-0.8, 0.2, 1001), np.linspace(0.2, -0.8, 1001)[1:]])
    sim = quasi_static_1d(_zeeman_energy_at, ys, start)
    jumps = np.flatnonzero(np.abs(np.diff(sim)) > 0.3)
    assert len(jumps) == 2
    folds = [_fold_between(_zeeman_energy_at, ys[k], ys[k + 1], sim[k]) for k in jumps]
    return ys, sim, folds


def test_zeeman_loop_snaps_where_an_independent_scan_puts_the_folds(zeeman_move, zeeman_simulated):
    """Up and back along y at x = 0.1: two folds, where an independent simulation (steps of
    1e-3 in y, each a walk down V(theta) from the previous angle) jumps, refined by bisection
    to 1e-11; the state at each leg's end is the simulation's."""
    res, mv = zeeman_move
    ys, sim, folds = zeeman_simulated
    assert list(mv.snaps.kind) == ["fold", "fold"]
    assert np.abs(mv.snaps.y.to_numpy() - folds).max() < 1e-6, (list(mv.snaps.y), folds)
    assert (mv.snaps.released > 0).all() and mv.status == "ok"
    steps = mv.table[mv.table.event == "step"]
    for s, k in ((1.0, 1000), (2.0, len(ys) - 1)):
        row = steps[np.isclose(steps.s, s)].iloc[0]
        assert _deg_gap(row["wheel.angle_deg"], np.degrees(sim[k])) < 1e-6
    assert mv.ends_in == int(res.stable.solution_id.iloc[0])  # the loop returns to its state


def test_move_png_names_each_snap_by_the_parameter_there(zeeman_move, zeeman_simulated):
    """move.png's title: `fold at y = ...` with the y of the independent simulation's folds (5
    significant digits), and y from the path's waypoints at the snap's position s (linear
    between -0.8, 0.2, -0.8), not the position itself."""
    from cotm_bertini.plot.motion import move_figure, snaps_text

    _, mv = zeeman_move
    labels = snaps_text(mv).split("; ")
    values = [float(re.fullmatch(r"fold at y = (\S+)", label).group(1)) for label in labels]
    assert np.abs(np.array(values) - zeeman_simulated[2]).max() < 1e-4
    s = mv.snaps.s.to_numpy()
    on_path = np.where(s <= 1, -0.8 + s, 0.2 - (s - 1))
    assert labels == [f"fold at y = {y:.5g}" for y in on_path]
    title = " ".join(move_figure(mv)._suptitle.get_text().split())
    assert all(label in title for label in labels) and "s =" not in title
    assert "along y: -0.8 -> 0.2 -> -0.8" in title


def test_every_step_row_is_a_minimum_of_the_independent_energy(zeeman_move):
    """At every recorded step the angle is a minimum of the independent V: slope 0 (central
    differences) and positive curvature."""
    _, mv = zeeman_move
    steps = mv.table[mv.table.event == "step"]
    for y, deg in zip(steps.y, steps["wheel.angle_deg"], strict=True):
        f = (lambda y_: lambda t: zeeman_energy(t, (0.1, y_), cables=False))(y)
        t = np.radians(deg)
        assert abs(_slope(f, t)) < 1e-7
        assert f(t + 1e-3) + f(t - 1e-3) - 2 * f(t) > 0


# --- the paper's case 2 along L01 --------------------------------------------------------------


def _torus_settle(energy, x: np.ndarray) -> np.ndarray:
    """A minimum of energy(g1, g2) from x: Newton with central-difference derivatives where the
    Hessian is positive definite, else backtracking steps down the gradient."""
    h, k = 1e-5, 1e-4
    e = np.eye(2)
    for _ in range(5000):
        g = np.array([(energy(*(x + h * d)) - energy(*(x - h * d))) / (2 * h) for d in e])
        H = np.array([[(energy(*(x + k * a + k * b)) - energy(*(x + k * a - k * b))
                        - energy(*(x - k * a + k * b)) + energy(*(x - k * a - k * b)))
                       / (4 * k * k) for b in e] for a in e])  # fmt: skip
        if np.linalg.eigvalsh(H).min() > 0:
            step = -np.linalg.solve(H, g)
            if np.abs(step).max() < 0.05:
                x = x + step
                if np.abs(step).max() < 1e-9:  # the differences' noise: about 1e-10 rad
                    return x
                continue
        d, t = -g / np.linalg.norm(g), 0.02
        while energy(*(x + t * d)) >= energy(*x) and t > 1e-14:
            t /= 2
        x = x + t * d
    raise AssertionError("no minimum within 5000 steps")


def test_case2_snaps_at_the_papers_fold_and_lands_as_an_independent_torus_simulation():
    """Case 2 from L01 = 12 down to 10 and back: each stable state followed, against small steps
    of L01 (2e-3) each followed by a descent of the independent V on the torus; the snap at the
    paper's fold L01 = 11.0128 m, inside the simulation's jump, landing where it lands."""
    params = cb.Params.case("case2").replace(L01=12.0)
    res = cb.solve(params)
    values = np.concatenate([np.linspace(12, 10, 1001), np.linspace(10, 12, 1001)[1:]])
    snapped = 0
    for _, row in res.stable.iterrows():
        mv = move(res, state=int(row.solution_id), path={"L01": [12.0, 10.0, 12.0]})
        x = np.radians([row.gamma1_deg, row.gamma2_deg])
        sim = []
        for v in values:
            p = params.replace(L01=float(v))
            x = _torus_settle(lambda a, b, p=p: paper_energy(p, a, b), x)
            sim.append(np.degrees(x))
        sim = np.array(sim)
        jumps = np.flatnonzero(np.abs(np.diff(sim, axis=0)).max(axis=1) > 5.0)
        assert len(mv.snaps) == len(jumps)
        for (_, snap), k in zip(mv.snaps.iterrows(), jumps, strict=True):
            snapped += 1
            assert snap.kind == "fold"
            assert abs(snap.L01 - PAPER_FOLD_L01) < 5e-5
            assert min(values[k], values[k + 1]) <= snap.L01 <= max(values[k], values[k + 1])
            p = params.replace(L01=snap.L01 - 1e-6)  # just past the fold, from its pose
            before = np.radians([snap["before.gamma1_deg"], snap["before.gamma2_deg"]])
            land = np.degrees(_torus_settle(lambda a, b, p=p: paper_energy(p, a, b), before))
            assert _deg_gap([snap["after.gamma1_deg"], snap["after.gamma2_deg"]], land) < 1e-3
        steps = mv.table[mv.table.event == "step"]
        for s, k in ((1.0, 1000), (2.0, len(values) - 1)):
            got = steps[np.isclose(steps.s, s)].iloc[0][["gamma1_deg", "gamma2_deg"]]
            assert _deg_gap(got.to_numpy(float), sim[k]) < 1e-5
    assert snapped == 1  # one of the two stable states falls off the fold on the way down


# --- a cable going slack -----------------------------------------------------------------------


def _slack_energy(u):
    def f(t):
        rim = np.array([1 + 0.5 * np.cos(t), 0.5 * np.sin(t)])
        du, dp = np.hypot(*(rim - np.asarray(u))), np.hypot(*(rim - np.array([2.0, 0.25])))
        return 2.0 * max(du - 0.25, 0.0) ** 2 + 0.5 * max(dp - 0.25, 0.0) ** 2

    return f


def test_a_cable_going_slack_snaps_with_kind_cable_switch():
    """The stiff band holds the wheel next to the maximum of the other band alone (theta* on the
    line from p through the centre); moving u away, the band reaches its free length at theta*
    (closed form: |rim(theta*) - u| = L0) and the wheel falls to where an independent walk down
    the piecewise V goes."""
    star = np.arctan2(0.25, 1.0) + np.pi
    rim = np.array([1 + 0.5 * np.cos(star), 0.5 * np.sin(star)])
    tangent = np.array([-np.sin(star), np.cos(star)])
    u0, u1 = np.round(rim + 0.2 * tangent, 4), np.round(rim + 0.3 * tangent, 4)
    fw = cb.Framework.from_toml(SLACK).replace(x=float(u0[0]), y=float(u0[1]))
    res = cb.solve(fw)
    near = res.stable[_deg_gap_col(res.stable["wheel.angle_deg"], np.degrees(star)) < 20]
    assert len(near) == 1
    path = {"x": [float(u0[0]), float(u1[0])], "y": [float(u0[1]), float(u1[1])]}
    mv = move(res, state=int(near.solution_id.iloc[0]), path=path)
    # Where |rim - u(s)| = 0.25 along the straight path: a quadratic in s.
    d, w = u1 - u0, u0 - rim
    a, b, c = d @ d, 2 * d @ w, w @ w - 0.25**2
    s_switch = min(r for r in np.roots([a, b, c]).real if 0 <= r <= 1)
    (snap,) = mv.snaps.itertuples()
    assert snap.kind == "cable_switch"
    assert abs(snap.s - s_switch) < 1e-7
    assert _deg_gap(mv.snaps["before.wheel.angle_deg"].iloc[0], np.degrees(star)) < 1e-5
    u_past = u0 + (snap.s + 1e-9) * d
    land = walk_down(_slack_energy(u_past), star + 1e-6 * np.sign(snap.s))
    assert _deg_gap(mv.snaps["after.wheel.angle_deg"].iloc[0], np.degrees(land)) < 1e-5
    ss = np.linspace(0, 1, 1001)
    sim = quasi_static_1d(lambda s: _slack_energy(u0 + s * d), ss,
                          np.radians(float(near["wheel.angle_deg"].iloc[0])))  # fmt: skip
    assert _deg_gap(mv.table["wheel.angle_deg"].iloc[-1], np.degrees(sim[-1])) < 1e-5


def _deg_gap_col(a, b) -> np.ndarray:
    return np.abs((np.asarray(a, float) - b + 180.0) % 360.0 - 180.0)


# --- input, files, command line ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"path": {"z": [0.0, 1.0]}}, "'z' is no parameter"),
        ({"path": {"y": [-0.8]}}, "at least 2 waypoints"),
        ({"path": {"y": [-0.8, 0.2], "x": [0.1, 0.2, 0.3]}}, "3 waypoints"),
        ({"path": {"y": [-0.5, 0.2]}}, "starts at -0.5"),
        ({"path": {"y": [-0.8, float("nan")]}}, "not a finite number"),
        ({"path": {"y": [-0.8, 0.2]}, "state": 2}, "not a stable solution_id"),
        ({"path": {"y": [-0.8, 0.2]}, "steps": 0}, "steps = 0"),
        ({"path": {"y": [-0.8, 1e15]}}, "y = 1e"),  # a waypoint the framework refuses
    ],
)
def test_bad_input_is_refused_in_one_line(zeeman_move, kwargs, message):
    res, _ = zeeman_move
    args = {"state": 1, **kwargs}
    with pytest.raises(cb.ParameterError, match=message) as err:
        move(res, **args)
    assert "\n" not in str(err.value)


def test_the_command_line_writes_the_run(tmp_path):
    """`move` solves at the path's start, follows, writes the run folder; a bad path: exit 2."""
    zeeman = str(ROOT / "examples" / "zeeman.toml")
    args = ["move", "--framework", zeeman, "--set", "x=0.1", "--state", "1", "--quiet"]
    done = run_cli(*args, "--path", "y=-0.8,0.2,-0.8", "--steps", "20", "--out", str(tmp_path),
                   "--html")  # fmt: skip
    assert done.returncode == 0, done.stderr
    folder = tmp_path / "latest"
    names = {p.name for p in folder.iterdir()}
    assert names >= {"trajectory.csv", "snaps.csv", "run.json", "columns.md", "move.png",
                     "move.gif", "explore.html"}  # fmt: skip
    record = json.loads((folder / "run.json").read_text())
    assert record["snaps"] == 2 and record["ends_in"] == 1 and record["status"] == "ok"
    assert record["path"] == {"y": [-0.8, 0.2, -0.8]} and record["params"]["y"] == -0.8
    bad = run_cli(*args, "--path", "y=-0.8,x", "--out", str(tmp_path / "b"))
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "--path" in bad.stderr
    assert not (tmp_path / "b").exists()


# --- plans -------------------------------------------------------------------------------------

WINDOW = ("x", (-0.6, 0.8), "y", (-0.8, 0.2))
ZEEMAN_POINTS = 15  # tests/test_explore.py maps the same window alike: its sweep is then cached


@pytest.fixture(scope="module")
def zeeman_bistable():
    """Zeeman's machine inside its bistable region, and a 15 x 15 map around it."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman.toml").replace(x=0.1, y=-0.25)
    res = cb.solve(fw)
    assert len(res.stable) == 2
    return res, cb.design_map(fw, *WINDOW, points=ZEEMAN_POINTS)


def _simulate_waypoints(path, theta: float) -> tuple[float, int]:
    """The independent quasi-static simulation along straight segments between waypoints (steps
    of at most 1e-3 in x and y, a walk down V from the previous angle each): the final angle
    and the number of jumps (over 0.3 rad in one step)."""
    pts = path[["x", "y"]].to_numpy(float)
    jumps = 0
    theta = walk_down(lambda t: zeeman_energy(t, tuple(pts[0]), cables=False), theta)
    for a, b in zip(pts[:-1], pts[1:], strict=True):
        n = max(1, int(np.ceil(np.abs(b - a).max() / 1e-3)))
        for k in range(1, n + 1):
            u = tuple(a + k / n * (b - a))
            new = walk_down(lambda t, u=u: zeeman_energy(t, u, cables=False), theta)
            jumps += abs(new - theta) > 0.3
            theta = new
    return theta, jumps


@pytest.mark.parametrize("order", [0, 1])
def test_a_plan_between_zeeman_states_ends_in_the_goal(zeeman_bistable, order):
    """From each stable state to the other: the path starts and ends at the solve's values, and
    the independent simulation of its waypoints ends in the goal, with the move's snaps."""
    res, dm = zeeman_bistable
    a, b = (res.stable.solution_id.tolist())[:: 1 if order == 0 else -1]
    pl = cb.plan(res, a, b, WINDOW, design_map=dm)
    assert pl.status == "ok" and pl.move.ends_in == b
    start = pl.path.iloc[0].to_dict()
    assert start == {"x": 0.1, "y": -0.25} == pl.path.iloc[-1].to_dict()
    angle = dict(
        zip(res.stable.solution_id, np.radians(res.stable["wheel.angle_deg"]), strict=True)
    )
    end, jumps = _simulate_waypoints(pl.path, angle[a])
    goal = walk_down(lambda t: zeeman_energy(t, (0.1, -0.25), cables=False), angle[b])
    assert _deg_gap(np.degrees(end), np.degrees(goal)) < 1e-6
    assert jumps == len(pl.move.snaps) == pl.record["snaps"]
    assert cb.move(res, a, pl.path).ends_in == b  # the plan's table is a path as it is


def test_a_plan_after_the_identical_map_reuses_it(zeeman_bistable, monkeypatch):
    """Issue 39, item 6: a plan over the window and grid of a map made before takes that map
    from the cache (no sweep, no fold curve: both raise here), and its run.json says so;
    another grid is another map."""
    from cotm_bertini.api import maps, sweeps

    res, dm = zeeman_bistable
    a, b = res.stable.solution_id.tolist()

    def no(*args, **kwargs):
        raise AssertionError("the map was made again")

    monkeypatch.setattr(sweeps, "sweep", no)
    monkeypatch.setattr(maps, "fold_points", no)
    pl = cb.plan(res, a, b, WINDOW, points=ZEEMAN_POINTS)
    assert pl.record["map_reused"] is True and pl.map.record["reused"] is True
    assert pl.map.regions.equals(dm.regions) and pl.map.folds.equals(dm.folds)
    assert pl.status == "ok"
    with pytest.raises(AssertionError, match="made again"):
        cb.plan(res, a, b, WINDOW, points=ZEEMAN_POINTS + 1)


def test_a_window_inside_the_bistable_region_is_unreachable(zeeman_bistable):
    """A small window around the start where, by independent scans of V at its corners and
    centre, both stable states exist throughout: no plan, and the answer says so."""
    res, _ = zeeman_bistable
    window = ("x", (0.05, 0.15), "y", (-0.27, -0.23))
    for u in [(0.05, -0.27), (0.05, -0.23), (0.15, -0.27), (0.15, -0.23), (0.1, -0.25)]:
        kinds = [k for _, k in scan_critical_points(lambda t, u=u: zeeman_energy(t, u, False))]
        assert kinds.count("min") == 2
    a, b = res.stable.solution_id.tolist()
    pl = cb.plan(res, a, b, window, points=5)
    assert pl.status == "unreachable" and pl.move is None and pl.path.empty


def test_plan_input_is_refused_in_one_line(zeeman_bistable):
    res, dm = zeeman_bistable
    a, b = res.stable.solution_id.tolist()
    cases = [
        ({"state": a, "goal": a, "over": WINDOW}, "already"),
        ({"state": a, "goal": 99, "over": WINDOW}, "goal = 99"),
        ({"state": a, "goal": b, "over": ("x", (0.2, 0.8), "y", (-0.8, 0.2))}, "outside"),
        ({"state": a, "goal": b, "over": WINDOW, "design_map": dm, "points": 5}, "as it is"),
        ({"state": a, "goal": b, "over": ("x", (-0.6, 0.7), "y", (-0.8, 0.2)), "design_map": dm},
         "window"),
    ]  # fmt: skip
    for kwargs, message in cases:
        with pytest.raises(cb.ParameterError, match=message) as err:
            cb.plan(res, **kwargs)
        assert "\n" not in str(err.value)


def test_the_plan_command_writes_its_run(tmp_path):
    """`plan` on the command line: the path, the move that checks it, the pictures."""
    zeeman = str(ROOT / "examples" / "zeeman.toml")
    done = run_cli("plan", "--framework", zeeman, "--set", "x=0.1", "--set", "y=-0.25",
                   "--state", "1", "--goal", "2", "--param", "x", "--from", "-0.6", "--to", "0.8",
                   "--param2", "y", "--from2", "-0.8", "--to2", "0.2", "--points", "11",
                   "--workers", "1", "--quiet", "--out", str(tmp_path))  # fmt: skip
    assert done.returncode == 0, done.stderr
    folder = tmp_path / "latest"
    names = {p.name for p in folder.iterdir()}
    assert names >= {"plan.csv", "trajectory.csv", "snaps.csv", "run.json", "plan.png",
                     "move.png", "move.gif", "columns.md"}  # fmt: skip
    record = json.loads((folder / "run.json").read_text())
    assert record["status"] == "ok" and record["move_ends_in"] == 2
    plan_csv = (folder / "plan.csv").read_text().splitlines()
    assert plan_csv[0] == "x,y" and plan_csv[1] == plan_csv[-1] == "0.1,-0.25"


# --- a degenerate point on the path ------------------------------------------------------------


class _Quartic:
    """V = t^4/4 - a t^2/2 (one angle t, parameter a): a pitchfork at a = 0, where the minimum
    t = 0 becomes a maximum between two new minima at +-sqrt(a)."""

    newton_tol, zero_length, length_unit, hessian_unit = 1e-13, 0.0, 1.0, 1.0

    def __init__(self, a: float):
        self.a = a

    def energy(self, x):
        return float(x[0] ** 4 / 4 - self.a * x[0] ** 2 / 2)

    def gradient(self, x):
        return np.array([x[0] ** 3 - self.a * x[0]])

    def eigh(self, x):
        return np.array([3 * x[0] ** 2 - self.a]), np.eye(1)

    def newton(self, x, grad):
        h = 3 * x[0] ** 2 - self.a
        return None if h <= 0 else -grad / h

    def move(self, x, step):
        return x + step

    def shortest(self, x):
        return np.inf

    def cable_gap(self, x):
        return np.inf


def test_a_pitchfork_on_the_path_is_reported_not_chosen():
    """Through a = 0 the state at t = 0 goes on without falling; the follower says so (kind
    degenerate, a warning) instead of calling it a fold."""
    from cotm_bertini.motion.follow import follow
    from cotm_bertini.motion.path import actuator_path

    path = actuator_path({"a": [-1.0, 1.0]}, {"a": -1.0})
    f = follow(lambda v: _Quartic(v["a"]), path, np.array([0.05]), 20)
    # Newton converges only linearly at the degenerate minimum (V ~ t^4), so the state may be
    # reported at the last step before a = 0 as well as at it: each report says degenerate.
    assert f.snaps and all(sn.kind == "degenerate" and abs(sn.s - 0.5) < 1e-9 for sn in f.snaps)
    assert len(f.warnings) == len(f.snaps) and all("pitchfork" in w for w in f.warnings)
    assert abs(abs(f.states[-1][0]) - 1.0) < 1e-12  # on one of the two new minima, sqrt(1)


def test_a_zero_energy_fold_of_the_paper_is_passed_and_reported():
    """From L01 = L02 = 3.5 m along L01, the stable state reaches a pose with both springs at
    their free lengths (V = 0) exactly where their length gradients are parallel: a singular
    minimum where zero-energy poses are born. Newton on independent equations (d2 = 3.5 m and
    det d(d1, d2)/d(gamma) = 0, the physics module's lengths, differences for derivatives; the
    snap's pose only as a first guess) puts it at L01 = d1 there. The move reports it as
    degenerate and still reaches the path's end (before STALLED it stopped there)."""
    from physics import points as pts

    p = cb.Params(L01=3.5, L02=3.5)
    res = cb.solve(p)
    (sid,) = res.stable.solution_id  # one stable state there
    mv = move(res, int(sid), {"L01": [3.5, 10.5]})
    assert mv.table.s.iloc[-1] == 1.0 and set(mv.snaps.kind) == {"degenerate"}
    assert mv.status == "incomplete" and all("pitchfork" in w for w in mv.warnings)

    def lengths(g):
        q = pts(p, *g)
        return np.array([np.linalg.norm(q[6] - q[2]), np.linalg.norm(q[5] - q[3])])

    def jac(g, h=1e-6):
        return np.array([(lengths(g + h * e) - lengths(g - h * e)) / (2 * h) for e in np.eye(2)]).T

    def equations(g):  # d2 = L02 and the springs' length gradients parallel
        return np.array([lengths(g)[1] - 3.5, np.linalg.det(jac(g))])

    snap = mv.snaps.iloc[0]
    g = np.radians([snap["before.gamma1_deg"], snap["before.gamma2_deg"]])  # a first guess only
    for _ in range(40):  # Newton on the independent equations, derivatives by differences
        h = 1e-5
        J = np.array([(equations(g + h * e) - equations(g - h * e)) / (2 * h) for e in np.eye(2)]).T
        g = g - np.linalg.solve(J, equations(g))
    assert np.abs(equations(g)).max() < 1e-8
    d1 = lengths(g)[0]
    assert abs(mv.snaps.L01.iloc[0] - d1) < 1e-6, (list(mv.snaps.L01), d1)
