"""A solver warning that a solution may be wrong is the run's warning (issue 39, item 4).

Bertini prints "N path crossing(s) ... remained unresolved ...; the affected solutions may be
wrong" from its C++ code on file descriptor 2 and flags the paths. Provoked here for real on a
small system (Euler predictor, loose tracking, no tightening on its re-tracks), checked against
an independent solve of the same system with Bertini's defaults (all 8 x 7 = 56 roots, the
Bezout number, distinct): the flagged paths end at one point, so the provoked solve lacks a root.
The package must keep Bertini's raw line off the console, read the flags, and carry them to the
status and run.json.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
from conftest import ROOT, run_cli, same_sets

from cotm_bertini.backends import crossings

SYSTEM = "variable_group x,y; function f1,f2; f1 = x^8 - 3*x*y + 1 - y^3; f2 = y^7 + x^2*y - 2 + x;"
BERTINI_LINE = (
    "warning: 4 path crossing(s) detected at the endgame boundary remained unresolved after 2 "
    "re-track attempt(s); the affected solutions may be wrong.  Consider a higher-order "
    "predictor or a tighter tracking tolerance.  See EndgameBoundaryMetadata().\n"
)


def _solver(sloppy: bool):
    import bertini
    from bertini import nag_algorithm as na
    from bertini import tracking

    bertini.random.set_random_seed(1)
    solver = na.ZeroDimSolver(bertini.parse.system(SYSTEM), mptype="double")
    solver.set(num_threads=1)
    if sloppy:
        solver.set(predictor=tracking.Predictor.Euler, tracking_tolerance=1e-1,
                   newton_before_endgame=1e-1, midpath_decrease_tolerance_factor=1)  # fmt: skip
    return solver


def _points(solver) -> np.ndarray:
    return np.array([[complex(z) for z in p] for p in solver.all_solutions()])


def _distinct(pts: np.ndarray, tol: float = 1e-8) -> int:
    kept: list[np.ndarray] = []
    for p in pts:
        if not any(np.abs(p - q).max() < tol for q in kept):
            kept.append(p)
    return len(kept)


def test_a_provoked_crossing_is_read_from_the_flags_not_printed_raw(capfd):
    """The provoked solve prints Bertini's line when run bare (the control); through
    crossings.solve nothing of it reaches stderr, and exactly the flagged paths read as
    CROSSING: they end at one point, and the solve has one root fewer than the 56 of an
    independent default solve."""
    from cotm_bertini.backends.homotopy import _code

    _solver(True).solve(show_progress=False)
    assert "path crossing(s)" in capfd.readouterr().err  # the provocation is real
    sloppy, clean = _solver(True), _solver(False)
    crossings.solve(sloppy)
    crossings.solve(clean)
    assert "path crossing(s)" not in capfd.readouterr().err
    codes = [_code(m) for m in sloppy.solution_metadata()]
    bad = [i for i, c in enumerate(codes) if c == crossings.CROSSING]
    assert bad == [i for i, m in enumerate(sloppy.solution_metadata()) if m.crossing_unresolved]
    assert len(bad) >= 2
    pts, ref = _points(sloppy), _points(clean)
    assert np.abs(pts[bad] - pts[bad[0]]).max() < 1e-8  # two paths on one root
    assert _distinct(ref) == 56 == 8 * 7
    assert _distinct(pts) < 56
    assert all(c != crossings.CROSSING for c in map(_code, clean.solution_metadata()))


def test_the_filter_drops_bertinis_line_only_whatever_the_chunks(tmp_path):
    """Everything else written to stderr passes through, byte for byte, even when Bertini's
    line and the others arrive cut at any byte (a progress bar's \\r lines included)."""
    import os

    other = "cotm-bertini: a line\r 10%|#   | bar\rwarning: something else\nwar"
    text = (other + "\n" + BERTINI_LINE + "tail").encode()
    expected = (other + "\ntail").encode()
    for step in (1, 3, 7, 64, len(text)):
        out = tmp_path / f"out{step}"
        with open(out, "wb") as f:
            pump = crossings._Filter(f.fileno())
            for k in range(0, len(text), step):
                pump.feed(text[k : k + step])
            pump.flush()
            os.fsync(f.fileno())
        assert out.read_bytes() == expected, step
        assert pump.dropped == 1


def test_the_bertini2_commands_stderr_is_counted():
    """The bertini2 command's stderr: the numbers of its lines, summed."""
    assert crossings.count_in("") == 0
    assert crossings.count_in("x\n" + BERTINI_LINE + BERTINI_LINE.replace("4 path", "3 path")) == 7


def test_unresolved_crossings_make_the_framework_run_incomplete(tmp_path):
    """End to end: Zeeman's wheel solved once (its generic set cached), then again in a process
    where Bertini flags every path as crossing another (a copy of the cache, so that nothing
    it finds is kept): the second start and the ab-initio solve cannot part them either, so the
    run is incomplete (exit 5), run.json counts the crossings and its warnings say them, in the
    package's words on stderr, with no raw Bertini line."""
    import os
    import shutil

    toml = ROOT / "examples" / "zeeman_cables.toml"
    args = ["solve", "--framework", str(toml), "--no-plots", "--no-cache", "--route", "complex"]
    r = run_cli(*args, "--out", str(tmp_path / "a"))
    assert r.returncode == 0, r.stderr
    first = json.loads((tmp_path / "a" / "latest" / "run.json").read_text())
    assert first["counts"]["crossings_unresolved"] == 0
    shutil.copytree(os.environ["COTM_CACHE"], tmp_path / "cache")
    script = (
        "import sys; from cotm_bertini.backends import crossings; "
        "crossings.flagged = lambda m: True; from cotm_bertini.cli.main import main; "
        f"sys.exit(main({[*args, '--out', str(tmp_path / 'b')]!r}))"
    )
    r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                       env={**os.environ, "COTM_CACHE": str(tmp_path / "cache")})  # fmt: skip
    assert r.returncode == 5, r.stderr
    rec = json.loads((tmp_path / "b" / "latest" / "run.json").read_text())
    tracked = [v for v in rec["details"]["taut_sets"].values() if "tracked" in v]
    assert rec["status"] == "incomplete"
    assert rec["counts"]["crossings_unresolved"] == sum(v["lost"] for v in tracked) > 0
    assert any("crossed another path" in w for w in rec["warnings"])
    assert "crossed another path" in r.stderr and "path crossing(s)" not in r.stderr


