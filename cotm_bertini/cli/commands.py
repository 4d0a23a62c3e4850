"""The subcommands: each translates its options, calls the library and reports."""

from __future__ import annotations

import argparse
import math
import shutil
import sys
import time
from pathlib import Path

from ..errors import ParameterError, SolverError
from ..fs import link_latest, new_run_folder, output_root
from ..progress import silenced
from .options import (
    EXIT_CERTIFICATE,
    EXIT_DISAGREE,
    EXIT_INCOMPLETE,
    EXIT_OK,
    describe,
    label_of,
    params_from,
    settings_from,
)


def _warn(warnings: list[str]) -> None:
    for text in warnings:
        print(f"cotm-bertini: warning: {text}", file=sys.stderr)


def _files_line(folder: Path) -> str:
    files = sorted(p.name for p in folder.iterdir() if p.is_file())
    return f"files in {folder}: {', '.join(files)}"


def solve(args: argparse.Namespace) -> int:
    """`solve`: one parameter set, a run folder under runs/<label>/."""
    from ..api.solutions import solve as solve_params

    start = time.perf_counter()
    params, settings, label = params_from(args), settings_from(args), label_of(args)
    if getattr(args, "scheduler", None) is not None:  # `certify` has none
        settings = settings.replace(scheduler=args.scheduler)
    if getattr(args, "workers", None) is not None:
        settings = settings.replace(workers=args.workers)
    root = output_root(args.out) if args.out else Path("runs") / label
    output_root(root)
    try:
        res = solve_params(params, settings, cache=not args.no_cache, label=label)
    except SolverError as exc:
        folder = getattr(exc, "folder", None)
        if folder is not None:
            kept = new_run_folder(root)
            kept = kept.with_name(kept.name + "-failed")
            shutil.move(str(folder), kept)
            print(f"cotm-bertini: the solver's files are in {kept}", file=sys.stderr)
        raise
    cert = _certify(res) if getattr(args, "certify", False) else None
    folder = res.save(new_run_folder(root), plots=not args.no_plots, command=sys.argv[:])
    link_latest(root, folder)
    _warn(res.warnings)
    head = f"{label} ({describe(params)}): {res.summary}"
    print(folder if args.quiet else f"{head}\n{_files_line(folder)}")
    if res.cache_hit:
        hit = res.record["cache"]
        print(
            f"cache: answered from a solve of {hit['solved']} (key {hit['key']}) in "
            f"{hit['seconds'] * 1e3:.0f} ms; this command took "
            f"{time.perf_counter() - start:.2f} s in all; --no-cache solves again",
            file=sys.stderr,
        )
    if cert is not None:
        print(f"certificate: {cert.statement} ({cert.seconds:.2f} s)")
        if cert.status == "contradiction":
            for text in cert.contradictions:
                print(f"cotm-bertini: certificate: {text}", file=sys.stderr)
    code = _exit_code(res.status, cert)
    # The last line names the status and what its exit code means: run.json is not the only
    # place that says a run is ok. --quiet keeps stdout to the folder, so it goes to stderr.
    print(_status_line(code), file=sys.stderr if args.quiet else sys.stdout)
    return code


# A solve's status (run.json `status`) by its exit code, and what that code means (docs/cli.md).
SOLVE_STATUS = {
    EXIT_OK: ("ok", "every completeness check passed"),
    EXIT_INCOMPLETE: (
        "incomplete",
        "a completeness check failed, equilibria may be missing (the warnings above, run.json)",
    ),
    EXIT_CERTIFICATE: (
        "contradiction",
        "a proof and an independent check disagree (the solver's Morse count, or the "
        "certificate): a bug, see the warnings above",
    ),
}


