"""The parallel curve's certified cover (issue 17, goals 3 and 4): the cover holds the curve
(checked against the double-precision sampler of analysis.design.free_lengths, another code path),
the completeness search along it agrees with the two-dimensional branch and bound over the torus,
and both proofs fail when what they check is wrong: an equilibrium dropped from the table (one with
a spring of 6e-3 L3, in the narrow region the search must resolve; a relaxed one), a row given
twice, samples of the curve removed."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import cotm_bertini as cb
from cotm_bertini.analysis.certify.curve import certify_samples
from cotm_bertini.analysis.certify.mechanism import certify_table
from cotm_bertini.analysis.certify.search import COVER_CELLS, GEOMETRY, _cover
from cotm_bertini.analysis.design.free_lengths import parallel_cross, parallel_roots
from cotm_bertini.catastrophe.paper_folds import _grid, parallel_samples
from cotm_bertini.point import solve_point

sys.path.insert(0, str(Path(__file__).resolve().parent / "stress"))
from test_stress import random_params  # noqa: E402

CASE3 = cb.Params.case("case3")


@pytest.mark.parametrize("params", [CASE3, random_params(3), random_params(5)])
def test_every_point_of_the_curve_is_in_a_leaf_where_it_is_a_graph(params):
    """Points of the curve from the sign-change sampler lie in leaves of the cover, and there
    the curve's slope in the leaf's other angle (finite differences of a1 x a2) has the sign
    that the leaf's ball enclosure proves."""
    cover = _cover(tuple(getattr(params, n) for n in GEOMETRY))
    assert cover.leaves and not cover.undecided
    lo = np.array([[q[0], q[2]] for q in cover.leaves])
    hi = np.array([[q[1], q[3]] for q in cover.leaves])
    axes = np.array([q[4] for q in cover.leaves])
    signs = np.array([1.0 if q[5] > 0 else -1.0 for q in cover.leaves])
    fixed, roots = parallel_roots(params, np.linspace(-np.pi, np.pi, 97, endpoint=False))
    points = np.column_stack([fixed, roots])
    assert len(points) > 100
    h = 1e-7
    for g in points:
        inside = np.flatnonzero(((lo <= g + 1e-12) & (g - 1e-12 <= hi)).all(axis=1))
        assert len(inside), g
        for n in inside:
            step = np.eye(2)[1 - axes[n]] * h
            slope = parallel_cross(params, *(g + step)) - parallel_cross(params, *(g - step))
            assert np.sign(slope) == signs[n], (g, cover.leaves[n][:5])
    assert COVER_CELLS >= 2**20  # the smallest box is 6e-6 rad


@pytest.mark.parametrize("params", [cb.Params.case("case2"), random_params(4)])
def test_the_search_along_the_curve_agrees_with_the_torus_branch_and_bound(params):
    table = solve_point(params).table
    curve = certify_table(params, table)
    torus = certify_table(params, table, method="torus")
    assert curve.status == torus.status == "proved", (curve.statement, torus.statement)
    assert curve.proved_equilibria == torus.proved_equilibria
    assert curve.kinds == torus.kinds
    assert curve.record()["method"] != torus.record()["method"]


def _drop(table, row: int):
    return table.drop(index=table.index[row]).reset_index(drop=True)


def test_dropping_the_short_spring_saddle_of_case3_is_a_contradiction():
    """Case 3's saddle with d2 = 0.059 m (6.6e-3 L3) lies where spring 2 is short, between its
    two zero-length configurations: the search resolves that region and finds it missing."""
    table = solve_point(CASE3).table
    phys = np.flatnonzero(table["physical"].to_numpy())
    row = phys[np.argmin(table["d2"].to_numpy()[phys])]
    assert 0.05 < table["d2"].iloc[row] < 0.07
    cert = certify_table(CASE3, _drop(table, row))
    assert cert.status == "contradiction"
    assert any("not in the table" in text for text in cert.contradictions)


def test_dropping_a_relaxed_equilibrium_is_a_contradiction():
    """A relaxed minimum (V = 0, both springs at their free lengths, off the parallel curve) is
    found by the relaxed search."""
    table = solve_point(CASE3).table
    relaxed = np.flatnonzero(table["physical"].to_numpy() & (np.abs(table["energy"]) < 1e-9))
    assert len(relaxed) == 4
    cert = certify_table(CASE3, _drop(table, relaxed[0]))
    assert cert.status == "contradiction"
    assert any("not in the table" in text for text in cert.contradictions)


def test_a_row_given_twice_is_a_contradiction():
    table = solve_point(cb.Params.case("case2")).table
    row = np.flatnonzero(table["physical"].to_numpy())[0]
    twice = table.iloc[[row]].assign(solution_id=int(table["solution_id"].max()) + 1)
    doubled = pd.concat([table, twice], ignore_index=True)
    cert = certify_table(cb.Params.case("case2"), doubled)
    assert cert.status == "contradiction"
    assert any("overlapping boxes" in text for text in cert.contradictions)


def test_the_map_certificate_puts_back_samples_removed_from_the_curve():
    """Remove every sample with gamma1 in a 20 deg band (whole arcs and closed pieces of the
    curve among them): the certificate finds the crossings of its leaves' edges missing and adds
    them, so every leaf edge crossing is a sample again."""
    points = 300
    grid = _grid(points)
    samples = parallel_samples(CASE3, points)
    record, full = certify_samples(CASE3, samples, grid)
    assert record["status"] == "proved" and record["samples_added"] == 0
    band = (math.radians(100), math.radians(120))
    cut = []
    for axis, (fixed, roots) in enumerate(samples):
        g1 = fixed if axis == 0 else roots
        keep = (g1 < band[0]) | (g1 > band[1])
        cut.append((fixed[keep], roots[keep]))
    record, repaired = certify_samples(CASE3, cut, grid)
    assert record["status"] == "proved" and record["samples_added"] > 10
    again, _ = certify_samples(CASE3, repaired, grid)
    assert again["samples_added"] == 0
