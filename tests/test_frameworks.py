"""Frameworks from a file (issue 18): validation, and each example's equilibria against a route
that shares no code with the solver (dense scans and local searches of an independent energy,
the built-in paper model)."""

from __future__ import annotations

import os

import numpy as np
import pytest
from conftest import ROOT
from framework_physics import (
    fourbar_branch,
    fourbar_energy,
    fourbar_points,
    gradient_norm,
    grid_minima,
    pendulum_energy,
    scan_critical_points,
    zeeman_energy,
)
from physics import mp_refine

import cotm_bertini as cb
from cotm_bertini.errors import ParameterError

# These share the cold generic sets of the costly examples (fourbar, double pendulum,
# cotm.toml): one xdist worker runs them in turn, so each set is solved once.
pytestmark = pytest.mark.xdist_group("framework_examples")

EXAMPLES = ROOT / "examples"


def _angle_gap(a, b):
    d = np.abs(np.mod(np.asarray(a) - np.asarray(b) + 180.0, 360.0) - 180.0)
    return d


def _match(found_deg, expected_deg, tol):
    """Every expected angle has a found one within tol and the counts agree."""
    found, expected = np.sort(np.asarray(found_deg)), np.sort(np.asarray(expected_deg))
    assert len(found) == len(expected), (found, expected)
    for e in expected:
        assert _angle_gap(found, e).min() < tol, (e, found)


@pytest.mark.parametrize("cables", [False, True])
@pytest.mark.parametrize("u", [(0.1, -0.25), (1.45, 0.2), (0.6, 0.1)])
def test_zeeman_against_a_dense_scan(cables, u):
    name = "zeeman_cables" if cables else "zeeman"
    fw = cb.Framework.from_toml(EXAMPLES / f"{name}.toml").replace(x=u[0], y=u[1])
    res = cb.solve(fw)
    assert res.status == "ok", res.warnings
    crit = scan_critical_points(lambda t: zeeman_energy(t, u, cables))
    phys = res.physical
    _match(phys["wheel.angle_deg"], [np.degrees(t) for t, _ in crit], 1e-6)
    mins = [np.degrees(t) for t, kind in crit if kind == "min"]
    _match(res.stable["wheel.angle_deg"], mins, 1e-6)
    assert set(phys["kind"]) <= {"min", "max"}


def test_zeeman_cables_slack_band_is_reported():
    # u close to the wheel: band_u can go slack, so two taut sets are solved.
    fw = cb.Framework.from_toml(EXAMPLES / "zeeman_cables.toml").replace(x=1.45, y=0.2)
    res = cb.solve(fw)
    assert res.counts["taut_sets_solved"] == 2
    phys = res.physical
    slack = phys[~phys["band_u.taut"].astype(bool)]
    assert len(slack), "expected an equilibrium with band_u slack"
    assert (slack["band_u.length"] <= 0.25 + 1e-9).all()
    assert (slack["band_u.tension"] == 0).all()


def _cotm_rows(table):
    return np.stack([table["rod.angle_deg"], table["top.angle_deg"]], axis=1)


def _paper_rows(table):
    return np.stack([table["gamma1_deg"], table["gamma2_deg"]], axis=1)


def _same_poses(a, b, tol):
    assert len(a) == len(b), (a, b)
    for row in b:
        assert _angle_gap(a, row).max(axis=1).min() < tol, (row, a)


@pytest.mark.parametrize("case", ["case1", "case2", "case3"])
def test_cotm_framework_equals_the_built_in_model(case):
    p = cb.Params.case(case)
    fw = cb.Framework.from_toml(EXAMPLES / "cotm.toml").replace(L01=p.L01, L02=p.L02)
    res, ref = cb.solve(fw), cb.solve(p)
    assert res.status == "ok", res.warnings
    _same_poses(_cotm_rows(res.physical), _paper_rows(ref.physical), 1e-9)
    _same_poses(_cotm_rows(res.stable), _paper_rows(ref.stable), 1e-9)


def _same_or_truer(fw_rows, paper_rows, params):
    """Each pose of the built-in model has the framework's within 1e-9 deg; where the two differ
    by more (an ill-conditioned pose), the framework's is within 1e-9 deg of the 40-digit Newton
    answer (physics.mp_refine, the paper's equations) and the built-in's within 1e-7."""
    assert len(fw_rows) == len(paper_rows), (fw_rows, paper_rows)
    for row in paper_rows:
        gaps = _angle_gap(fw_rows, row).max(axis=1)
        if gaps.min() < 1e-9:
            continue
        truth = np.array(mp_refine(params, *row))
        assert _angle_gap(fw_rows[gaps.argmin()], truth).max() < 1e-9, (row, truth)
        assert _angle_gap(row, truth).max() < 1e-7, (row, truth)