def _exit_code(status: str, cert) -> int:
    """A solve's exit code: its status (a contradiction 4), overridden by a certificate that
    contradicts the solver (4) or proves less than the rows and completeness (5)."""
    if status == "contradiction" or (cert is not None and cert.status == "contradiction"):
        return EXIT_CERTIFICATE
    if cert is not None and cert.status not in ("proved", "rows proved"):  # rows proved: no
        return EXIT_INCOMPLETE  # completeness claim, and none expected
    return EXIT_OK if status == "ok" else EXIT_INCOMPLETE


def _status_line(code: int) -> str:
    """The last line of a solve: `status ok (exit 0): ...`."""
    status, meaning = SOLVE_STATUS[code]
    return f"status {status} (exit {code}): {meaning}"


def _certify(res):
    """The certificate of a solve (kept on it, even when it contradicts the table)."""
    from ..api.certificates import certify

    return certify(res, strict=False)


def certify(args: argparse.Namespace) -> int:
    """`certify`: solve (or read the cache) and prove the result: `solve --certify`."""
    args.certify = True
    return solve(args)


def _check_points(name: str, start: float, stop: float, points: int | None, suffix: str) -> None:
    """A range needs two points or more, one point needs --from equal to --to (item 2, issue 16)."""
    if points is None:
        raise ParameterError(f"--points{suffix} is required with {name}")
    if points < 1:
        raise ParameterError(f"--points{suffix} {points}: must be >= 1")
    if points == 1 and start != stop:
        raise ParameterError(
            f"--points{suffix} 1 for {name} from {start:g} to {stop:g}: a range needs at least 2 "
            f"points (for one value, give --from{suffix} V --to{suffix} V)"
        )
    if points > 1 and start == stop:
        raise ParameterError(
            f"--from{suffix} {start:g} --to{suffix} {stop:g} for {name}: an empty range cannot "
            f"hold {points} distinct points (use --points{suffix} 1, or widen the range)"
        )


def _sweep_spec_values(
    args: argparse.Namespace, which: str, known: tuple[str, ...] | None = None
) -> tuple[float, ...] | None:
    """The values of --param (or --param2); `known`: a framework's parameter names."""
    from ..continuation.spec import DEFAULT_RANGES, linspace
    from ..params import PARAM_NAMES

    suffix = "2" if which == "param2" else ""
    name = getattr(args, which)
    if name is None:
        for opt in ("start", "stop", "points"):
            if getattr(args, opt + suffix, None) is not None and suffix:
                raise ParameterError(
                    f"--{opt.replace('start', 'from').replace('stop', 'to')}2 "
                    "given without --param2"
                )
        return None
    if name not in (PARAM_NAMES if known is None else known):
        names = " ".join(PARAM_NAMES if known is None else known) or "none"
        raise ParameterError(f"--{which} {name!r}: unknown parameter (known: {names})")
    if suffix and name == args.param:
        raise ParameterError(f"--param2 {name!r}: same as --param")
    start, stop = getattr(args, "start" + suffix), getattr(args, "stop" + suffix)
    points = getattr(args, "points" + suffix)
    if start is None or stop is None:
        if name not in DEFAULT_RANGES:
            flag = "--from" + suffix if start is None else "--to" + suffix
            raise ParameterError(
                f"{flag} is required for --{which} {name} (only "
                f"{', '.join(DEFAULT_RANGES)} have a default range)"
            )
        lo, hi = DEFAULT_RANGES[name]
        start, stop = lo if start is None else start, hi if stop is None else stop
    _check_points(name, start, stop, points, suffix)
    return linspace(name, start, stop, points)


