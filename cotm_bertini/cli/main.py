"""Command line of cotm-bertini (docs/cli.md)."""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

from .._version import __version__
from ..errors import CotmError, ParameterError, SolverError
from . import commands
from .options import (
    EXIT_SOLVER,
    EXIT_USAGE,
    Parser,
    add_case,
    add_only,
    add_params,
    add_route,
    add_settings,
)

PURPOSE = (
    "Every equilibrium of the planar compliant tensegrity mechanism (two triangles, a rigid rod\n"
    "and two springs; Tanouye & Vikas, DETC2018-85998), solved with Bertini, each one\n"
    "classified real, physical and stable; sweeps, proofs and design maps of the same."
)


def _version_text() -> str:
    from ..versions import bertini2_version

    return f"cotm-bertini {__version__} (bertini2 {bertini2_version()})"


HTML_HELP = "also write explore.html: the results in a browser, offline, one file"


def _solve_parser(sub) -> None:
    s = sub.add_parser("solve", help="every equilibrium of one parameter set")
    add_case(s)
    add_params(s)
    add_settings(s)
    add_only(s)
    s.add_argument("--out", metavar="DIR", help="root of run folders (default runs/<label>)")
    s.add_argument(
        "--no-plots", action="store_true", help="skip the figures (and the import of matplotlib)"
    )
    s.add_argument(
        "--no-cache", action="store_true", help="solve even if an identical request was answered"
    )
    s.add_argument("--quiet", action="store_true", help="print only where the files are")
    s.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="a Dask scheduler, tcp://host:8786: a generic set solved ab initio has its paths "
        "split over the workers, a framework's real search its boxes",
    )
    s.add_argument(
        "--workers",
        type=int,
        help="local processes that share a framework's real search (default: this process "
        "for 2 s, then one a core)",
    )
    s.add_argument(
        "--certify",
        action="store_true",
        help="prove every solution and that no equilibrium is missing (docs/certify.md); "
        "exit 4 if the proof contradicts the solver",
    )
    s.set_defaults(run=commands.solve)
    c = sub.add_parser(
        "certify",
        parents=[],
        help="solve and prove: every solution certified, the physical set complete",
    )
    add_case(c)
    add_params(c)
    add_settings(c)
    c.add_argument("--out", metavar="DIR", help="root of run folders (default runs/<label>)")
    c.add_argument("--no-plots", action="store_true", help="skip the figures")
    c.add_argument("--no-cache", action="store_true", help="solve even if answered before")
    c.add_argument("--quiet", action="store_true", help="print only where the files are")
    c.set_defaults(run=commands.certify)


def _sweep_parser(sub) -> None:
    w = sub.add_parser(
        "sweep",
        help="solve along a parameter range (or a 2-D grid)",
        description="Solve at evenly spaced values of one parameter (or a grid of two). "
        "--from and --to are required except for L01 and L02 (default 0 to 12 m, the paper's "
        "Figs 5-6).",
    )
    w.add_argument("--param", default="L01", help="swept parameter (default L01)")
    w.add_argument("--from", dest="start", type=float, help="first value")
    w.add_argument("--to", dest="stop", type=float, help="last value")
    w.add_argument("--points", type=int, default=241, help="number of values (default 241)")
    w.add_argument("--param2", help="a second swept parameter: a 2-D grid")
    w.add_argument("--from2", dest="start2", type=float, help="first value of --param2")
    w.add_argument("--to2", dest="stop2", type=float, help="last value of --param2")
    w.add_argument("--points2", type=int, help="number of values of --param2")
    add_params(w)
    add_settings(w)
    add_only(w)
    w.add_argument("--workers", type=int, help="local processes (default: one per core)")
    w.add_argument("--scheduler", metavar="ADDRESS", help="a Dask scheduler, tcp://host:8786")
    w.add_argument("--out", metavar="DIR", default="runs", help="root of sweep folders (runs)")
    w.add_argument("--resume", metavar="DIR", help="continue the sweep stored in DIR")
    w.add_argument("--all", action="store_true", help="plot the non-physical real roots too")
    w.add_argument("--no-plots", action="store_true", help="skip the figures")
    w.add_argument("--html", action="store_true", help=HTML_HELP + " (one-parameter sweeps)")
    w.add_argument("--quiet", action="store_true", help="no progress report")
    w.add_argument(
        "--certify", action="store_true", help="prove every point (docs/certify.md); slower"
    )
    w.set_defaults(run=commands.sweep, case=None)


