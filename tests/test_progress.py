"""Long work says what it is doing, how far it is and how long is left, measured as it goes
(issue 27, items 3, 4 and 9): the one reporter (cotm_bertini.progress), the generic solve's
measured rate, derivations, certificates, and what a framework will cost before it costs it.

Path counts are checked against the multihomogeneous Bezout number computed here, as a
coefficient of a polynomial product (sympy), not by the package's dynamic programming; rates
against the elapsed times the lines themselves print.
"""

from __future__ import annotations

import re
import time
import tomllib

import numpy as np
import pytest
import sympy
from conftest import ROOT, run_cli

import cotm_bertini as cb
from cotm_bertini import progress

ZEEMAN = ROOT / "examples" / "zeeman.toml"
LINE = re.compile(
    r"^generic set \(seed (\d+)\): (\d+)/(\d+) paths(?:, [^;]*)?; ([\d.e+-]+) s a path, "
    r"([\d.e+-]+) s so far, about ([\d.e+-]+) s left$"
)


def bezout(degrees, sizes) -> int:
    """The coefficient of prod z_g^|g| in prod_i (sum_g d_ig z_g)."""
    z = sympy.symbols(f"z0:{len(sizes)}")
    product = sympy.Mul(*[sum(int(d) * zg for d, zg in zip(row, z, strict=True))
                          for row in degrees])  # fmt: skip
    monomial = sympy.Mul(*[zg**s for zg, s in zip(z, sizes, strict=True)])
    return int(sympy.Poly(sympy.expand(product), *z).coeff_monomial(monomial))


def zeeman_paths() -> int:
    """Paths of each of Zeeman's generic sets: the Bezout number of its system's degrees in
    its variable groups, read off the exponents (max total degree per group, equation by
    equation)."""
    from cotm_bertini.model.framework.compiled import framework_system, variable_groups

    fs = framework_system(cb.Framework.from_toml(ZEEMAN), ())
    groups = variable_groups(fs)
    system = fs.ps.instantiate([0.3 + 0.7j] * len(fs.ps.parameters))
    col = {v: k for k, v in enumerate(system.variables)}
    degrees = [[int(max(e[:, [col[v] for v in g]].sum(axis=1))) for g in groups]
               for e in system.exponents]  # fmt: skip
    return bezout(np.array(degrees), [len(g) for g in groups])


def test_first_solve_reports_measured_rate_and_the_cost_first(tmp_path):
    """Off a terminal, Zeeman's first solve (empty cache) says first the total work (2 seeds x
    the Bezout number of paths), then each generic set's progress: lines whose rate is the
    elapsed time over the paths done, whose time left is that rate times the paths left, and a
    last line at the total; the second set's announcement calls its estimate a first guess,
    taken from the first set's measured rate. Afterwards `params` says both sets are cached."""
    env = {"COTM_CACHE": str(tmp_path / "cache"), progress.ENV_SECONDS: "0",
           progress.ENV_DELAY: "0"}  # fmt: skip
    res = run_cli("solve", "--framework", str(ZEEMAN), "--no-plots", "--quiet", "--generic",
                  "total-degree", "--out", str(tmp_path / "runs"), env=env)  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert "\r" not in res.stderr  # lines, no bar
    paths = zeeman_paths()
    lines = res.stderr.splitlines()
    # The work is stated before any path is tracked (after the derivation's own lines).
    head = next(k for k, ln in enumerate(lines) if ln.startswith("cotm-bertini: zeeman: "))
    assert not [ln for ln in lines[:head] if not ln.startswith("deriving the equations")]
    assert re.search(rf"zeeman: 1 taut set, {paths} paths per generic set x 2 seeds = "
                     rf"{2 * paths} paths; {2 * paths} still to solve, an estimated .* \(a "
                     r"first guess: a fixed prior\)", lines[head])  # fmt: skip
    found = [m for m in map(LINE.match, lines) if m]
    assert len(found) >= 4 and {m[1] for m in found} == {"1", "7920"}
    for m in found:
        done, total, rate, so_far, left = int(m[2]), int(m[3]), *map(float, m.groups()[3:])
        assert total == paths and 0 < done < total
        assert rate == pytest.approx(so_far / done, rel=0.15, abs=0.02)  # printed to 2 digits
        assert left == pytest.approx(rate * (total - done), rel=0.15, abs=0.05)
    for seed in ("1", "7920"):
        assert f"generic set (seed {seed}): {paths}/{paths} paths" in "\n".join(lines)
    # Announced when its first guess (the first set's measured rate) is over 2 s.
    for line in [ln for ln in lines if "solving the generic solution set" in ln]:
        assert "first guess" in line and ("seed 1 " in line or "seed 1's paths" in line)
    again = run_cli("params", "--framework", str(ZEEMAN), "--generic", "total-degree", env=env)
    assert again.returncode == 0, again.stderr
    assert "(seeds 1, 7920 cached)" in again.stdout
    assert "every generic set is in the cache already" in again.stdout


