"""Speed side by side (issue 9): the paper's L01 sweep by four routes, a 2-D grid, one solve.

1. The same work -- every equilibrium at N points of the paper's sweep (L01 from 0 to 12 m,
   L02 = 0, Table 1) -- by four routes: ours (`cb.sweep`, 2 workers, points continued from their
   neighbours), the bare `bertini2` command per point (total degree), Bertini 2 in-process ab
   initio (`ZeroDimSolver`) per point, and PHCpack `phc -b` per point. Ours is run at every N;
   the three peers cost ~0.2-1 s a point, so they are timed on a sample of points and their
   time for N points is N times the sample mean (marked `sampled`). Beside every time: the paths
   tracked per point, the cost per path, and the worst angle error of the physical equilibria at
   the sample points against 40-digit Newton (bench/reference.py's method), misses counted.
2. The 101 x 101 (L01, L02) grid over (0, 12] x (0, 12] with 2 workers (`--grid`).
3. One solve end to end: `cotm-bertini solve case3 --no-cache --no-plots` as a subprocess,
   median of 5, with the import times of its heavy modules (python -X importtime).
4. `--profile`: cProfile of continued sweep points (the top functions).
6. `--map`: issue 17's map goal: the `make map` command (101 x 101 direct solves over
   [0, 14]^2, fold curves, figures) end to end, with its split (fold curves, the 2-D sweep's
   solving and finishing, the rest) and the CPU time of it and its workers.
5. `--ratios`: issue 17's yardstick, in one run: the CLI sweep of the paper (241 points, 2
   workers, no figures) and the cold `solve case3 --no-cache --no-plots`, each interleaved with a
   bare `bertini2` case-2 solve (total degree, 48 paths), median of `--repeats`; the sweep's time
   split into solving (run.json stats.seconds: worker start-up and the points), finishing
   (branches, events, CSV) and the rest (interpreter, imports, exit); the load average beside.

Benchmarks, not tests: nothing is asserted; targets are printed beside the measurements.
Usage: .venv/bin/python bench/speed.py [--grid] [--profile] [--sample 8] [--ratios [--repeats 5]]
       [--map] [--all]
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
from benchlib import RESULTS, match, median, run_bertini2, show, write_csv

SERIES = (1, 10, 30, 100, 241)
TARGET_SWEEP_S = 2.5
TARGET_GRID_S = 120.0
TARGET_SOLVE_S = 0.3
TARGET_SWEEP_RATIO = 1.6  # issue 17: the CLI sweep in <= 1.6 bare bertini2 case-2 solves
TARGET_OUTSIDE = 0.2  # ... with at most 20 % of it outside solving
TARGET_SOLVE_RATIO = 0.3  # the cold solve in <= 0.3 bare bertini2 case-2 solves
TARGET_MAP_S = 60.0  # issue 17: `make map` (101 x 101) end to end
# The Makefile's `make map`.
MAP_ARGS = "map --param L01 --from 0 --to 14 --param2 L02 --from2 0 --to2 14 --points 101".split()


def sweep_values(n: int) -> np.ndarray:
    """The paper's sweep at n points."""
    return np.linspace(0.0, 12.0, n)


def reference_at(values: np.ndarray) -> dict[float, pd.DataFrame]:
    """40-digit physical equilibria at each L01 (energy route starts, mpmath Newton)."""
    from reference import newton_mp

    from cotm_bertini.analysis.critical_points import critical_points
    from cotm_bertini.params import Params

    out = {}
    for v in values:
        params = Params(L01=float(v))
        rows = [newton_mp(params, c.gamma1_deg, c.gamma2_deg) for c in
                critical_points(params).itertuples(index=False)]  # fmt: skip
        out[float(v)] = pd.DataFrame(rows)
    return out


def ours(n: int, workers: int = 2) -> dict:
    """cb.sweep over n points in a fresh folder: seconds, methods, the table."""
    import cotm_bertini as cb

    with tempfile.TemporaryDirectory(prefix="bench-speed-") as tmp:
        start = time.perf_counter()
        sw = cb.sweep(cb.Params(), "L01", sweep_values(n), workers=workers, out=tmp)
        wall = time.perf_counter() - start
        table = sw.table
        record = sw.record
    firsts = table.groupby("point")["method"].first()
    return {
        "seconds": record["stats"]["seconds"],
        "wall": wall,
        "table": table,
        "lost": record["lost_paths"],
        "methods": firsts.str.split(" \\(").str[0].value_counts().to_dict(),
    }