def _verify_parser(sub) -> None:
    v = sub.add_parser("verify", help="cross-check one parameter set by independent routes")
    add_case(v)
    add_params(v)
    add_settings(v)
    v.add_argument("--out", metavar="DIR", help="also write verify.json (the report) there")
    v.set_defaults(run=commands.verify)


def _barriers_parser(sub) -> None:
    b = sub.add_parser("barriers", help="energy barriers between the stable equilibria")
    add_case(b)
    add_params(b)
    add_settings(b)
    b.add_argument("--out", metavar="DIR", help="default runs/barriers-<label>")
    b.add_argument("--no-plots", action="store_true", help="skip the picture of the paths")
    b.set_defaults(run=commands.barriers)


def _window_options(p, points: int) -> None:
    """The two axes of a map (or a plan's map) and their ranges, points, workers."""
    p.add_argument("--param", help="first axis (default L01; a framework: one of its parameters)")
    p.add_argument("--from", dest="start", type=float, help="default 0 (the paper)")
    p.add_argument("--to", dest="stop", type=float, help="default 14 (the paper)")
    p.add_argument("--param2", help="second axis (default L02)")
    p.add_argument("--from2", dest="start2", type=float, help="default 0 (the paper)")
    p.add_argument("--to2", dest="stop2", type=float, help="default 14 (the paper)")
    p.add_argument("--points", type=int, default=points,
                   help=f"grid points a side (default {points})")  # fmt: skip
    p.add_argument("--workers", type=int, help="local processes (default: one per core)")


def _map_parser(sub) -> None:
    m = sub.add_parser(
        "map",
        help="stable-count regions and fold curves over two parameters",
        description="The paper's mechanism over (L01, L02), default 0 to 14 m on both axes; "
        "or a framework (--framework FILE.toml) over any two of its parameters (--param, "
        "--param2 and their ranges required).",
    )
    add_params(m)
    add_settings(m)
    add_only(m)
    _window_options(m, points=101)
    m.add_argument("--grid", choices=("auto", "search", "continuation"), default="auto",
                   help="search: every grid point solved; continuation: a framework on the real "
                   "route, anchors searched and equilibria followed in chart angles; auto "
                   "(default): continuation for a spatial framework on the real route, search "
                   "with --only stable")  # fmt: skip
    m.add_argument("--out", metavar="DIR", default="runs/map", help="default runs/map")
    m.add_argument("--no-plots", action="store_true", help="skip map.png/svg")
    m.add_argument("--html", action="store_true", help=HTML_HELP)
    m.add_argument("--quiet", action="store_true", help="no progress report")
    m.set_defaults(run=commands.design_map, case=None)


def _move_parser(sub) -> None:
    m = sub.add_parser(
        "move",
        help="follow a stable state while parameters move: where it snaps, the energy released",
        description="Solve at the path's start (the parameters with each path name at its first "
        "waypoint), then follow the stable state --state (a solution_id as `solve` prints it) "
        "along the path, piecewise linear; at a fold or a cable switch it snaps to the minimum "
        "it falls into. Writes trajectory.csv, snaps.csv, run.json, move.png and move.gif.",
    )
    _state_options(m)
    m.add_argument("--path", action="append", required=True, metavar="NAME=V0,V1,...",
                   help="waypoints of one parameter (repeatable; as many for each)")  # fmt: skip
    m.add_argument("--steps", type=int, default=100, help="recorded steps a segment (default 100)")
    _run_options(m, "move", "move.png/svg and move.gif")
    m.set_defaults(run=commands.move)


def _state_options(p) -> None:
    """The mechanism, its solver settings and the stable state a move or plan starts from."""
    add_case(p)
    add_params(p)
    add_settings(p)
    p.add_argument("--state", type=int, required=True, metavar="ID", help="a stable solution_id")


