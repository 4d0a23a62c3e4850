"""The generic-set routes (backends/generic.py, issue 28): settings honoured or refused, the
monodromy route's evidence in run.json, a failed trace test reported as incomplete, a search
interrupted and resumed from its checkpoint, and the two routes agreeing through cb.solve.

The reference for "the same set" is Bertini's own total-degree solve (tests/test_monodromy.py's
`total_degree`, which calls ZeroDimSolver directly, not the package's route)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, run_cli, same_sets
from test_monodromy import ZFL, total_degree

import cotm_bertini as cb
from cotm_bertini.backends import generic, monodromy
from cotm_bertini.backends.homotopy import SECOND_START
from cotm_bertini.model.compiled import parametric_system


def test_generic_setting_is_honoured_or_refused():
    assert generic.route_of(cb.Settings()) == generic.DEFAULT_ROUTE
    assert generic.route_of(cb.Settings(generic="monodromy")) == "monodromy"
    assert generic.route_of(cb.Settings(scheduler="tcp://h:1")) == "total-degree"
    assert generic.route_of(cb.Settings(generic="both")) == "both"
    with pytest.raises(cb.ParameterError, match="generic = 'simplex'"):
        cb.Settings(generic="simplex")
    with pytest.raises(cb.ParameterError, match="monodromy route runs in one process"):
        cb.Settings(generic="monodromy", scheduler="tcp://h:1")
    with pytest.raises(cb.ParameterError, match="cli engine"):
        cb.Settings(generic="monodromy", engine="cli")
    # Not part of a result's key (every route gives the same set), absent from it when unset.
    assert "generic" not in cb.Settings(generic="both").result_key()
    assert "generic" not in cb.Settings().as_dict()


def test_both_routes_through_solve_agree_and_record_their_evidence():
    """case 2 solved with generic='both': the monodromy set and the total-degree set of the
    same seed have the same count, the solve is complete, and run.json's record names the
    monodromy route with a passing trace test."""
    res = cb.solve(cb.Params.case("case2"), settings=cb.Settings(generic="both", seed=3))
    assert res.status == "ok", res.warnings
    mono, td = res.record["details"]["homotopy"]["generic_route"]["generic_sets"]
    assert mono["route"] == "monodromy" and mono["complete"] and "route" not in td
    assert (mono["seed"], td["seed"]) == (3, 3)
    assert mono["evidence"] == ["trace test"] and mono["trace_residual"] < monodromy.TRACE_TOL
    ps = parametric_system(ZFL["case2"])
    gs = generic.monodromy_set(ps, 3)
    points, _, _ = total_degree(ps.instantiate([gs.start[n] for n in ps.parameters]))
    assert same_sets(gs.points, points)


def _failing_search(monkeypatch, tmp_path) -> list:
    """A trace test that cannot pass (tolerance 0, stagnation after one fresh edge), in an
    empty cache of its own; the list counts the searches run."""
    monkeypatch.setenv("COTM_CACHE", str(tmp_path))
    monkeypatch.setattr(generic, "_LOADED", {})
    real, searches = generic.monodromy_generic, []

    def failing(*args, **kw):
        searches.append(1)
        return real(*args, **{**kw, "trace_tol": 0.0, "max_stall": 1})

    monkeypatch.setattr(generic, "monodromy_generic", failing)
    return searches


def test_a_failed_trace_test_makes_the_solve_incomplete(monkeypatch, tmp_path):
    """generic='monodromy' and a failed trace test: the solve still answers, its status is
    incomplete with the reason; the set is cached as incomplete, so a second solve (a sweep's
    next point) says the same without searching again."""
    searches = _failing_search(monkeypatch, tmp_path)
    settings = cb.Settings(seed=5, generic="monodromy")
    for _ in range(2):
        res = cb.solve(cb.Params.case("case1"), settings=settings, cache=False)
        assert res.status == "incomplete"
        assert any("stagnation" in w and "trace test" in w for w in res.warnings), res.warnings
    assert len(searches) == 1
    monkeypatch.setattr(generic, "_LOADED", {})  # from the disk cache too
    again = cb.solve(cb.Params.case("case1"), settings=settings, cache=False)
    assert again.status == "incomplete" and len(searches) == 1


def test_the_default_route_falls_back_to_total_degree_after_a_failed_trace_test(
    monkeypatch, tmp_path
):
    """The default route (generic unset) after a failed trace test: the total-degree route's
    two sets, whose counts agree, so the solve is complete (the paper's 6 equilibria of case
    1, Table 2), and run.json says why the monodromy set was not used."""
    searches = _failing_search(monkeypatch, tmp_path)
    res = cb.solve(cb.Params.case("case1"), settings=cb.Settings(seed=5), cache=False)
    assert len(searches) == 1 and res.status == "ok", res.warnings
    first, second = res.record["details"]["homotopy"]["generic_route"]["generic_sets"]
    assert "stagnation" in first["after_monodromy"] and "after_monodromy" not in second
    assert (first["seed"], second["seed"]) == (5, 5 + SECOND_START)
    assert len(res.table) == 6


def test_an_interrupted_search_resumes_from_its_checkpoint(monkeypatch, tmp_path):
    """The search stopped by an interrupt after its first round of edges keeps what it found
    in the checkpoint; the next call resumes from it (the roots found are not found again) and
    ends with the set of an uninterrupted search; the checkpoint is removed once complete."""
    ps = parametric_system(ZFL["case2"])
    checkpoint = tmp_path / "monodromy.partial.json"
    real = monodromy._trace
    calls = []

    def interrupt(aug, g):
        calls.append(len(g.nodes[0]))
        raise KeyboardInterrupt

    monkeypatch.setattr(monodromy, "_trace", interrupt)
    with pytest.raises(KeyboardInterrupt):
        monodromy.monodromy_generic(ps, 2, checkpoint=checkpoint)
    assert checkpoint.is_file() and calls[0] > 1
    monkeypatch.setattr(monodromy, "_trace", real)
    resumed = monodromy.monodromy_generic(ps, 2, checkpoint=checkpoint)
    whole = monodromy.monodromy_generic(ps, 2)
    assert resumed.complete and resumed.resumed == calls[0]
    assert not checkpoint.exists()
    assert same_sets(resumed.points, whole.points)
    assert resumed.paths == whole.paths  # the same work, the first round not done twice
    assert np.isfinite(resumed.trace_residual)


def test_the_cost_statement_follows_the_route(monkeypatch, tmp_path):
    """By monodromy no time is promised (its path count is not known before the solve); by
    total degree two seeds are counted, by "both" one plus the monodromy check."""
    from cotm_bertini.model.framework import compiled

    # An empty cache of its own (nothing solved yet), and of derived systems in memory too: the
    # ones derived here must not outlive this cache for the tests after it.
    monkeypatch.setenv("COTM_CACHE", str(tmp_path))
    monkeypatch.setattr(compiled, "_LOADED", {})
    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman.toml")
    mono = cb.cost(fw, cb.Settings(generic="monodromy"), sample=False)
    assert np.isnan(mono.estimate) and not mono.over_an_hour
    assert "by monodromy" in mono.headline() and "estimated" not in mono.headline()
    total = cb.cost(fw, cb.Settings(generic="total-degree"), sample=False)
    both = cb.cost(fw, cb.Settings(generic="both"), sample=False)
    assert total.paths == 2 * both.paths > 0 and np.isfinite(total.estimate)
    assert both.headline().endswith("a monodromy set of the same seed to check it")


def test_params_takes_the_seed_and_route_of_the_first_solve(tmp_path):
    """`params --framework` states the work of the seed and route asked for; for the paper's
    mechanism (no cost statement) they are refused in one line, not ignored."""
    env = {"COTM_CACHE": str(tmp_path)}
    zeeman = str(ROOT / "examples" / "zeeman.toml")
    real = run_cli("params", "--framework", zeeman, "--seed", "3", env=env)
    assert real.returncode == 0 and "zeeman: the real route" in real.stdout, real.stderr
    mono = run_cli("params", "--framework", zeeman, "--seed", "3", "--generic", "monodromy",
                   env=env)  # fmt: skip
    assert mono.returncode == 0, mono.stderr
    assert "first solve of zeeman (seed 3)" in mono.stdout and "by monodromy" in mono.stdout
    total = run_cli("params", "--framework", zeeman, "--route", "complex", env=env)  # few paths
    assert "x 2 seeds" in total.stdout and "by monodromy" not in total.stdout
    assert "by total-degree (2 seeds x" in total.stdout
    refused = run_cli("params", "case3", "--seed", "3", env=env)
    assert refused.returncode == 2 and refused.stdout == ""
    assert "--seed: only with --framework" in refused.stderr