def _classified(params, endpoints) -> pd.DataFrame:
    from cotm_bertini.analysis.classify import classify

    return classify(params, endpoints)


def bare_bertini2(value: float) -> tuple[float, pd.DataFrame, int]:
    """The bertini2 command on the total-degree input of one point."""
    from cotm_bertini.backends.parse import read_output
    from cotm_bertini.backends.render import render_input
    from cotm_bertini.model.compiled import polynomial_system
    from cotm_bertini.params import Params
    from cotm_bertini.settings import Settings

    params = Params(L01=value)
    system = polynomial_system(params)
    text = render_input(system, Settings(seed=1, engine="cli"), params.as_dict())
    with tempfile.TemporaryDirectory(prefix="bench-bare-") as tmp:
        seconds = run_bertini2(text, Path(tmp) / "run")
        endpoints = read_output(Path(tmp) / "run").endpoints
    return seconds, _classified(params, endpoints), system.total_degree


def in_process_ab_initio(value: float) -> tuple[float, pd.DataFrame, int]:
    """Bertini 2's ZeroDimSolver (total degree) on one point, in process."""
    from cotm_bertini.backends.homotopy import ab_initio
    from cotm_bertini.model.compiled import parametric_system, polynomial_system
    from cotm_bertini.params import Params
    from cotm_bertini.settings import Settings

    params = Params(L01=value)
    ps = parametric_system(params.zfl)
    start = time.perf_counter()
    endpoints, _lost = ab_initio(ps, params, Settings(seed=1))
    seconds = time.perf_counter() - start
    return seconds, _classified(params, endpoints), polynomial_system(params).total_degree


def phcpack(value: float) -> tuple[float, pd.DataFrame, int]:
    """phc -b on one point (seed 1)."""
    from cotm_bertini.backends.phc import solve_phc
    from cotm_bertini.model.compiled import polynomial_system
    from cotm_bertini.params import Params

    params = Params(L01=value)
    start = time.perf_counter()
    res = solve_phc(polynomial_system(params), seed=1)
    seconds = time.perf_counter() - start
    return seconds, _classified(params, res.endpoints), res.root_count


def _errors(tables: dict[float, pd.DataFrame], ref: dict[float, pd.DataFrame]) -> tuple:
    worst, missed = 0.0, 0
    for v, table in tables.items():
        m = match(ref[v], table[table["physical"].astype(bool)])
        worst, missed = max(worst, m["worst_err_deg"]), missed + m["missed"]
    return worst, missed


PEERS = {
    "bare bertini2 (subprocess, total degree)": bare_bertini2,
    "Bertini 2 in-process ab initio (ZeroDimSolver)": in_process_ab_initio,
    "PHCpack phc -b": phcpack,
}


def peer_sample(route, sample: np.ndarray) -> dict:
    """Time one peer route on the sample points: mean seconds a point, paths, tables."""
    seconds, tables, paths = [], {}, 0
    for v in sample:
        s, table, paths = route(float(v))
        seconds.append(s)
        tables[float(v)] = table
    return {"per_point": float(np.mean(seconds)), "paths": paths, "tables": tables}


def series(sample_size: int) -> pd.DataFrame:
    """Section 1: every route at every N, with errors on the sample points."""
    sample = sweep_values(241)[np.linspace(5, 235, sample_size).astype(int)]
    ref = reference_at(sample)
    ours(10)  # warm: generic sets solved or loaded, worker start-up paid once
    rows = []
    for n in SERIES:
        run = ours(n)
        at = {v: g for v, g in run["table"].groupby("L01")}
        tables = {float(v): at[v] for v in sample if n == 241 and v in at}
        worst, missed = _errors(tables, ref) if tables else (np.nan, np.nan)
        rows.append(_row("ours: cb.sweep, 2 workers, continued points", n, run["seconds"],
                         20, worst, missed, "measured", run["methods"], run["lost"]))  # fmt: skip
        print(f"  ours {n:4d} points: {run['seconds']:.2f} s", flush=True)
    for name, route in PEERS.items():
        got = peer_sample(route, sample)
        worst, missed = _errors(got["tables"], ref)
        for n in SERIES:
            rows.append(_row(name, n, n * got["per_point"], got["paths"], worst, missed,
                             f"sampled ({len(sample)} points)", {}, 0))  # fmt: skip
        print(f"  {name}: {got['per_point'] * 1e3:.0f} ms a point", flush=True)
    return pd.DataFrame(rows)