def test_cotm_framework_random_geometries():
    # 20 geometries in `make stress` (COTM_STRESS=full), 3 in `make test`.
    rng = np.random.default_rng(2026)
    for _ in range(20 if os.environ.get("COTM_STRESS") == "full" else 3):
        values = {"L01": rng.uniform(5, 14), "L02": rng.uniform(5, 14), "k2": rng.uniform(1, 5),
                  "p5x": rng.uniform(-1, 1), "p6x": rng.uniform(3, 5)}  # fmt: skip
        params = cb.Params().replace(**values)
        fw = cb.Framework.from_toml(EXAMPLES / "cotm.toml").replace(**values)
        res, ref = cb.solve(fw), cb.solve(params)
        assert res.status == "ok", res.warnings
        _same_or_truer(_cotm_rows(res.physical), _paper_rows(ref.physical), params)
        _same_or_truer(_cotm_rows(res.stable), _paper_rows(ref.stable), params)


def test_double_pendulum_against_torus_search():
    res = cb.solve(cb.Framework.from_toml(EXAMPLES / "double_pendulum.toml"))
    assert res.status == "ok", res.warnings
    assert res.morse["applicable"] and res.morse["ok"]
    phys = res.physical
    th = np.radians(np.stack([phys["link1.angle_deg"], phys["link2.angle_deg"]], axis=1))
    for x in th:  # every reported equilibrium is critical for the independent energy
        assert gradient_norm(pendulum_energy, x) < 1e-6
    minima = np.degrees(np.array(grid_minima(pendulum_energy)))
    stable = np.stack([res.stable["link1.angle_deg"], res.stable["link2.angle_deg"]], axis=1)
    _same_poses(stable, minima, 1e-6)


def _write(tmp_path, text: str):
    path = tmp_path / "f.toml"
    path.write_text(text)
    return path


BASE = """
name = "t"
[parameters]
x = 1.0
[ground]
c = [0.0, 0.0]
u = ["x", 1.0]
[bodies.w]
o = [0.0, 0.0]
r = [1.0, 0.0]
[[pins]]
a = "w.o"
b = "ground.c"
[[springs]]
a = "w.r"
b = "ground.u"
k = 1.0
L0 = 0.5
"""


@pytest.mark.parametrize(
    "edit, words",
    [
        (('b = "ground.u"', 'b = "ground.nowhere"'), ["springs.spring1.b", "ground.nowhere"]),
        (("r = [1.0, 0.0]", "r = [1.0, 0.0, 2.0]"), ["bodies.w.r", "3 coordinates"]),
        (('u = ["x", 1.0]', 'u = ["z", 1.0]'), ["ground.u", "'z'", "not defined"]),
        (('u = ["x", 1.0]', 'u = ["x*(2", 1.0]'), ["ground.u", "not closed"]),
        (('u = ["x", 1.0]', 'u = ["x $ 2", 1.0]'), ["ground.u", "'$'"]),
        (("k = 1.0", "k = -1.0"), ["springs.spring1.k", "-1.0"]),
        (('name = "t"', 'name = "t"\ndim = 4'), ["dim", "4"]),
        (("L0 = 0.5\n", "L0 = 0.5\n[bodies.empty]\n"), ["bodies.empty", "at least one point"]),
    ],
)
def test_bad_framework_files_name_the_element(tmp_path, edit, words):
    text = BASE.replace(*edit)
    assert text != BASE
    with pytest.raises(ParameterError) as err:
        cb.Framework.from_toml(_write(tmp_path, text))
    message = str(err.value)
    assert "\n" not in message
    for word in words:
        assert word in message, message


LOAD = '[[loads]]\nname = "wA"\npoint = "w.r"\nforce = [0.0, -0.1]\n'


@pytest.mark.parametrize(
    "edit, line",
    [
        ((LOAD, LOAD.replace("force =", "forces =")),
         "loads[1] (wA): unknown key 'forces' (did you mean 'force'?)"),
        ((LOAD, LOAD.replace('name = "wA"\n', "").replace("point", "pont")),
         "loads[1]: unknown key 'pont' (did you mean 'point'?)"),
        (("L0 = 0.5", "LO = 0.5"), "springs[1]: unknown key 'LO' (did you mean 'L0'?)"),
        (("k = 1.0", 'name = "s"\nk = 1.0\nstiff = 2'),
         "springs[1] (s): unknown key 'stiff' (known: L0, a, b, k, name)"),
        (('b = "ground.c"', 'b = "ground.c"\nc = "w.r"'),
         "pins[1]: unknown key 'c' (known: a, b)"),
        (("[[springs]]", "[[sprngs]]"),
         "the framework file's top level: unknown key 'sprngs' (did you mean 'springs'?)"),
        (('name = "t"', 'name = "t"\ndimension = 2'),
         "the framework file's top level: unknown key 'dimension' (did you mean 'dim'?)"),
        (("[[springs]]", '[[bars]]\na = "w.r"\nb = "ground.u"\nlenght = 1.0\n[[springs]]'),
         "bars[1]: unknown key 'lenght' (did you mean 'length'?)"),
    ],
)  # fmt: skip
def test_an_unknown_key_is_named_with_its_table_and_the_nearest_known_key(tmp_path, edit, line):
    """Issue 46: `forces = [...]` in a load was answered "needs point and force"; a misspelt
    key of any table is named, with its element and the key it was probably meant to be."""
    text = (BASE + LOAD).replace(*edit)
    assert text != BASE + LOAD
    with pytest.raises(ParameterError) as err:
        cb.Framework.from_toml(_write(tmp_path, text))
    assert str(err.value) == line