def sweep(args: argparse.Namespace) -> int:
    """`sweep`: a 1-D range or a 2-D grid, resumable; sweep.csv, events.csv, figures."""
    from ..api.sweeps import resume_sweep
    from ..api.sweeps import sweep as sweep_params
    from ..continuation.runner import SPEC_FILE, default_workers
    from ..params import Params

    workers = default_workers() if args.workers is None else args.workers
    if isinstance(workers, int) and workers < 1:
        raise ParameterError(f"--workers {workers}: must be >= 1")
    progress = not args.quiet
    if args.html and args.param2:
        raise ParameterError("--html: a two-parameter sweep is explored as a map (`map --html`)")
    if args.resume and not (Path(args.resume) / SPEC_FILE).is_file():
        raise ParameterError(f"--resume {args.resume!r}: not a sweep folder (no {SPEC_FILE})")
    if args.resume:
        with silenced(args.quiet):  # --quiet: no progress report from any stage
            sw = resume_sweep(args.resume, workers, args.scheduler, progress, sys.argv[:])
    else:
        base = params_from(args)
        known = None if isinstance(base, Params) else tuple(base.values)
        values = _sweep_spec_values(args, "param", known)
        values2 = _sweep_spec_values(args, "param2", known)
        with silenced(args.quiet):
            sw = sweep_params(
                base, args.param, values, settings_from(args), param2=args.param2,
                values2=values2, workers=workers, scheduler=args.scheduler,
                out=output_root(args.out), progress=progress, command=sys.argv[:],
                certify=args.certify,
            )  # fmt: skip
    figures = [] if args.no_plots else sw.plot(show_all=args.all)
    if args.html:
        figures.append(sw.explore())
    rec, stats = sw.record, sw.record["stats"]
    print(
        f"{rec['rows']} rows at {rec['points']} points ({stats['skipped']} resumed), "
        f"{rec['events']} events, {stats['seconds']:.1f} s solving"
    )
    names = ", ".join(p.name for p in figures)
    print(
        f"files: {sw.folder}/sweep.csv, events.csv, columns.md, run.json"
        + (f", {names}" if names else "")
    )
    if sw.status != "ok":
        print(
            f"cotm-bertini: warning: {len(rec['incomplete_points'])} points failed a "
            "completeness check (column status); equilibria may be missing there",
            file=sys.stderr,
        )
        return EXIT_INCOMPLETE
    return EXIT_OK


def _verify_text(label: str, res, results) -> str:
    c = res.counts
    lines = [
        f"{label}: Bertini finds {c['distinct_solutions']} distinct finite solutions "
        f"({c['real']} real, {c['physical']} physical)"
    ]
    width = max(len(r.route) for r in results)
    for r in results:
        verdict = {True: "agrees", False: "DISAGREES", None: "n/a"}[r.agrees]
        gap = (
            ""
            if r.max_disagreement_deg != r.max_disagreement_deg
            else (f", max gap {r.max_disagreement_deg:.1e} deg")
        )
        note = f" ({r.note})" if r.note else ""
        lines.append(f"  {r.route:<{width}}  {verdict:<9} {r.found}{gap}{note}")
    bad = [r.route for r in results if r.agrees is False]
    lines.append("all routes agree" if not bad else f"disagreement: {', '.join(bad)}")
    return "\n".join(lines)


def verify(args: argparse.Namespace) -> int:
    """`verify`: the independent routes against the solver's solutions."""
    from dataclasses import asdict

    from ..analysis.verify import verify as verify_routes
    from ..api.solutions import solve as solve_params
    from ..fs import write_json
    from ..routes.choice import check_route

    params, label = params_from(args), label_of(args)
    settings = settings_from(args)
    check_route(params, settings, "verify")  # before any folder
    output = output_root(args.out) if args.out else None
    res = solve_params(params, settings, label=label)
    results = verify_routes(params, res.table, seed=args.seed or 1)
    text = _verify_text(f"{label} ({describe(params)})", res, results)
    print(text)
    ok = not any(r.agrees is False for r in results)
    if output is not None:
        write_json(
            output / "verify.json",
            {
                "label": label,
                "ok": ok,
                "parameters": params.as_dict(),
                "counts": res.counts,
                "routes": [asdict(r) for r in results],
                "report": text,
            },
        )
        print(f"file: {output / 'verify.json'}")
    return EXIT_OK if ok else EXIT_DISAGREE


