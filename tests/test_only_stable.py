"""`only="stable"`: the stable equilibria alone, each proved a strict local minimum, none
missing (boxsearch.stability drops the boxes where V can have no local minimum, boxsearch.minima
proves the roots). Checked against the full search's stable rows, against minima found by an
independent statics (Newton from many starts, a positive definite Hessian: tests'
random_mechanisms and tensegrity_physics, no package code), and by sabotage."""

from __future__ import annotations

import math

import numpy as np
import pytest
import random_mechanisms as rm
import tensegrity_physics as tp
from conftest import ROOT

import cotm_bertini as cb
from cotm_bertini.boxsearch import boxes
from cotm_bertini.cli.main import main
from cotm_bertini.errors import ParameterError

SHIPPED = ["examples/chain3.toml", "examples/prism_slack.toml", "examples/xmodule.toml",
           "tests/fixtures/chain3_collapse.toml"]  # fmt: skip


def _pose(table) -> np.ndarray:
    """Each row's pose: planar angles as (cos, sin), node positions."""
    cols = []
    for name in table.columns:
        if name.endswith(".angle_deg"):
            rad = np.radians(table[name].to_numpy(float))
            cols += [np.cos(rad), np.sin(rad)]
        elif name.endswith((".x", ".y", ".z")) and "." in name:
            cols.append(table[name].to_numpy(float))
    return np.stack(cols, axis=1)


@pytest.mark.parametrize("name", SHIPPED)
def test_only_stable_gives_the_full_search_s_stable_rows_with_fewer_boxes(name):
    """The same stable rows as the full search (pose to 1e-8, each a min), each proved a strict
    local minimum, no Morse count, no more boxes."""
    fw = cb.Framework.from_toml(ROOT / name)
    full = cb.solve(fw, cache=False)
    only = cb.solve(fw, cache=False, only="stable")
    assert full.status == only.status == "ok", (full.warnings, only.warnings)
    a, b = _pose(full.stable), _pose(only.physical)
    assert len(a) == len(b) == len(only.stable) > 0
    for x in a:
        assert np.abs(b - x).max(axis=1).min() < 1e-8
    assert set(only.physical["kind"]) == {"min"}
    info = only.record["details"]["real_search"]["only"]
    assert info["proved_minima"] == len(b) and info["undecided"] == 0
    assert only.morse["applicable"] is False
    assert only.counts["boxes"] <= full.counts["boxes"]


@pytest.mark.parametrize(("seed", "links"), [(0, 2), (1, 3), (2, 3)])
def test_a_random_chain_s_minima_are_those_of_an_independent_statics(seed, links, tmp_path):
    """A random chain of springs, cables and loads: the rows are exactly the minima (index 0,
    not degenerate) that Newton finds on the statics written in the tests."""
    ch = rm.planar_chain(seed, links)
    path = tmp_path / "chain.toml"
    path.write_text(ch.toml(f"chain_{seed}"))
    res = cb.solve(cb.Framework.from_toml(path), cache=False, only="stable")
    assert res.status == "ok", res.warnings
    ref = [p for p in rm.chain_critical_points(ch) if p["index"] == 0 and not p["degenerate"]]
    rows = res.physical
    angles = np.radians(rows[[f"link{i + 1}.angle_deg" for i in range(links)]].to_numpy(float))
    assert len(rows) == len(ref) > 0
    for p in ref:
        gap = np.abs((angles - p["angles"] + math.pi) % (2 * math.pi) - math.pi).max(axis=1)
        (i,) = np.flatnonzero(gap < 1e-7)
        assert math.isclose(float(rows.iloc[i]["energy"]), p["energy"], rel_tol=1e-9)


@pytest.mark.parametrize("seed", [0, 1])
def test_hanging_nodes_minima_are_those_of_an_independent_statics(seed, tmp_path):
    """Two nodes hanging by bars with cables and loads: the rows are exactly the minima of the
    Lagrange statics of tensegrity_physics (Newton from 600 starts, index 0)."""
    hn = rm.hanging_nodes(seed, 2)
    path = tmp_path / "hanging.toml"
    path.write_text(hn.toml(f"hanging_{seed}"))
    res = cb.solve(cb.Framework.from_toml(path), cache=False, only="stable")
    assert res.status == "ok", res.warnings
    ref = [p for p in tp.critical_points(hn.spatial, starts=600, seed=seed) if p["index"] == 0]
    X = res.physical[[f"{n}.{c}" for n in hn.spatial.free for c in "xyz"]].to_numpy(float)
    assert len(X) == len(ref) > 0
    for p in ref:
        assert np.abs(X - p["X"]).max(axis=1).min() < 1e-7


