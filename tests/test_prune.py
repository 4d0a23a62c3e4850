"""Taut sets no pose can hold (model/framework/prune.py, issue 29 item 1): pruned, recorded with
their proof, and nothing physical lost. The references are a closed form (a node between two
cables in series) and random poses of the prism drawn here with numpy, not the package's code."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from conftest import ROOT

import cotm_bertini as cb
from cotm_bertini.model.framework import prune as prune_module
from cotm_bertini.model.framework.taut_sets import pruned_taut_sets, taut_sets

# A planar node N held by a spring of zero free length to g3 and by two cables in series
# between g1 and g2, 3 apart: both slack would need |g1 - g2| <= 1 + 1.2 = 2.2.
SERIES = """
name = "series"
dim = 2
nodes = ["N"]

[ground]
g1 = [0.0, 0.0]
g2 = [3.0, 0.0]
g3 = [1.5, 1.0]

[[springs]]
name = "s"
a = "N"
b = "ground.g3"
k = 1.0
L0 = 0.0

[[cables]]
name = "c1"
a = "ground.g1"
b = "N"
k = 2.0
L0 = 1.0

[[cables]]
name = "c2"
a = "N"
b = "ground.g2"
k = 3.0
L0 = 1.2
"""


def _series(tmp_path) -> cb.Framework:
    path = tmp_path / "series.toml"
    path.write_text(SERIES)
    return cb.Framework.from_toml(path)


def test_two_slack_cables_in_series_too_short_to_span_are_pruned(tmp_path):
    """Only the set with both cables slack is pruned: g1 and g2 are 3 apart (the ground) and
    at most 2.2 (the two free lengths) if both are slack."""
    fw = _series(tmp_path)
    (why,) = pruned_taut_sets(fw).values()
    assert list(pruned_taut_sets(fw)) == [()]
    # Any pair of the chain g1 - N - g2 proves it, each by the same margin 3 - 2.2.
    pairs = [{"ground.g1", "ground.g2"}, {"N", "ground.g1"}, {"N", "ground.g2"}]
    assert {why.a, why.b} in pairs and why.lower - why.upper == pytest.approx(0.8)
    assert set(taut_sets(fw)) == {("c1", "c2"), ("c1",), ("c2",)}


def test_a_pruned_set_is_recorded_and_loses_nothing_physical(tmp_path, monkeypatch):
    """The solve lists the pruned set with its proof and does not solve it; solved anyway (the
    pruning off), that set's only equilibrium is N = g3 (the spring alone), where c1 is 1.80
    long, beyond its free length 1: not consistent, so the physical rows are the same."""
    fw = _series(tmp_path)  # (a free node: the real route's by default; the pruning is the
    res = cb.solve(fw, cache=False, route="complex")  # complex route's)
    record = res.record["details"]["taut_sets"]["none"]
    assert record["pruned"] == "bound smoothing" and "no pose holds it" in record["note"]
    assert res.record["counts"]["taut_sets_pruned"] == 1
    monkeypatch.setattr(prune_module, "prune", lambda fw, taut: None)
    full = cb.solve(fw, cache=False, route="complex")
    assert "tracked" in full.record["details"]["taut_sets"]["none"]
    assert len(full.table) > len(res.table)  # the pruned set's rows, none physical
    cols = ["N.x", "N.y"]
    assert np.allclose(res.physical[cols].to_numpy(float), full.physical[cols].to_numpy(float))
    assert np.hypot(1.5, 1.0) > 1.0  # N = g3 stretches c1: the closed form above


def _prism_cables() -> list[tuple[str, str, str]]:
    """(name, a, b) of the prism's cables, read from the file with tomllib."""
    data = tomllib.loads((ROOT / "examples" / "prism.toml").read_text())
    return [(c["name"], c["a"], c["b"]) for c in data["cables"]]


def test_no_random_pose_of_the_prism_holds_a_pruned_set():
    """The prism with free lengths 0.5 (top) and 0.6 (diagonal): 200,000 random poses (each top
    node on its strut's sphere) hold none of the pruned sets, and do hold some of the others
    (so the check can fail)."""
    fw = cb.Framework.from_toml(ROOT / "examples" / "prism.toml").replace(L0t=0.5, L0d=0.6)
    pruned = pruned_taut_sets(fw)
    assert 0 < len(pruned) < 64
    r, h = 1.0, 1.2
    corners = [[r, 0, 0], [-r / 2, r * np.sqrt(3) / 2, 0], [-r / 2, -r * np.sqrt(3) / 2, 0]]
    base = {f"ground.{k}": np.array(v) for k, v in zip("abc", corners, strict=True)}
    rng = np.random.default_rng(29)
    pos = dict(base)
    for node, corner in zip("ABC", "abc", strict=True):
        u = rng.normal(size=(200_000, 3))
        pos[node] = base[f"ground.{corner}"] + h * u / np.linalg.norm(u, axis=1)[:, None]
    free = {"top": 0.5, "diag": 0.6}
    lengths = {n: np.linalg.norm(pos[a] - pos[b], axis=-1) for n, a, b in _prism_cables()}
    held = set()
    for taut in [*pruned, *taut_sets(fw)]:
        ok = np.ones(200_000, dtype=bool)
        for name, d in lengths.items():
            L0 = free[name.split("_")[0]]
            ok &= d >= L0 if name in taut else d <= L0
        if ok.any():
            held.add(taut)
    assert not held & set(pruned)
    assert held  # some unpruned sets are held by a sampled pose


def test_the_cost_statement_counts_the_pruned_sets_apart(tmp_path, monkeypatch):
    """cb.cost: the three sets to solve, and the pruned one named apart (not solved)."""
    from cotm_bertini.model.framework import compiled

    monkeypatch.setenv("COTM_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(compiled, "_LOADED", {})
    c = cb.cost(_series(tmp_path), cb.Settings(route="complex"), sample=False)
    assert len(c.sets) == 3 and c.pruned == 1
    assert "3 taut sets (1 more pruned: no pose holds them)" in c.headline()


def test_a_set_too_large_to_lay_out_is_not_sampled(tmp_path, monkeypatch):
    """cb.cost samples the rate on the largest set of at most SAMPLE_MAX_PATHS paths (Bertini
    lays out every start point first: prism_slack's smallest set spent 56 s there); with every
    set above the cap nothing is sampled, and the statement says why."""
    from cotm_bertini import Settings
    from cotm_bertini.api import costs
    from cotm_bertini.model.framework import compiled

    monkeypatch.setenv("COTM_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(compiled, "_LOADED", {})
    seen = []
    monkeypatch.setattr(costs, "sample_rate", lambda ps, *a: seen.append(ps) or (0.5, 3))
    settings = Settings(generic="total-degree")
    fw = _series(tmp_path)
    sizes = sorted(s.paths for s in costs.cost(fw, settings, sample=False).sets)
    monkeypatch.setattr(costs, "SAMPLE_MAX_PATHS", sizes[0])  # only the smallest set fits
    c = costs.cost(fw, settings, sample=True)
    assert c.measured and len(seen) == 1
    assert len(seen[0].variables) == min(s.unknowns for s in c.sets)
    monkeypatch.setattr(costs, "SAMPLE_MAX_PATHS", sizes[0] - 1)  # none fits
    c = costs.cost(fw, settings, sample=True)
    assert not c.measured and len(seen) == 1
    assert f"every taut set has more than {sizes[0] - 1:,} paths" in c.rate_source