def paper(args: argparse.Namespace) -> int:
    """`paper`: Tables 2-4 of the paper matched to our solutions, with and without k2/k1."""
    from ..paper.compare import compare_with_paper

    out = output_root(args.out)
    verdict = compare_with_paper(out, seed=args.seed)
    print(verdict)
    return EXIT_OK


def params(args: argparse.Namespace) -> int:
    """`params`: the parameter set a command line describes (Table 1 by default), as TOML; for
    a framework also what its first solve will cost (api.costs), as TOML comments."""
    from ..params import PARAM_MEANING, PARAM_UNITS, Params

    p = params_from(args)  # exactly the set `solve` would solve
    if not isinstance(p, Params):
        from ..api.costs import cost

        for name, value in p.as_dict().items():
            print(f"{name} = {value!r}")
        for line in cost(p, settings_from(args)).lines():  # TOML comments: still a TOML file
            print(line)
        return EXIT_OK
    given = [f"--{n}" for n in ("seed", "generic") if getattr(args, n, None) is not None]
    if given:  # they decide a framework's cost statement; the paper's mechanism prints none
        raise ParameterError(f"{', '.join(given)}: only with --framework (a first solve's work)")
    for name, value in p.as_dict().items():
        print(f"{name} = {value!r}  # {PARAM_UNITS[name]}, {PARAM_MEANING[name]}")
    return EXIT_OK


def barriers(args: argparse.Namespace) -> int:
    """`barriers`: solve (or take the cached solve), then every saddle's descents and barriers."""
    from ..api.barriers import barriers as find_barriers
    from ..api.solutions import solve as solve_params

    params, settings, label = params_from(args), settings_from(args), label_of(args)
    root = output_root(args.out) if args.out else Path("runs") / f"barriers-{label}"
    output_root(root)
    found = find_barriers(solve_params(params, settings, label=label))
    folder = found.save(new_run_folder(root), plots=not args.no_plots)
    link_latest(root, folder)
    _warn(found.warnings)
    cols = ["saddle_id", "min_a", "min_b", "barrier_a", "barrier_b"]
    pairs = found.pairs[cols]
    print(
        f"{label} ({describe(params)}): {len(found.table)} saddles, "
        f"{len(pairs)} pairs of minima joined"
    )
    print(pairs.to_string(index=False) if len(pairs) else "(no saddle joins two minima)")
    print(_files_line(folder))
    return EXIT_INCOMPLETE if found.warnings else EXIT_OK


def move(args: argparse.Namespace) -> int:
    """`move`: solve at the path's start, follow the state along the path, write the run."""
    from ..api.motion import move as follow_state
    from ..api.solutions import solve as solve_params
    from .options import path_from

    path = path_from(args.path)
    model, settings, label = params_from(args), settings_from(args), label_of(args)
    values = model.as_dict()
    for name, points in path.items():
        given = name in values and any(t.partition("=")[0].strip() == name for t in args.set)
        if given and values[name] != points[0]:
            raise ParameterError(f"--set {name}={values[name]:g}, but --path {name} starts at "
                                 f"{points[0]:g}: the move starts where the path does")  # fmt: skip
    model = model.replace(**{n: p[0] for n, p in path.items() if n in values})
    root = output_root(args.out) if args.out else Path("runs") / f"move-{label}"
    output_root(root)
    with silenced(args.quiet):
        res = solve_params(model, settings, label=label)
        found = follow_state(res, args.state, path, steps=args.steps, progress=not args.quiet)
    folder = found.save(new_run_folder(root), plots=not args.no_plots, html=args.html)
    link_latest(root, folder)
    _warn(found.warnings)
    n = len(found.snaps)
    print(f"{label} ({describe(model)}): state {args.state} followed along "
          f"{found.path.text()}: {n} snap{'' if n == 1 else 's'}")  # fmt: skip
    if len(found.snaps):
        cols = ["snap", *path, "kind", "released"]
        print(found.snaps[cols].to_string(index=False))
    ends, wp, last = found.ends_in, found.path.waypoints, float(found.table.s.iloc[-1])
    if last < found.path.segments:
        print(f"stops at path position {last:.10g} of {found.path.segments} (see the warning)")
    elif ends is not None:
        print(f"ends in state {ends}")
    elif (wp[-1] == wp[0]).all():
        print("ends back at the solve's values in none of its stable states")
    else:
        print("ends at the path's last waypoint (its state: the last row of trajectory.csv)")
    print(_files_line(folder))
    return EXIT_INCOMPLETE if found.warnings else EXIT_OK