def _row(route, n, seconds, paths, worst, missed, how, methods, lost) -> dict:
    return {
        "route": route,
        "points": n,
        "seconds": seconds,
        "ms_per_point": 1e3 * seconds / n,
        "paths_per_point": paths,
        "us_per_path": 1e6 * seconds / n / paths,
        "worst_err_deg": worst,
        "missed": missed,
        "lost_paths": lost,
        "timing": how,
        "methods": "; ".join(f"{k}: {v}" for k, v in methods.items()),
    }


def plot_series(table: pd.DataFrame, path: Path) -> None:
    """Time per point against the number of points, one line per route (log-log)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 5.5), layout="constrained")
    ax = fig.subplots()
    for route, group in table.groupby("route", sort=False):
        style = "-o" if route.startswith("ours") else "--s"
        ax.plot(group["points"], group["ms_per_point"], style, label=route)
    ax.axhline(1e3 * TARGET_SWEEP_S / 241, color="grey", lw=0.8, ls=":",
               label=f"target: 241 points in {TARGET_SWEEP_S} s")  # fmt: skip
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("points of the paper's L01 sweep")
    ax.set_ylabel("wall time per point (ms)")
    ax.set_title("Every equilibrium at N points: time per point by route (2 cores)")
    ax.legend(fontsize=8)
    RESULTS.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    print(f"-> {path.relative_to(RESULTS.parent.parent)}")


def grid(n: int = 101) -> dict:
    """Section 2: the n x n (L01, L02) grid over (0, 12] x (0, 12], 2 workers."""
    import cotm_bertini as cb

    values = np.linspace(12.0 / n, 12.0, n)
    with tempfile.TemporaryDirectory(prefix="bench-grid-") as tmp:
        sw = cb.sweep(cb.Params(), "L01", values, param2="L02", values2=values, workers=2,
                      out=tmp)  # fmt: skip
        firsts = sw.table.groupby("point")["method"].first()
        record = sw.record
    methods = firsts.str.split(" \\(").str[0].value_counts().to_dict()
    out = {
        "points": n * n,
        "seconds": record["stats"]["seconds"],
        "ms_per_point": 1e3 * record["stats"]["seconds"] / (n * n),
        "lost_paths": record["lost_paths"],
        "status": record["status"],
        **{f"method: {k}": v for k, v in methods.items()},
    }
    show(f"2. {n} x {n} grid over (L01, L02), 2 workers (target {TARGET_GRID_S:.0f} s)",
         pd.DataFrame([out]).T.reset_index().set_axis(["what", "value"], axis=1))  # fmt: skip
    return out


def one_solve(repeats: int = 5) -> dict:
    """Section 3: `cotm-bertini solve case3 --no-cache --no-plots`, median wall, import times."""
    exe = str(Path(sys.executable).with_name("cotm-bertini"))
    walls = []
    with tempfile.TemporaryDirectory(prefix="bench-solve-") as tmp:
        cmd = [exe, "solve", "case3", "--no-cache", "--no-plots", "--quiet", "--out", tmp]
        subprocess.run(cmd, capture_output=True, check=True)  # warm caches
        for _ in range(repeats):
            start = time.perf_counter()
            subprocess.run(cmd, capture_output=True, check=True)
            walls.append(time.perf_counter() - start)
        trace = subprocess.run(
            [sys.executable, "-X", "importtime", "-m", "cotm_bertini.cli", *cmd[1:]],
            capture_output=True, text=True, check=True,
        ).stderr  # fmt: skip
    imports = _import_times(trace, ("numpy", "bertini", "jinja2", "cotm_bertini.point"))
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    bare = time.perf_counter() - start
    out = {"median_s": median(walls), "runs": ", ".join(f"{w:.3f}" for w in walls),
           "python -c pass": bare, **imports}  # fmt: skip
    show(f"3. cotm-bertini solve case3 --no-cache --no-plots (target {TARGET_SOLVE_S} s)",
         pd.DataFrame([out]).T.reset_index().set_axis(["what", "value"], axis=1))  # fmt: skip
    return out


def _import_times(trace: str, names: tuple[str, ...]) -> dict[str, float]:
    """Cumulative import seconds of the named top-level modules from python -X importtime."""
    out = {}
    for line in trace.splitlines():
        parts = [p.strip() for p in line.removeprefix("import time:").split("|")]
        if len(parts) == 3 and parts[2] in names:
            out[f"import {parts[2]} (s)"] = int(parts[1]) / 1e6
    return out


def profile_points(n: int = 101) -> None:
    """Section 4: cProfile of n continued points of the paper's sweep (one process)."""
    import cProfile
    import pstats

    from cotm_bertini.params import Params
    from cotm_bertini.point import solve_point
    from cotm_bertini.settings import Settings

    settings = Settings(threads=1)
    warm = solve_point(Params(L01=0.5), settings).warm
    prof = cProfile.Profile()
    prof.enable()
    for v in np.linspace(0.6, 12.0, n):
        warm = solve_point(Params(L01=float(v)), settings, warm=warm).warm
    prof.disable()
    print(f"\n== 4. Profile of {n} continued points (one process, one thread) ==")
    pstats.Stats(prof).sort_stats("tottime").print_stats(15)