def test_params_framework_states_paths_seeds_and_a_measured_estimate(tmp_path):
    """`params --framework` (empty cache): still a TOML parameter file, followed by comments
    with each taut set's unknowns and paths (the Bezout number, counted here), the two seeds,
    and an estimate from paths measured now, said to be an estimate."""
    env = {"COTM_CACHE": str(tmp_path / "cache")}
    res = run_cli("params", "--framework", str(ZEEMAN), "--generic", "total-degree", env=env)
    assert res.returncode == 0, res.stderr
    assert tomllib.loads(res.stdout) == {"x": 0.0, "y": 0.0}
    paths = zeeman_paths()
    assert re.search(rf"taut set none: 6 unknowns in \d+ groups, {paths} paths per generic set",
                     res.stdout)  # fmt: skip
    m = re.search(
        r"= (\d+) paths; (\d+) still to solve, an estimated ([\d.]+) s at ([\d.]+) s "
        r"a path \(measured on the first (\d+) paths of taut set none\)",
        res.stdout,
    )
    assert m, res.stdout
    assert int(m[1]) == int(m[2]) == 2 * paths and 0 < int(m[5]) <= paths
    assert float(m[3]) == pytest.approx(2 * paths * float(m[4]), rel=0.12)
    assert "an estimate" in res.stdout


def test_cost_beyond_an_hour_says_so_and_what_to_do(tmp_path, monkeypatch):
    """cost() on Zeeman, then the same work at a rate 200 times slower (as a large file would
    have): beyond an hour, the statement says so plainly and names the ways out."""
    from dataclasses import replace

    from cotm_bertini.api.costs import cost

    monkeypatch.setenv("COTM_CACHE", str(tmp_path))
    c = cost(cb.Framework.from_toml(ZEEMAN), cb.Settings(generic="total-degree"), sample=False)
    assert c.paths == c.paths_to_solve == 2 * zeeman_paths() and not c.measured
    assert "first guess" in c.headline() and not c.advice()
    slow = replace(c, seconds_per_path=3600.0 / c.paths_to_solve * 1.5)
    assert slow.over_an_hour and "beyond an hour" in slow.advice()
    for way in ("free length", "--scheduler", "cached"):
        assert way in slow.advice()
    assert slow.advice() in "\n".join(slow.lines())


def test_reporter_lines_rate_eta_and_silence(capsys, monkeypatch):
    """The one reporter off a terminal: a line per update when the interval is 0, with the
    rate measured on the units done and the time left at it; a last line at the total;
    nothing when silenced, nothing for a stage shorter than its delay."""
    monkeypatch.setenv(progress.ENV_SECONDS, "0")
    with progress.Progress("stage", 4, "things", delay=0.0) as rep:
        for _ in range(4):
            time.sleep(0.05)
            rep.update(1, note="ok")
    lines = capsys.readouterr().err.splitlines()
    assert lines[-1] == "stage: 4/4 things, ok" and len(lines) == 4
    for k, line in enumerate(lines[:-1], start=1):
        m = re.match(rf"stage: {k}/4 things, ok; ([\d.]+) s a thing, ([\d.]+) s so far, "
                     r"about ([\d.]+) s left", line)  # fmt: skip
        assert m, line
        assert 0.04 <= float(m[1]) <= 0.5 and float(m[3]) == pytest.approx(
            float(m[1]) * (4 - k), rel=0.1, abs=0.01)  # fmt: skip
    with progress.silenced():
        with progress.Progress("hidden", 2, "things", delay=0.0) as rep:
            rep.update(2)
        progress.say("hidden too")
    with progress.Progress("short", 2, "things", delay=60.0) as rep:
        rep.update(2)
    assert capsys.readouterr().err == ""