def plan(args: argparse.Namespace) -> int:
    """`plan`: solve, map the window, find and check the path from --state to --goal."""
    from ..api.motion import plan as find_plan
    from ..api.solutions import solve as solve_params

    model, settings, label = params_from(args), settings_from(args), label_of(args)
    (x, xr), (y, yr) = _map_axes(args, model)
    workers = _workers(args)
    root = output_root(args.out) if args.out else Path("runs") / f"plan-{label}"
    output_root(root)
    with silenced(args.quiet):
        res = solve_params(model, settings, label=label)
        found = find_plan(res, args.state, args.goal, (x, xr, y, yr), points=args.points,
                          settings=settings, workers=workers, progress=not args.quiet)  # fmt: skip
    folder = found.save(new_run_folder(root), plots=not args.no_plots, html=args.html)
    link_latest(root, folder)
    print(f"{label} ({describe(model)}): from state {args.state} to {args.goal} over {x} "
          f"{xr[0]:g}..{xr[1]:g}, {y} {yr[0]:g}..{yr[1]:g}: {found.status}")  # fmt: skip
    if found.status == "unreachable":
        print("unreachable within the window: no path over its grid ends in the goal")
    else:
        print(found.path.to_string(index=False))
        print(f"{found.record['snaps']} snaps on the way; the move along it ends in state "
              f"{found.record['move_ends_in']}")  # fmt: skip
    print(_files_line(folder))
    return EXIT_INCOMPLETE if found.status == "incomplete" else EXIT_OK


def _workers(args: argparse.Namespace) -> int:
    """--workers, or one per core; refused below 1."""
    from ..backends.pools import default_workers

    workers = default_workers() if args.workers is None else args.workers
    if workers < 1:
        raise ParameterError(f"--workers {workers}: must be >= 1")
    return workers


def _map_axes(args: argparse.Namespace, model) -> tuple[tuple, tuple]:
    """((x, (from, to)), (y, (from, to))) of `map`: the paper's free lengths (0 to 14 m by
    default), or two parameters of a framework, named with their ranges."""
    from ..catastrophe.maps import FREE_LENGTHS, PAPER_WINDOW
    from ..params import Params

    if isinstance(model, Params):
        x, y = args.param or FREE_LENGTHS[0], args.param2 or FREE_LENGTHS[1]
        if {x, y} != set(FREE_LENGTHS):
            raise ParameterError(
                f"--param {x} --param2 {y}: the map is over the free lengths, "
                "so the two axes must be L01 and L02"
            )
        ends = [args.start, args.stop, args.start2, args.stop2]
        ends = [d if v is None else v for v, d in zip(ends, PAPER_WINDOW * 2, strict=True)]
        return (x, tuple(ends[:2])), (y, tuple(ends[2:]))
    known = " ".join(model.values) or "none"
    axes = []
    for which, suffix in (("param", ""), ("param2", "2")):
        name = getattr(args, which)
        if name is None:
            raise ParameterError(
                f"--{which} is required with --framework (its parameters: {known})"
            )
        if name not in model.values:
            raise ParameterError(
                f"--{which} {name!r}: not a parameter of framework {model.name!r} (known: {known})"
            )
        ends = getattr(args, "start" + suffix), getattr(args, "stop" + suffix)
        for flag, v in zip(("--from", "--to"), ends, strict=True):
            if v is None:
                raise ParameterError(f"{flag}{suffix} is required for --{which} {name}")
        axes.append((name, ends))
    if axes[0][0] == axes[1][0]:
        raise ParameterError(f"--param2 {axes[1][0]!r}: same as --param")
    return axes[0], axes[1]