def _bare_case2() -> float:
    """One bare bertini2 solve of case 2's total-degree input: its wall seconds."""
    from cotm_bertini.backends.render import render_input
    from cotm_bertini.model.compiled import polynomial_system
    from cotm_bertini.params import Params
    from cotm_bertini.settings import Settings

    params = Params.case("case2")
    text = render_input(polynomial_system(params), Settings(seed=1, engine="cli"),
                        params.as_dict())  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="bench-bare-") as tmp:
        return run_bertini2(text, Path(tmp) / "run")


def _timed_cli(args: list[str]) -> float:
    exe = str(Path(sys.executable).with_name("cotm-bertini"))
    start = time.perf_counter()
    subprocess.run([exe, *args], capture_output=True, check=True)
    return time.perf_counter() - start


def _cli_sweep() -> dict:
    """The CLI sweep of the paper in a new folder: wall, solving and finishing seconds."""
    import json

    with tempfile.TemporaryDirectory(prefix="bench-sweep-") as tmp:
        wall = _timed_cli(["sweep", "--param", "L01", "--from", "0", "--to", "12",
                           "--points", "241", "--workers", "2", "--no-plots", "--quiet",
                           "--out", tmp])  # fmt: skip
        record = json.loads(next(Path(tmp).glob("sweep-*/run.json")).read_text())
    return {"wall": wall, "solve": record["timings"]["solve"],
            "finish": record["timings"]["finish"]}  # fmt: skip


def _list(values: list[float]) -> str:
    return ", ".join(f"{v:.2f}" for v in values)


def ratios(repeats: int = 5) -> dict:
    """Section 5: the CLI sweep and the cold solve against bare bertini2 case-2 solves, each
    pair run back to back, so that both see the same load."""
    import os

    solve = ["solve", "case3", "--no-cache", "--no-plots", "--quiet"]
    with tempfile.TemporaryDirectory(prefix="bench-solve-") as tmp:
        _timed_cli([*solve, "--out", tmp])  # warm: generic sets, compiled equations
        _cli_sweep()
        load = [os.getloadavg()[0]]
        bare, sweeps, solves = [], [], []
        for _ in range(repeats):
            bare.append(_bare_case2())
            sweeps.append(_cli_sweep())
            bare.append(_bare_case2())
            solves.append(_timed_cli([*solve, "--out", tmp]))
        load.append(os.getloadavg()[0])
    b = median(bare)
    wall = median([s["wall"] for s in sweeps])
    solving = median([s["solve"] for s in sweeps])
    finishing = median([s["finish"] for s in sweeps])
    out = {
        "bare bertini2 case 2 (s, median)": b,
        "CLI sweep, 241 points (s)": wall,
        "  of which solving (stats.seconds)": solving,
        "  of which finishing (branches, events, CSV)": finishing,
        "  of which start-up, imports, exit": wall - solving - finishing,
        "sweep / bare case 2": wall / b,
        "sweep: share outside solving": 1 - solving / wall,
        "cold solve case3 (s)": median(solves),
        "cold solve / bare case 2": median(solves) / b,
        "load average (1 min) before, after": f"{load[0]:.2f}, {load[1]:.2f}",
        "runs": f"sweeps {_list([s['wall'] for s in sweeps])}; solves {_list(solves)}; "
        f"bare {_list(bare)}",
    }
    show(f"5. Same-run ratios (targets: sweep <= {TARGET_SWEEP_RATIO} bare case-2 solves, "
         f"<= {TARGET_OUTSIDE:.0%} outside solving; cold solve <= {TARGET_SOLVE_RATIO})",
         pd.DataFrame([out]).T.reset_index().set_axis(["what", "value"], axis=1))  # fmt: skip
    return out


