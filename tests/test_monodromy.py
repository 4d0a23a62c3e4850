"""Monodromy generic sets (backends/monodromy.py, issue 28) against independent routes.

The reference generic sets come from Bertini's own total-degree / multihomogeneous solve
(ZeroDimSolver, called here directly, not through the package's generic_set) of the same
system at the same start parameters p0; the augmented fibre's reference is the same solve of
G(x; c0, e0) = F(x) + u (a . x) + e0 itself.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
from conftest import ROOT, same_sets

import cotm_bertini as cb
from cotm_bertini.backends import monodromy as mono
from cotm_bertini.backends.homotopy import START_CENTRE, GenericSet, track
from cotm_bertini.model.compiled import parametric_system

ZFL = {"case1": (True, True), "case2": (False, True), "case3": (False, False)}
SEED = 1


def total_degree(system, groups=None) -> tuple[np.ndarray, int, int]:
    """Bertini's own ab-initio solve: (finite nonsingular points in the system's variable
    order, finite endpoints, finite singular endpoints)."""
    import bertini
    from bertini import nag_algorithm as na

    from cotm_bertini.backends.render import render_system

    bertini.recording(False)
    bertini.random.set_random_seed(SEED)
    solver = na.ZeroDimSolver(bertini.parse.system(render_system(system, groups)))
    solver.solve(show_progress=False)
    names = [v for g in groups for v in g] if groups else list(system.variables)
    order = [names.index(v) for v in system.variables]
    points, singular = [], 0
    for meta, point in zip(solver.solution_metadata(), solver.all_solutions(), strict=True):
        code = str(meta.endgame_success_code).rsplit(".", 1)[-1]
        if not (meta.is_finite and code == "Success"):
            continue
        if meta.is_singular or meta.multiplicity > 1:
            singular += 1
        else:
            points.append([complex(point[k]) for k in order])
    return np.array(points, dtype=complex), len(points) + singular, singular


def framework(name: str):
    """The first taut set's system of examples/<name>.toml, its start centre and groups."""
    from cotm_bertini.model.framework.compiled import framework_system, variable_groups
    from cotm_bertini.model.framework.taut_sets import taut_sets
    from cotm_bertini.model.framework.units import normalized_slots

    fw = cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml")
    fs = next(f for f in (framework_system(fw, t) for t in taut_sets(fw)) if not f.free)
    centre = normalized_slots(fw.at_defaults())
    return fs.ps, {n: centre[n] for n in fs.ps.parameters}, variable_groups(fs)


@cache
def monodromy(name: str) -> mono.MonodromySet:
    """The monodromy generic set of a paper case or an example (once a session)."""
    if name in ZFL:
        return mono.monodromy_generic(parametric_system(ZFL[name]), SEED)
    ps, centre, _ = framework(name)
    return mono.monodromy_generic(ps, SEED, centre)


def assert_same_as_total_degree(name: str) -> None:
    m = monodromy(name)
    if name in ZFL:
        ps, groups = parametric_system(ZFL[name]), None
    else:
        ps, _, groups = framework(name)
    system = ps.instantiate([m.start[n] for n in ps.parameters])
    points, finite, singular = total_degree(system, groups)
    assert m.complete, m.reason
    assert m.trace_residual < mono.TRACE_TOL
    assert m.lost_endpoints == 0
    # Every finite nonsingular solution, nothing else, to 1e-8; and they solve F(x; p0).
    assert len(m.points) > 0 and same_sets(m.points, points), (len(m.points), len(points))
    assert np.abs(system.evaluate(m.points)).max() < 1e-9
    assert (m.finite_endpoints, m.singular_endpoints) == (finite, singular)
    # The augmented fibre is at least as large as F's finite count (each is a path's end).
    assert m.augmented >= finite


@pytest.mark.parametrize("case", ["case1", "case2"])
def test_monodromy_equals_total_degree_on_the_paper_cases(case):
    assert_same_as_total_degree(case)