def design_map(args: argparse.Namespace) -> int:
    """`map`: fold curves and stable-count regions over two parameters (the paper's free
    lengths, or any two of a framework's)."""
    from ..api.maps import SWEEP_FOLDER
    from ..api.maps import design_map as make_map
    from ..params import Params

    model = params_from(args)
    (x, xr), (y, yr) = _map_axes(args, model)
    workers = _workers(args)
    if args.points < 2:
        raise ParameterError(f"--points {args.points}: a map needs at least 2 points a side")
    root = output_root(args.out)
    with silenced(args.quiet):  # --quiet: no progress report from any stage
        found = make_map(
            model, x, xr, y, yr, points=args.points, settings=settings_from(args),
            workers=workers, progress=not args.quiet, grid=args.grid,
        )  # fmt: skip
    folder = found.save(new_run_folder(root), plots=not args.no_plots, html=args.html)
    link_latest(root, folder)
    counts = found.regions.stable.value_counts().sort_index()
    spread = ", ".join(f"{n} stable: {c} points" for n, c in counts.items())
    rec, unit, (x, y) = found.record, " m" if isinstance(model, Params) else "", found.axes
    (lo1, hi1), (lo2, hi2) = rec["window"][x], rec["window"][y]
    print(
        f"map: in the window {x} {lo1:g}..{hi1:g}{unit}, {y} {lo2:g}..{hi2:g}{unit}: "
        f"{len(found.folds)} fold points on {rec['fold_curves']} pieces, "
        f"{len(found.cusps)} cusps; {spread}"
    )
    if "unexplained_changes" in rec:
        print(
            f"stable-count changes between grid neighbours: {rec['count_changes']}, "
            f"{rec['unexplained_changes']} not explained by a fold curve or cable switch"
        )
    chart = rec.get("chart")
    if chart:
        lost, morse = chart["propagation"]["lost_branches"], chart["morse_failed"]
        print(f"grid by continuation: {chart['anchors_proved']} of {len(chart['anchors'])} "
              f"anchors proved; {lost} branches lost; {morse} grid points fail the Morse sum; "
              f"{chart['not_proved']}")  # fmt: skip
    print(_files_line(folder))
    print(f"the 2-D sweep behind regions.csv: {folder / SWEEP_FOLDER} (sweep.csv, points.bin)")
    if rec.get("unexplained_changes"):
        _warn([f"{rec['unexplained_changes']} stable-count changes unexplained (run.json)"])
    return EXIT_OK if found.status == "ok" else EXIT_INCOMPLETE


def design(args: argparse.Namespace) -> int:
    """`design`: the free lengths holding a pose, printed (and one CSV row with --out)."""
    import pandas as pd

    from ..analysis.design.free_lengths import design as design_pose
    from ..fs import write_csv

    params = params_from(args)
    out = Path(args.out) if args.out else None
    if out is not None and out.suffix.lower() != ".csv":
        raise ParameterError(f"--out must name a .csv file, got {args.out!r}")
    for flag in ("gamma1", "gamma2", "L01", "L02"):
        value = getattr(args, flag)
        if value is not None and not math.isfinite(value):
            raise ParameterError(f"--{flag} {value!r}: must be a finite number")
    dsg = design_pose(params, args.gamma1, args.gamma2, L01=args.L01, L02=args.L02)
    print(dsg.as_toml())
    if out is not None:
        output_root(out.parent if str(out.parent) else Path("."))
        write_csv(out, pd.DataFrame([dsg.as_dict()]))
        print(f"-> {out}")
    return EXIT_OK