def test_a_test_that_drops_a_box_with_a_minimum_is_caught(monkeypatch):
    """Sabotage: a non-convexity test that drops every box it is asked about (minima too). The
    search still says it decided every box, but the local descents, which share no code with it,
    reach minima it did not find: a contradiction, not a quiet answer."""
    monkeypatch.setattr(boxes, "no_minimum", lambda H: np.ones(len(H.lo), dtype=bool))
    res = cb.solve(cb.Framework.from_toml(ROOT / "examples" / "chain3.toml"), cache=False,
                   only="stable")  # fmt: skip
    assert res.status == "contradiction", res.warnings
    assert "local descents" in res.warnings[0]


def test_what_only_stable_cannot_answer_is_refused():
    """A setting is honoured or refused: the paper's mechanism (Bertini's complex roots), the
    complex route, a map's continuation grid, a certificate and barriers need every equilibrium."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "chain3.toml")
    with pytest.raises(ParameterError, match="only = 'stable'"):
        cb.solve(cb.Params.case("case3"), only="stable")
    with pytest.raises(ParameterError, match="only = 'stable'"):
        cb.solve(fw, route="complex", only="stable")
    with pytest.raises(ParameterError, match="only = 'anything'"):
        cb.Settings(only="anything")
    with pytest.raises(ParameterError, match="grid = 'continuation' with only = 'stable'"):
        cb.design_map(fw, "L0", (1.0, 2.0), "weight", (0.0, 0.2), points=3,
                      settings=cb.Settings(only="stable"), grid="continuation")  # fmt: skip
    res = cb.solve(fw, cache=False, only="stable")
    for call in (cb.certify, cb.barriers):
        with pytest.raises(ParameterError, match="only = 'stable'"):
            call(res)


def test_the_command_line_solves_the_stable_equilibria_alone(tmp_path, capsys):
    """`solve --framework FILE --only stable`: exit 0, the report says what was looked for."""
    code = main(["solve", "--framework", str(ROOT / "examples" / "chain3.toml"), "--only",
                 "stable", "--no-cache", "--no-plots", "--out", str(tmp_path)])  # fmt: skip
    out = capsys.readouterr().out
    assert code == 0
    assert "5 stable equilibria (5 proved strict local minima; only the stable ones" in out


def test_a_map_of_the_stable_states_is_proved_at_every_grid_point():
    """Zeeman's machine over (x, y), only="stable": every grid point searched for its minima
    (a 2-D sweep, each point proved), the stable counts those of the full map's grid, and the
    map's check (every change of the count crossed by a fold curve) passes."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman.toml")
    window = ("x", (-0.6, 0.8), "y", (-0.8, 0.2))
    full = cb.design_map(fw, *window, points=15, grid="search")
    only = cb.design_map(fw, *window, points=15, settings=cb.Settings(only="stable"))
    assert only.record["sweep_status"] == "ok" and only.record["status"] == "ok"
    assert (only.regions["stable"].to_numpy() == full.regions["stable"].to_numpy()).all()
    assert (only.regions["physical"] == only.regions["stable"]).all()
    assert len(set(only.regions["stable"])) == 2  # the cusp region's two minima, one outside


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(20))
@pytest.mark.parametrize("kind", ["chain2", "chain3", "collapse3", "hanging2"])
def test_random_mechanisms_give_the_full_search_s_stable_rows(kind, seed, tmp_path):
    """(make stress) Random chains (some with springs that can collapse) and hanging nodes:
    `only="stable"` gives the full search's stable rows, with the same status."""
    if kind == "hanging2":
        m = rm.hanging_nodes(seed, 2)
    else:
        m = rm.planar_chain(seed, 2 if kind == "chain2" else 3, collapse=kind == "collapse3")
    path = tmp_path / "f.toml"
    path.write_text(m.toml(f"{kind}_{seed}"))
    fw = cb.Framework.from_toml(path)
    full = cb.solve(fw, cache=False, timeout=120)
    only = cb.solve(fw, cache=False, only="stable", timeout=120)
    assert full.status == only.status == "ok", (full.warnings, only.warnings)
    a, b = _pose(full.stable), _pose(only.physical)
    assert len(a) == len(b)
    for x in a:
        assert np.abs(b - x).max(axis=1).min() < 1e-7