@pytest.mark.slow
def test_monodromy_equals_total_degree_on_case3():
    assert_same_as_total_degree("case3")


def test_monodromy_equals_multihomogeneous_on_zeeman():
    assert_same_as_total_degree("zeeman")


@pytest.mark.slow
def test_monodromy_equals_multihomogeneous_on_the_double_pendulum():
    assert_same_as_total_degree("double_pendulum")


OUT_OF_REACH = {"chain3", "prism_slack", "prism4", "tower"}


def _example_sets() -> list[tuple[str, tuple[str, ...]]]:
    """(example, taut set) of every shipped example's taut sets with isolated equilibria, but
    those whose reference, Bertini's own solve, is out of reach: chain3's (86,528 paths a set:
    docs/benchmarks.md) and the spatial ones of issue 29 (46,656 to 6e12 paths a set:
    docs/frameworks.md), which tests/test_spatial_examples.py checks against their own route."""
    from cotm_bertini.model.framework.compiled import framework_system
    from cotm_bertini.model.framework.taut_sets import taut_sets

    out = []
    for path in sorted((ROOT / "examples").glob("*.toml")):
        if path.stem in OUT_OF_REACH:
            continue
        fw = cb.Framework.from_toml(path)
        out += [(path.stem, t) for t in taut_sets(fw) if not framework_system(fw, t).free]
    return out


@pytest.mark.slow
@pytest.mark.parametrize(
    "name, taut",
    [pytest.param(n, t, id=f"{n}-{'+'.join(t) or 'none-taut'}") for n, t in _example_sets()],
)
def test_every_taut_set_of_every_example_by_monodromy_equals_bertinis_own_solve(name, taut):
    """The default route against Bertini's own multihomogeneous solve (ZeroDimSolver called
    here, not the package's total-degree route): the same finite nonsingular set to 1e-8."""
    from cotm_bertini.model.framework.compiled import framework_system, variable_groups
    from cotm_bertini.model.framework.units import normalized_slots

    fw = cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml")
    fs = framework_system(fw, taut)
    centre = normalized_slots(fw.at_defaults())
    m = mono.monodromy_generic(fs.ps, SEED, {n: centre[n] for n in fs.ps.parameters})
    assert m.complete and m.trace_residual < mono.TRACE_TOL, m.reason
    system = fs.ps.instantiate([m.start[n] for n in fs.ps.parameters])
    points, finite, singular = total_degree(system, variable_groups(fs))
    assert same_sets(m.points, points), (len(m.points), len(points))
    assert (m.finite_endpoints, m.singular_endpoints) == (finite, singular)