def _run_options(p, name: str, plots: str) -> None:
    """Where a move's or plan's run folder goes and what it holds."""
    p.add_argument("--out", metavar="DIR", help=f"default runs/{name}-<label>")
    p.add_argument("--no-plots", action="store_true", help=f"skip {plots}")
    p.add_argument("--html", action="store_true", help=HTML_HELP)
    p.add_argument("--quiet", action="store_true", help="no progress report")


def _plan_parser(sub) -> None:
    p = sub.add_parser(
        "plan",
        help="an actuator path from one stable state to another, over a map",
        description="Solve at the parameters, make the map over the window (as `map`), then "
        "find the path over its grid with the fewest snaps, then the least travel, that takes "
        "the mechanism from --state to --goal and brings the actuators back; checked by a "
        "move along it. Writes plan.csv, the move's trajectory.csv and snaps.csv, run.json, "
        "plan.png, move.png, move.gif. 'unreachable' (exit 0) is an answer.",
    )
    _state_options(p)
    p.add_argument("--goal", type=int, required=True, metavar="ID", help="another stable one")
    _window_options(p, points=41)
    _run_options(p, "plan", "plan.png, move.png, move.gif")
    p.set_defaults(run=commands.plan)


def _design_parser(sub) -> None:
    d = sub.add_parser(
        "design",
        help="the free lengths that hold a chosen pose in equilibrium (inverse design)",
        description="Print the free lengths that hold the pose (gamma1, gamma2) in equilibrium, "
        "as TOML with units; angles in [0, 360) deg, lengths in m.",
    )
    add_case(d, default="none (L01, L02 of the parameters are not used)")
    add_params(d)
    d.add_argument("--gamma1", type=float, required=True, metavar="DEG", help="rod angle")
    d.add_argument("--gamma2", type=float, required=True, metavar="DEG", help="top body angle")
    given = d.add_mutually_exclusive_group()
    given.add_argument("--L01", type=float, metavar="M", help="choose L01 (parallel curve only)")
    given.add_argument("--L02", type=float, metavar="M", help="choose L02 (parallel curve only)")
    d.add_argument("--out", metavar="FILE.csv", help="also write the answer as a one-row CSV")
    d.set_defaults(run=commands.design)


def _parser() -> argparse.ArgumentParser:
    ap = Parser(
        prog="cotm-bertini",
        description=PURPOSE,
        epilog="`cotm-bertini COMMAND --help` describes a command's options; docs/cli.md "
        "describes them all, with the exit codes.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    ap.add_argument("--version", action="version", version=_version_text())
    sub = ap.add_subparsers(
        title="commands", dest="command", required=True, parser_class=Parser, metavar="COMMAND"
    )
    _solve_parser(sub)
    _sweep_parser(sub)
    _verify_parser(sub)
    pp = sub.add_parser("paper", help="compare Tables 2-4 of the paper with our solutions")
    pp.add_argument("--out", metavar="DIR", default="runs/paper", help="default runs/paper")
    pp.add_argument("--seed", type=int, default=1, help="solver seed (default 1)")
    pp.set_defaults(run=commands.paper)
    _barriers_parser(sub)
    _map_parser(sub)
    _move_parser(sub)
    _plan_parser(sub)
    _design_parser(sub)
    pr = sub.add_parser(
        "params", help="print the parameter set the other commands would use, as TOML"
    )
    add_case(pr)
    add_params(pr)
    add_route(pr)
    pr.set_defaults(run=commands.params)
    return ap


def _warning_line(message, category, filename: str, lineno: int, line=None) -> str:
    """A library warning as one console line, its source in brackets (not Python's two lines
    with the source line quoted)."""
    where = f"{category.__name__}, {Path(filename).name}:{lineno}"
    return f"cotm-bertini: warning: {message} ({where})\n"


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script."""
    # Warnings are fixed where they arise (model/intervals.py); one that is not yet reaches the
    # console as one line, like the package's own.
    warnings.formatwarning = _warning_line
    args = _parser().parse_args(argv)
    try:
        return args.run(args)
    except ParameterError as exc:
        print(f"cotm-bertini: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except SolverError as exc:
        print(f"cotm-bertini: solver failed: {exc}", file=sys.stderr)
        return EXIT_SOLVER
    except CotmError as exc:
        print(f"cotm-bertini: error: {exc}", file=sys.stderr)
        return EXIT_SOLVER


if __name__ == "__main__":
    sys.exit(main())