def make_map() -> dict:
    """Section 6: `make map` end to end in a fresh cache of sweeps (the generic sets and the
    compiled equations kept), its split, and the CPU seconds of it and its workers."""
    import json
    import os
    import resource
    import shutil

    from cotm_bertini.fs import cache_root

    shutil.rmtree(cache_root() / "sweeps", ignore_errors=True)  # solve every point again
    exe = str(Path(sys.executable).with_name("cotm-bertini"))
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="bench-map-") as tmp:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        subprocess.run([exe, *MAP_ARGS, "--out", tmp], capture_output=True, check=False)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        folder = next(p for p in Path(tmp).iterdir() if p.is_dir() and p.name != "latest")
        record = json.loads((folder / "run.json").read_text())
        sweep = json.loads((folder / record["sweep_folder"] / "run.json").read_text())
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    t = record["timings"]
    out = {
        "make map, end to end (s)": wall,
        "  fold curves and their proof (s)": t["folds"],
        "  2-D sweep: solving 10,201 points (s)": sweep["timings"]["solve"],
        "  2-D sweep: finishing (sweep.csv) (s)": sweep["timings"]["finish"],
        "  the rest: start-up, counts, figures, files (s)": wall - t["folds"] - t["regions"],
        "CPU seconds (all processes)": cpu,
        "ms of CPU a point": 1e3 * cpu / 10201,
        "methods (rows)": "; ".join(f"{k}: {v}" for k, v in sweep["methods"].items()),
        "status": sweep["status"],
        "load average (1 min) before, after": f"{load:.2f}, {os.getloadavg()[0]:.2f}",
    }
    show(f"6. make map, 101 x 101 (target {TARGET_MAP_S:.0f} s)",
         pd.DataFrame([out]).T.reset_index().set_axis(["what", "value"], axis=1))  # fmt: skip
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--grid", action="store_true", help="also the 101 x 101 grid (~2 min)")
    ap.add_argument("--profile", action="store_true", help="also a profile of sweep points")
    ap.add_argument("--sample", type=int, default=8, help="points timed for the peers")
    ap.add_argument("--ratios", action="store_true", help="only section 5 (issue 17 ratios)")
    ap.add_argument("--repeats", type=int, default=5, help="repeats of section 5")
    ap.add_argument("--map", action="store_true", help="only section 6 (make map, ~3 min)")
    ap.add_argument("--all", action="store_true", help="sections 1, 3, 5 and 6 in one run")
    args = ap.parse_args()
    if (args.ratios or args.map) and not args.all:
        if args.ratios:
            ratios(args.repeats)
        if args.map:
            make_map()
        return
    table = series(args.sample)
    show("1. The paper's sweep by four routes (2 cores)", table.drop(columns=["methods"]),
         {"seconds": ".3g", "ms_per_point": ".3g", "us_per_path": ".0f",
          "worst_err_deg": ".1e"})  # fmt: skip
    print("ours, methods at 241 points: " + table.loc[table["points"] == 241, "methods"].iloc[0])
    write_csv(table, "speed")
    plot_series(table, RESULTS / "speed.png")
    one_solve()
    if args.grid:
        grid()
    if args.profile:
        profile_points()
    if args.all:
        ratios(args.repeats)
        make_map()


if __name__ == "__main__":
    main()