def test_the_total_degree_routes_tracker_reads_the_flags_too(capfd):
    """The same system and sloppy tracking on the total-degree route's own start, tracked on
    its projective patch by homotopy.tracked_paths (HomotopySolver, not ZeroDimSolver): the
    paths Bertini flags read as CROSSING, each ends on the point of another flagged path, and
    its raw line stays off stderr."""
    from cotm_bertini.backends import homotopy
    from cotm_bertini.model.polynomial import ParametricSystem

    terms = (((1, (8, 0)), (-3, (1, 1)), (1, (0, 0)), (-1, (0, 3))),
             ((1, (0, 7)), (1, (2, 1)), (-2, (0, 0)), (1, (1, 0))))  # SYSTEM's  # fmt: skip
    ps = ParametricSystem(
        ("x", "y"), ("f1", "f2"), (),
        tuple(np.array([e for _, e in f], dtype=np.int64) for f in terms),
        tuple(np.zeros((len(f), 0), dtype=np.int64) for f in terms),
        tuple(np.array([c for c, _ in f], dtype=float) for f in terms), (),
    )  # fmt: skip
    lp, texts = homotopy.own_start(ps.instantiate([]), None, 1)
    starts = np.array(list(lp.points()))[:, lp.declared]
    sloppy = {"projective": True, "predictor": "Euler", "tracking_tolerance": 1e-1,
              "newton_before_endgame": 1e-1, "midpath_decrease_tolerance_factor": 1}  # fmt: skip
    out = homotopy.tracked_paths(texts, starts, "double", sloppy)
    bad = [i for i, c in enumerate(out["codes"]) if c == crossings.CROSSING]
    assert len(starts) == 56 and len(bad) >= 2
    pts = out["points"][bad]
    assert all(sorted(np.abs(pts - p).max(axis=1))[1] < 1e-8 for p in pts)  # in pairs
    assert "path crossing(s)" not in capfd.readouterr().err


def test_the_total_degree_route_tracks_flagged_paths_again_then_tighter(monkeypatch, capfd):
    """The generic solve on our own start and projective patch (homotopy._own_solve): a path
    Bertini flags is a failed path, tracked again in adaptive precision (double_then_adaptive);
    one flagged still is tracked again at CROSSING_TOLERANCES, said and recorded; one flagged
    even there leaves the set incomplete (generic.failed), its root missing. Bertini's flags
    are stood in for on the first `flags(...)` finite roots of each of its calls (two in double
    precision only; two until a call asks for the tighter tolerances; always, in that call all
    the paths tracked again). The roots are those of the hand-written system of
    tests/test_total_degree_route, found there by elimination."""
    from test_total_degree_route import _roots, _system

    from cotm_bertini.backends import generic, homotopy

    real = homotopy.tracked_paths

    def flagging(flags):
        def tracked(texts, points, mptype, options):
            out = real(texts, points, mptype, options)
            ok = [k for k, c in enumerate(out["codes"]) if c == "Success" and out["finite"][k]]
            for k in ok[: flags(mptype, "tracking_tolerance" in options)]:
                out["codes"][k] = crossings.CROSSING
            return out

        return tracked

    def solve(flags):
        monkeypatch.setattr(homotopy, "tracked_paths", flagging(flags))
        gs = homotopy.generic_set(_system(), 3, use_cache=False, centre={"p": 0.4})
        return gs, _roots(gs.start["p"]), capfd.readouterr().err

    gs, reference, err = solve(lambda mptype, tight: 2 * (mptype == "double"))
    assert same_sets(gs.points, reference) and "crossings_first_solve" not in gs.route
    assert "crossed another path" not in err

    gs, reference, err = solve(lambda mptype, tight: 0 if tight else 2)
    assert same_sets(gs.points, reference) and len(reference) == 6
    assert gs.route["crossings_first_solve"] >= 2 and gs.route["crossings_unresolved"] == 0
    assert gs.route["crossings_solved_again_at"] == homotopy.CROSSING_TOLERANCES
    assert not generic.failed(gs)
    assert "crossed another path and Bertini could not part them" in err
    assert "again: no crossing left" in err and "path crossing(s)" not in err

    gs, reference, err = solve(lambda mptype, tight: 12 if tight else 2)  # 12: all its paths
    left = gs.route["crossings_unresolved"]
    assert left == gs.route["crossings_first_solve"] >= 2 and generic.failed(gs)
    assert len(gs.points) == len(reference) - left
    assert all(np.abs(reference - p).max(axis=1).min() < 1e-8 for p in gs.points)  # all right
    assert "is incomplete" in err and f"{left} paths crossed another path, unresolved" in err
