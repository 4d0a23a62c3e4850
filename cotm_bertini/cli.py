"""Command line: `cotm-bertini solve CASE [options]`."""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
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
    s.add_argument(
        "--engine",
        choices=("homotopy", "cli"),
        help="homotopy: parameter homotopy in-process from the cached generic solution set "
        "(default); cli: total-degree solve by the bertini2 command (or --bertini)",
    )
    s.add_argument(
        "--no-plots", action="store_true", help="skip the figures (and the import of matplotlib)"
    )
    s.add_argument(
        "--no-cache",
        action="store_true",
        help="solve even if an identical request was answered before",
    )
    s.add_argument("--quiet", action="store_true", help="print only where the files are")
    v = sub.add_parser("verify", help="cross-check a case by independent routes")
    v.add_argument("case", nargs="?", choices=sorted(CASES), default="case3")
    v.add_argument("--params", metavar="FILE.toml")
    v.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    v.add_argument("--seed", type=int, default=1, help="Bertini and PHCpack seed (default 1)")
    v.add_argument("--timeout", type=float, default=600.0)
    v.add_argument("--threads", type=int, default=None)
    v.add_argument("--mptype", type=int, default=2, choices=(0, 1, 2))
    v.add_argument("--bertini", metavar="PATH")
    v.add_argument("--engine", choices=("homotopy", "cli"))
    w = sub.add_parser("sweep", help="solve along a parameter range (or a 2-D grid)")
    w.add_argument("--param", default="L01", help="swept parameter (default L01)")
    w.add_argument("--from", dest="start", type=float, default=0.0)
    w.add_argument("--to", dest="stop", type=float, default=12.0)
    w.add_argument("--points", type=int, default=241)
    w.add_argument("--param2", help="a second swept parameter: a 2-D grid")
    w.add_argument("--from2", dest="start2", type=float)
    w.add_argument("--to2", dest="stop2", type=float)
    w.add_argument("--points2", type=int)
    w.add_argument("--params", metavar="FILE.toml", help="base parameters (default Table 1)")
    w.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    w.add_argument("--seed", type=int, default=1)
    w.add_argument("--workers", type=int, default=None, help="local processes (default: cores)")
    w.add_argument("--scheduler", metavar="ADDRESS", help="a Dask scheduler, tcp://host:8786")
    w.add_argument("--out", metavar="DIR", default="runs", help="root of sweep folders")
    w.add_argument("--resume", metavar="DIR", help="continue the sweep in DIR")
    w.add_argument("--all", action="store_true", help="plot non-physical real roots too")
    w.add_argument("--no-plots", action="store_true", help="skip the figures")
    w.add_argument("--quiet", action="store_true", help="no progress bar")
    pp = sub.add_parser("paper", help="compare Tables 2-4 of the paper with our solutions")
    pp.add_argument("--out", metavar="DIR", default="runs/paper", help="default runs/paper")
    pp.add_argument("--seed", type=int, default=1, help="Bertini RandomSeed (default 1)")
    return ap


def _paper(args: argparse.Namespace) -> int:
    from .geometry import TABLE1
    from .paper import K_RATIO
    from .pipeline import solve_in
    from .report import Scenario, build_report
    from .results import write_csv, write_text

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scenarios = []
    for name, k2 in (
        ("Table 1 as printed (k2/k1 = 1)", TABLE1["k2"]),
        (f"k2/k1 = {K_RATIO} (NOTES.md)", TABLE1["k1"] * K_RATIO),
    ):
        params, tables, paths = {}, {}, {}
        for case in ("case1", "case2", "case3"):
            p = make_params(case, {"k2": k2})
            with tempfile.TemporaryDirectory(prefix="cotm-paper-") as tmp:
                solved = solve_in(Path(tmp) / "run", p, Settings(seed=args.seed))
            params[case], tables[case], paths[case] = p, solved.solutions, solved.paths_tracked
            print(f"{name}, {case}: {len(solved.solutions)} solutions", file=sys.stderr)
        scenarios.append(Scenario(name, params, tables, paths))
    text, rows = build_report(scenarios)
    write_text(out / "report.md", text)
    write_csv(out / "rows.csv", rows)
    print(f"report: {out / 'report.md'}, rows: {out / 'rows.csv'}")
    return 0


def _verify(args: argparse.Namespace) -> int:
    from .pipeline import solve
    from .verify import verify

    params = _params(args)
    settings = _settings(args)
    solutions = solve(params, settings)
    phys = int(solutions["physical"].sum())
    print(
        f"{args.case}: Bertini finds {len(solutions)} distinct finite solutions "
        f"({int(solutions['is_real'].sum())} real, {phys} physical)"
    )
    results = verify(params, solutions, seed=args.seed)
    width = max(len(r.route) for r in results)
    for r in results:
        verdict = {True: "agrees", False: "DISAGREES", None: "n/a"}[r.agrees]
        gap = (
            ""
            if r.max_disagreement_deg != r.max_disagreement_deg
            else (f", max gap {r.max_disagreement_deg:.1e} deg")
        )
        print(
            f"  {r.route:<{width}}  {verdict:<9} {r.found}{gap}"
            + (f" ({r.note})" if r.note else "")
        )
    bad = [r.route for r in results if r.agrees is False]
    print("all routes agree" if not bad else f"disagreement: {', '.join(bad)}")
    return 1 if bad else 0


