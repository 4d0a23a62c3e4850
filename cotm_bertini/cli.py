"""Command line: `cotm-bertini solve CASE [options]`."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .engine import EngineError
from .geometry import CASES, PARAM_NAMES, ParameterError, load_toml, make_params, parse_assignment
from .settings import Settings
from .solver import SolverError

EXIT_USAGE = 2
EXIT_SOLVER = 3


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, exit code 2
        self.exit(EXIT_USAGE, f"cotm-bertini: error: {message}\n")


def _parser() -> argparse.ArgumentParser:
    ap = _Parser(prog="cotm-bertini", description=__doc__)
    sub = ap.add_subparsers(dest="command", required=True, parser_class=_Parser)
    s = sub.add_parser("solve", help="every equilibrium of one parameter set")
    s.add_argument(
        "case",
        nargs="?",
        choices=sorted(CASES),
        default="case3",
        help="preset for L01/L02 (case1: 0,0; case2: 11.5,0; case3: 11.5,11.5)",
    )
    s.add_argument(
        "--params", metavar="FILE.toml", help=f"TOML with any of: {' '.join(PARAM_NAMES)}"
    )
    s.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="override one parameter (repeatable)",
    )
    s.add_argument("--out", metavar="DIR", help="run folder root (default runs/CASE)")
    s.add_argument("--seed", type=int, default=1, help="Bertini RandomSeed (default 1)")
    s.add_argument("--timeout", type=float, default=600.0, help="seconds before Bertini is killed")
    s.add_argument("--threads", type=int, default=None, help="bertini2 threads (default: all)")
    s.add_argument(
        "--mptype",
        type=int,
        default=2,
        choices=(0, 1, 2),
        help="Bertini MPType: 0 double, 1 fixed higher, 2 adaptive (default)",
    )
    s.add_argument(
        "--bertini",
        metavar="PATH",
        help="a Bertini 1.x binary instead of bertini2 (also $COTM_BERTINI)",
    )
    s.add_argument("--quiet", action="store_true", help="print only where the files are")
    return ap


def _params(args: argparse.Namespace):
    overrides: dict[str, float] = {}
    if args.params:
        overrides.update(load_toml(args.params))
    for text in args.set:
        name, value = parse_assignment(text)
        overrides[name] = value
    return make_params(args.case, overrides)


def _print_table(solved, folder: Path, record: dict) -> None:
    s = solved.solutions
    real = s[s["is_real"]]
    c = record["counts"]
    print(
        f"{record['label']}: {c['distinct_solutions']} distinct finite solutions "
        f"({c['real']} real, {c['physical']} physical, {c['stable']} stable) "
        f"from {c['finite_endpoints']} finite endpoints of {c['paths_tracked']} paths; "
        f"Bertini {record['engine']['version']} {record['timings']['solve']:.2f} s"
    )
    if len(real):
        cols = [
            "solution_id",
            "gamma1_deg",
            "gamma2_deg",
            "d1",
            "d2",
            "physical",
            "stable",
            "kind",
            "reason",
        ]
        print(real[cols].to_string(index=False, float_format=lambda v: f"{v:.4f}"))
    print(f"files: {folder}/solutions.csv, run.json, input, Bertini output")


def _solve(args: argparse.Namespace) -> int:
    from .pipeline import run_and_record

    params = _params(args)
    settings = Settings(
        seed=args.seed,
        timeout=args.timeout,
        threads=args.threads,
        mptype=args.mptype,
        bertini=args.bertini,
    )
    root = Path(args.out) if args.out else Path("runs") / args.case
    folder, solved, record = run_and_record(params, settings, root, args.case, command=sys.argv[:])
    if args.quiet:
        print(folder)
    else:
        _print_table(solved, folder, record)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "solve":
            return _solve(args)
    except ParameterError as exc:
        print(f"cotm-bertini: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except ValueError as exc:  # settings out of range
        print(f"cotm-bertini: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except (SolverError, EngineError) as exc:
        print(f"cotm-bertini: solver failed: {exc}", file=sys.stderr)
        return EXIT_SOLVER
    return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