def test_derivation_says_which_taut_set_and_how_long(tmp_path, monkeypatch, capsys):
    """A derivation longer than the delay (here 0) says "taut set k/n" and its elapsed time
    every few seconds, then how long it took; derived again from an empty cache."""
    from cotm_bertini.api.costs import cost
    from cotm_bertini.model.framework import compiled

    monkeypatch.setenv("COTM_CACHE", str(tmp_path))
    monkeypatch.setenv(progress.ENV_DELAY, "0")
    monkeypatch.setenv(progress.ENV_SECONDS, "0")
    monkeypatch.setattr(compiled, "_LOADED", {})
    # A spatial framework: derived by sympy (planar bodies pinned to the ground are derived
    # in milliseconds without it, and say nothing).
    fw = cb.Framework.from_toml(ROOT / "tests" / "fixtures" / "floppy_node.toml")
    c = cost(fw, cb.Settings(route="complex"), sample=False)
    err = capsys.readouterr().err.splitlines()
    assert [s.taut for s in c.sets] == [("ca", "cb"), ("ca",), ("cb",), ()]
    for k, s in enumerate(c.sets[:3], start=1):
        head = f"deriving the equations of floppy_node, taut set {k}/4 ({' '.join(s.taut)})"
        mine = [ln for ln in err if ln.startswith(head)]
        # The first takes a while (a line at every step here); the others may be too quick.
        assert mine or k > 1, err
        if mine:
            assert re.fullmatch(rf"{re.escape(head)}(, the [^;]*)?; [\d.]+ s so far", mine[0])
            assert re.fullmatch(rf"{re.escape(head)}: done in [\d.]+ s", mine[-1]), mine


def test_certificate_search_reports_the_share_decided(monkeypatch, capsys):
    """The branch and bound of a torus certificate reports the share of the poses decided,
    rising to 100%."""
    monkeypatch.setenv(progress.ENV_DELAY, "0")
    monkeypatch.setenv(progress.ENV_SECONDS, "0")
    res = cb.solve(cb.Framework.from_toml(ZEEMAN))
    capsys.readouterr()
    cert = cb.certify(res)
    shares = [int(m[1]) for m in re.finditer(r"certificate search: (\d+)% of the poses decided",
                                             capsys.readouterr().err)]  # fmt: skip
    assert cert.boxes > 1 and len(shares) >= 2
    assert shares == sorted(shares) and shares[-1] == 100


def test_sweep_lines_carry_the_measured_rate(tmp_path):
    """A sweep off a terminal, a line per point (interval 0): each before the last with the
    rate and the time left at it; the last the count. The rate is the time so far over the
    points done, or, where the first point took more than ONE_OFF times as long as the later
    ones (its one-off costs), the later points' pace: never more than the average then."""
    env = {progress.ENV_SECONDS: "0"}
    res = run_cli("sweep", "--from", "1", "--to", "2", "--points", "3", "--workers", "1",
                  "--no-plots", "--out", str(tmp_path), env=env)  # fmt: skip
    assert res.returncode == 0, res.stderr
    lines = [ln for ln in res.stderr.splitlines() if ln.startswith("sweep: ")]
    assert lines[-1] == "sweep: 3/3 points, 0 paths lost"
    for k, line in enumerate(lines[:-1], start=1):
        m = re.fullmatch(rf"sweep: {k}/3 points, 0 paths lost; ([\d.]+) s a point, ([\d.]+) s "
                         r"so far, about ([\d.]+) s left", line)  # fmt: skip
        assert m, line
        rate, so_far, left = map(float, m.groups())
        if k == 1:
            assert rate == pytest.approx(so_far, rel=0.15, abs=0.02)
        else:
            assert rate <= so_far / k * 1.15 + 0.02
        assert left == pytest.approx(rate * (3 - k), rel=0.15, abs=0.02)
    assert len(lines) == 3