def test_augmented_fibre_is_complete_and_a_dropped_root_fails_the_trace_test():
    """The monodromy's augmented fibre is the whole fibre of G(x; c0, e0) (Bertini's
    total-degree solve of G itself); its trace is affine; without any one root it is not."""
    ps = parametric_system(ZFL["case2"])
    m = monodromy("case2")
    aug = mono.augmented_family(ps, SEED, START_CENTRE)
    full, finite, singular = total_degree(aug.system(aug.origin))
    assert singular == 0 and finite == len(full) == m.augmented
    assert same_sets(m.augmented_points, full)
    assert mono.trace_test(aug, full) < mono.TRACE_TOL
    norms = np.abs(full).max(axis=1)
    for drop in {int(np.argmin(norms)), int(np.argmax(norms)), len(full) // 2}:
        residual = mono.trace_test(aug, np.delete(full, drop, axis=0))
        assert residual > 1e4 * mono.TRACE_TOL, (drop, residual)


def test_stagnation_or_spent_loops_without_a_passing_trace_test_is_incomplete():
    """A trace test that cannot pass (tolerance 0): the roots stop coming, and that is
    reported as stagnation, incomplete, never as complete; so is a spent loop budget."""
    ps = parametric_system(ZFL["case1"])
    stalled = mono.monodromy_generic(ps, SEED, trace_tol=0.0, max_stall=1)
    assert not stalled.complete
    assert stalled.reason.startswith("stagnation: 1 fresh edges in a row found no new root")
    assert stalled.augmented == monodromy("case1").augmented  # all found, none certified
    assert 0 < stalled.trace_residual < mono.TRACE_TOL
    with pytest.raises(cb.SolverError, match="stagnation"):
        stalled.generic_set("incomplete")  # never used as a generic set
    spent = mono.monodromy_generic(ps, SEED, trace_tol=0.0, max_edges=3)
    assert not spent.complete and spent.edges == 3
    assert spent.reason.startswith("the edge budget (3 edges) is spent")


def test_a_root_one_detour_of_the_final_homotopy_missed_makes_the_set_incomplete(monkeypatch):
    """The final homotopy runs along two detours; a path that went to infinity on the check
    (one finite root turned into a path at infinity, as a jump onto another path's way there
    would) leaves the two sets unequal: incomplete, said why, while both runs agreeing (the
    same call untouched) is complete."""
    ps = parametric_system(ZFL["case1"])
    real, calls = mono.track_segment, []

    def dropping(aug, points, start, target, detour=None, singular_ok=False, twist=0j):
        out = real(aug, points, start, target, detour, singular_ok, twist)
        if singular_ok:
            calls.append(detour)
            if len(calls) == 2:  # the check: its first finite root marked as gone to infinity
                ok, finite = out.ok.copy(), out.finite.copy()
                k = int(np.flatnonzero(ok)[0])
                ok[k] = finite[k] = False
                out = mono.Tracked(out.points, ok, out.codes, finite, out.singular,
                                   out.retracked_adaptive, out.cpu_seconds)  # fmt: skip
        return out

    monkeypatch.setattr(mono, "track_segment", dropping)
    m = mono.monodromy_generic(ps, SEED)
    assert len(calls) == 2 and calls[0] != calls[1]  # two detours, not the same one twice
    assert not m.complete and "ended at different roots" in m.reason, m.reason
    assert len(m.points) == len(monodromy("case1").points)  # the first run's roots, all kept
    assert monodromy("case1").complete  # untouched, the two runs agree


def test_monodromy_generic_set_tracks_to_a_target_as_the_total_degree_one():
    """As a GenericSet (same key fields, start p0) it reaches a real target: the same finite
    endpoints as Bertini's total-degree set tracked there."""
    ps = parametric_system(ZFL["case2"])
    m = monodromy("case2")
    gs = m.generic_set("monodromy-test")
    assert isinstance(gs, GenericSet) and gs.start == m.start
    assert gs.paths == m.augmented and gs.route["complete"]
    system = ps.instantiate([m.start[n] for n in ps.parameters])
    points, finite, singular = total_degree(system)
    reference = GenericSet("td-test", SEED, m.start, points, 0, finite, singular, 0.0, "")
    target = cb.Params.case("case2").normalized()
    ours, rep = track(ps, gs, target)
    theirs, rep2 = track(ps, reference, target)
    assert rep.lost == rep2.lost == 0 and rep.finite == rep2.finite == len(points)
    assert same_sets(ours.points, theirs.points, 1e-7)


def test_roots_that_stop_coming_for_a_set_time_are_stagnation(monkeypatch):
    """Edges that each still find a root now and then never stall by count: the roots not
    growing by STALL_GAIN within STALL_SECONDS (here 0 s) is stagnation too, incomplete, with
    the count it has."""
    monkeypatch.setattr(mono, "STALL_SECONDS", 0.0)
    stalled = mono.monodromy_generic(parametric_system(ZFL["case1"]), SEED, trace_tol=0.0)
    assert not stalled.complete
    assert (
        stalled.reason.startswith("stagnation: ") and "roots gained in the last" in stalled.reason
    )
    with pytest.raises(cb.SolverError, match="stagnation"):
        stalled.generic_set("incomplete")