def test_an_unknown_key_on_the_command_line_is_one_line_exit_2(tmp_path):
    from conftest import run_cli

    path = _write(tmp_path, BASE + LOAD.replace("force =", "forces ="))
    r = run_cli("solve", "--framework", str(path), "--out", str(tmp_path / "out"))
    assert r.returncode == 2 and not (tmp_path / "out").exists(), r.stderr
    assert r.stderr == (
        "cotm-bertini: error: loads[1] (wA): unknown key 'forces' (did you mean 'force'?)\n"
    )


def test_duplicate_names_are_refused(tmp_path):
    text = BASE + '[[springs]]\nname = "spring1"\na = "w.r"\nb = "ground.c"\nk = 1.0\nL0 = 0.1\n'
    with pytest.raises(ParameterError, match="spring1"):
        cb.Framework.from_toml(_write(tmp_path, text))


def test_a_framework_that_moves_freely_is_refused(tmp_path):
    # The spring's far end is pinned at the wheel's centre line: nothing resists the rotation
    # only if no element acts on the wheel; here the spring joins ground to ground's twin body.
    text = BASE.replace('a = "w.r"\nb = "ground.u"', 'a = "w.o"\nb = "ground.u"')
    fw = cb.Framework.from_toml(_write(tmp_path, text))
    with pytest.raises(ParameterError, match="moves freely|can move freely"):
        cb.solve(fw)


def test_replace_refuses_unknown_parameters():
    fw = cb.Framework.from_toml(EXAMPLES / "zeeman.toml")
    with pytest.raises(ParameterError, match="nope"):
        fw.replace(nope=1.0)


def test_fourbar_against_a_scan_of_both_assembly_branches():
    res = cb.solve(cb.Framework.from_toml(EXAMPLES / "fourbar.toml"))
    assert res.morse["applicable"] and res.morse["ok"]  # the loop's circles: chi 0
    phys = res.physical
    for branch in (1, -1):
        crit = scan_critical_points(lambda t, b=branch: fourbar_energy(t, b))
        on = [
            fourbar_branch(c, f) == branch
            for c, f in zip(phys["crank.angle_deg"], phys["coupler.angle_deg"], strict=True)
        ]
        found = phys[np.array(on, dtype=bool)]
        _match(found["crank.angle_deg"], [np.degrees(t) for t, _ in crit], 1e-6)
        mins = [np.degrees(t) for t, kind in crit if kind == "min"]
        _match(found[found["stable"].astype(bool)]["crank.angle_deg"], mins, 1e-6)


@pytest.mark.parametrize("route", ["complex", "real"])
@pytest.mark.parametrize("shift", [0.0, 4e-6])
def test_fourbar_equilibrium_at_the_lift_switch_is_one_row(shift, route):
    """The crank at 45 deg (the tie's maximum, lift slack) with the lift's anchor placed 0.5
    (+ shift) from the coupler's cable point, found independently: the lift is at (or within
    the borderline tolerance of) its free length there. It is one physical row (on the complex
    route both taut sets find it, and the other is kept, not physical, as a switch duplicate;
    the real route's search finds it once), and the physical count equals a scan's."""
    t = np.radians(45.0)
    _, p = fourbar_points(np.array([t]), 1)
    ex, ey = p[0, 0] + (0.5 + shift) * 0.6, p[1, 0] + (0.5 + shift) * 0.8
    fw = cb.Framework.from_toml(EXAMPLES / "fourbar.toml").replace(ex=ex, ey=ey)
    res = cb.solve(fw, route=route)
    phys = res.physical
    at = phys[_angle_gap(phys["crank.angle_deg"].to_numpy(), 45.0) < 1e-3]
    assert len(at) == 1 and at["kind"].iloc[0] == "degenerate", at
    table = res.table
    assert (table["reason"] == "switch_duplicate:lift").sum() == (route == "complex")
    crit = [
        kind
        for b in (1, -1)
        for _, kind in scan_critical_points(lambda x, b=b: fourbar_energy(x, b, ex, ey))
    ]
    assert len(phys) == len(crit) and int(phys["stable"].sum()) == crit.count("min")