def test_fold_curves_say_each_stage(monkeypatch, capsys):
    """A map's fold curves (Zeeman, the sweep route) report each stage with its count: the
    crossings' solves by vertical line (9), the lines' branches (18), the tracing from every
    seed found, the classification of the points."""
    from cotm_bertini.catastrophe.framework_folds import framework_fold_curves

    monkeypatch.setenv(progress.ENV_DELAY, "0")
    monkeypatch.setenv(progress.ENV_SECONDS, "0")
    fw = cb.Framework.from_toml(ZEEMAN)
    _, record = framework_fold_curves(fw, "x", (-0.6, 0.8), "y", (-0.8, 0.2), kinds=("fold",),
                                      seeds="sweep")  # fmt: skip
    info = record["taut_sets"]["none"]["fold"]
    err = capsys.readouterr().err
    head = "fold curves 1/1 (fold, taut set none)"
    assert f"{head}: seeds on 18 lines by a sweep of the lines" in err
    assert f"{head}: equilibria at 9 x 9 crossings, by vertical line: 9/9 lines" in err
    assert f"{head}: branches and their turns along the seed lines: 18/18 lines" in err
    assert f"{head}: tracing curves from seeds: {info['seeds']}/{info['seeds']} seeds" in err
    assert re.search(rf"{re.escape(head)}: classifying the points: (\d+)/\1 chunks", err)
    assert re.search(rf"{re.escape(head)}: equilibria .*: 1/9 lines; [\d.]+ s a line", err)


def test_a_fraction_s_time_left_is_at_its_recent_rate_and_unknown_when_it_stalls(monkeypatch):
    """A search's share decided races to 90% and then crawls: the time left is that of the
    last window's pace (not the 22 s the first minute's average kept saying for six minutes),
    not known before a window has passed, and not known while nothing is decided."""
    from cotm_bertini import progress

    clock = [0.0]
    monkeypatch.setattr(progress.time, "perf_counter", lambda: clock[0])
    p = progress.Progress("search", 1.0, "of the poses decided", delay=0.0, force=True)
    for t in range(1, 11):  # 9% a second for 10 s
        clock[0] = float(t)
        p.set(0.09 * t)
        if t == 9:
            assert p.left is None  # one window (10 s) has not passed since the start
    for t in range(11, 61):  # then 0.01% a second for 50 s
        clock[0] = float(t)
        p.set(0.9 + 0.0001 * (t - 10))
        if t == 25:  # the last 10 s crawled, the 10 s before raced: a floor, said so
            assert p.falling and "at least about" in p.line() and "pace is falling" in p.line()
    # the last window (20 s, a third of 60) decided 0.002: 0.095 left takes 950 s at that pace
    assert p.left == pytest.approx(0.095 / 0.002 * 20, rel=1e-6)
    assert p.left > 100 * (p.elapsed / p.done) * (1 - p.done)  # the average would say ~6 s
    assert not p.falling and "about 16 min left" in p.line() and "at least" not in p.line()
    clock[0] = 100.0  # 40 s with nothing decided
    assert p.left is None and "time left not known yet" in p.line()
    p.close()


def test_a_long_time_left_is_said_in_days_or_years():
    """A time left of months or millennia (a search whose pace says 12 million hours) reads in
    days or years, with the same value: hours below two days."""
    assert progress.duration(3 * 3600) == "3.0 h"
    assert progress.duration(47 * 3600) == "47.0 h"
    assert progress.duration(4.5 * 86400) == "4.5 days"
    assert progress.duration(40 * 86400) == "40 days"
    assert progress.duration(3 * 365.25 * 86400) == "3.0 years"
    assert progress.duration(12_428_446 * 3600) == f"{12_428_446 / 24 / 365.25:,.0f} years"


def test_a_first_unit_with_one_off_costs_does_not_set_the_pace(monkeypatch):
    """A first point that carried one-off costs (20 s) and later ones at 0.1 s: the time left
    is at the later pace, not at the average (which would say some 2 hours for 1,000 points
    where 100 s are left); points of one pace keep the average."""
    clock = [0.0]
    monkeypatch.setattr(progress.time, "perf_counter", lambda: clock[0])
    p = progress.Progress("map", 1002, "points", delay=1e9)
    clock[0] = 20.0
    p.update(1)
    assert p.rate == pytest.approx(20.0)  # one unit: nothing else to go by ...
    assert p.left is None and "time left not known yet" in p.line()  # ... so no time left
    for _ in range(10):
        clock[0] += 0.1
        p.update(1)
    assert p.rate == pytest.approx(0.1) and p.left == pytest.approx(0.1 * 991)
    even = progress.Progress("sweep", 10, "points", delay=1e9)
    for k in range(4):
        clock[0] += 1.0 + 0.2 * (k % 2)
        even.update(1)
    assert even.rate == pytest.approx(even.elapsed / 4)