def _sweep(args: argparse.Namespace) -> int:
    from .sweep import (
        SweepSpec,
        default_workers,
        finish,
        load_spec,
        prepare,
        run_points,
    )
    from .sweep import (
        pending_points as pending,
    )

    if args.resume:
        spec = load_spec(Path(args.resume))
        folder = prepare(spec, Path(args.out), resume=Path(args.resume))
    else:
        base = make_params(None, _overrides(args)).as_dict()
        spec = SweepSpec(
            base,
            args.param,
            args.start,
            args.stop,
            args.points,
            args.param2,
            args.start2,
            args.stop2,
            args.points2,
            args.seed,
        )
        for values in (spec.grid()[0], spec.grid()[-1]):
            make_params(None, {**base, **values})  # a bad range fails here, before any work
        folder = prepare(spec, Path(args.out))
    workers = args.workers or default_workers()
    bar = None
    if not args.quiet:
        from tqdm import tqdm

        bar = tqdm(total=len(spec.grid()), unit="pt", desc="sweep", file=sys.stderr)
        bar.update(len(spec.grid()) - len(pending(spec, folder)))

    def progress(done: int, total: int, lost: int) -> None:
        if bar is not None:
            bar.update(1)
            bar.set_postfix(lost_paths=lost)

    stats = run_points(spec, folder, workers=workers, scheduler=args.scheduler, progress=progress)
    if bar is not None:
        bar.close()
    record = finish(
        spec,
        folder,
        stats,
        plots=not args.no_plots,
        show_all=args.all,
        workers=workers,
        scheduler=args.scheduler,
        command=sys.argv[:],
    )
    print(
        f"{record['rows']} rows at {record['points']} points ({stats['skipped']} resumed), "
        f"{record['events']} events, {stats['seconds']:.1f} s solving"
    )
    print(
        f"files: {folder}/sweep.csv, events.csv, run.json"
        + (", " + ", ".join(record["figures"]) if record["figures"] else "")
    )
    return 0


def _settings(args: argparse.Namespace) -> Settings:
    """Settings from the command line; a Bertini binary (--bertini, $COTM_BERTINI) means cli."""
    engine = args.engine or (
        "cli" if (args.bertini or os.environ.get("COTM_BERTINI")) else "homotopy"
    )
    return Settings(
        seed=args.seed,
        timeout=args.timeout,
        threads=args.threads,
        mptype=args.mptype,
        bertini=args.bertini,
        engine=engine,
    )


def _overrides(args: argparse.Namespace) -> dict[str, float]:
    """--params FILE.toml, then each --set NAME=VALUE."""
    overrides: dict[str, float] = {}
    if args.params:
        overrides.update(load_toml(args.params))
    for text in args.set:
        name, value = parse_assignment(text)
        overrides[name] = value
    return overrides


def _params(args: argparse.Namespace):
    return make_params(args.case, _overrides(args))


def _summary(solved, folder: Path, record: dict) -> str:
    """The console report of a solve: counts, the real solutions, where the files are."""
    s = solved.solutions
    real = s[s["is_real"]]
    c = record["counts"]
    engine = record["engine"]
    lines = [
        f"{record['label']}: {c['distinct_solutions']} distinct finite solutions "
        f"({c['real']} real, {c['physical']} physical, {c['stable']} stable) "
        f"from {c['finite_endpoints']} finite endpoints of {c['paths_tracked']} paths tracked; "
        f"{engine['flavour']} ({engine['path']} {engine['version']}) "
        f"{record['timings']['solve']:.2f} s"
    ]
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
        lines.append(real[cols].to_string(index=False, float_format=lambda v: f"{v:.4f}"))
    return "\n".join(lines)


def _files_line(folder: Path) -> str:
    files = sorted(p.name for p in folder.iterdir() if p.is_file())
    return f"files in {folder}: {', '.join(files)}"


def _warn_morse(record: dict) -> None:
    morse = record.get("morse") or {}
    if morse and not morse["ok"]:
        print(
            "cotm-bertini: warning: #min - #saddle + #max (+ zero-length maxima) = "
            f"{morse['euler_characteristic']} != 0 on the torus"
            + (f", {morse['degenerate']} degenerate" if morse["degenerate"] else "")
            + ": equilibria may be missing",
            file=sys.stderr,
        )


def _solve(args: argparse.Namespace) -> int:
    import datetime as dt
    import time

    from . import cache
    from .results import link_latest, new_run_folder, write_json

    start = time.perf_counter()
    params = _params(args)
    settings = _settings(args)
    root = Path(args.out) if args.out else Path("runs") / args.case
    key = cache.request_key(params.as_dict(), settings.as_dict(), plots=not args.no_plots)
    cached = None if args.no_cache else cache.lookup(key)
    if cached is not None:
        work, final = new_run_folder(root)
        record = cache.replay(
            key,
            cached,
            work,
            final,
            {
                "created": dt.datetime.now().astimezone().isoformat(timespec="seconds"),
                "command": sys.argv[:],
            },
        )
        link_latest(root, final)
        _warn_morse(record)
        print(final if args.quiet else record["summary"] + "\n" + _files_line(final))
        print(
            f"cache: answered from a solve of {record['cache']['solved']} (key {key}) in "
            f"{(time.perf_counter() - start) * 1e3:.0f} ms; --no-cache solves again",
            file=sys.stderr,
        )
        return 0

    from .pipeline import run_and_record

    folder, solved, record = run_and_record(
        params, settings, root, args.case, command=sys.argv[:], plots=not args.no_plots
    )
    _warn_morse(record)
    text = _summary(solved, folder, record)
    record.update(summary=text, cache={"hit": False, "key": key})
    write_json(folder / "run.json", record)
    cache.store(key, folder)
    print(folder if args.quiet else text + "\n" + _files_line(folder))
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script."""
    args = _parser().parse_args(argv)
    try:
        if args.command == "solve":
            return _solve(args)
        if args.command == "sweep":
            return _sweep(args)
        if args.command == "verify":
            return _verify(args)
        if args.command == "paper":
            return _paper(args)
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
