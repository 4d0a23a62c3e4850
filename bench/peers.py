"""Peers side by side on case 3 (Table 1, L01 = L02 = 11.5 m): one polynomial system, five solvers.

- ours, end to end: `cotm-bertini solve case3 --no-cache --no-plots --quiet` as a subprocess
  (interpreter start, imports, parameter homotopy, classification, run folder), median of 3;
- bare bertini2: the `bertini2` binary on the rendered total-degree input, engine environment;
- PHCpack: `phc -b` via `phc.solve_phc(system, seed=1)` (wall time of the call);
- Bertini 2 in-process ab initio: `bertini.nag_algorithm.ZeroDimSolver` on the INPUT section;
- ours, parameter homotopy alone: `homotopy.solve_target` from the cached generic set.

Counts: distinct finite / real / physical solutions after the package's classification of each
solver's finite endpoints (the end-to-end run's counts are read from its run.json).

Usage: .venv/bin/python bench/peers.py
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from benchlib import match, median, run_bertini2, show, write_csv

CASE = "case3"
REPEATS = 3


def _counts(table: pd.DataFrame, reference: pd.DataFrame | None) -> dict:
    out = {
        "distinct_finite": len(table),
        "real": int(table["is_real"].sum()),
        "physical": int(table["physical"].sum()),
    }
    if reference is not None:
        out["missed"] = match(reference, table[table["physical"]])["missed"]
    return out


def cli_end_to_end(repeats: int = REPEATS) -> tuple[list[float], pd.DataFrame]:
    """Wall times of the user's command and the solutions.csv of its last run."""
    exe = str(Path(sys.executable).with_name("cotm-bertini"))
    walls = []
    with tempfile.TemporaryDirectory(prefix="bench-peers-") as tmp:
        for k in range(repeats):
            cmd = [exe, "solve", CASE, "--no-cache", "--no-plots", "--quiet"]
            cmd += ["--out", f"{tmp}/{k}"]
            start = time.perf_counter()
            proc = subprocess.run(cmd, capture_output=True, text=True, check=True)
            walls.append(time.perf_counter() - start)
            folder = Path(proc.stdout.strip().splitlines()[-1])
        table = pd.read_csv(folder / "solutions.csv")
    return walls, table


def bare_bertini2(params) -> tuple[float, object]:
    """bertini2 on the total-degree input the package renders (default config)."""
    from cotm_bertini.backends.parse import read_output
    from cotm_bertini.backends.render import render_input
    from cotm_bertini.model.compiled import polynomial_system
    from cotm_bertini.settings import Settings

    text = render_input(polynomial_system(params), Settings(seed=1, engine="cli"), params.as_dict())
    with tempfile.TemporaryDirectory(prefix="bench-bare-") as tmp:
        seconds = run_bertini2(text, Path(tmp) / "run")
        endpoints = read_output(Path(tmp) / "run").endpoints
    return seconds, endpoints


def phcpack(params) -> tuple[float, object, str]:
    """phc -b through the package's wrapper, timed around the call."""
    from cotm_bertini.backends.phc import solve_phc
    from cotm_bertini.model.compiled import polynomial_system

    system = polynomial_system(params)
    start = time.perf_counter()
    res = solve_phc(system, seed=1)
    seconds = time.perf_counter() - start
    note = f"{res.root_count} paths ({res.start_system.lower()})"
    return seconds, res.endpoints, note


def zero_dim_solver(params) -> tuple[float, object, str]:
    """Bertini 2's in-process ab-initio solver on the INPUT section (total degree)."""
    import bertini
    from bertini import nag_algorithm as na

    from cotm_bertini.backends.endpoints import Endpoints
    from cotm_bertini.backends.homotopy import endpoint_record
    from cotm_bertini.backends.render import render_system
    from cotm_bertini.model.compiled import polynomial_system

    bertini.recording(False)
    system = polynomial_system(params)
    bertini.random.set_random_seed(1)
    start = time.perf_counter()
    solver = na.ZeroDimSolver(bertini.parse.system(render_system(system)))
    solver.solve(show_progress=False)
    seconds = time.perf_counter() - start
    meta, pts = solver.solution_metadata(), solver.all_solutions()
    keep = [
        i
        for i, m in enumerate(meta)
        if m.is_finite and str(m.endgame_success_code).endswith("Success")
    ]
    rows = [endpoint_record(i, meta[i], pts[i]) for i in keep]
    endpoints = Endpoints.from_records(system.variables, rows)
    return seconds, endpoints, f"{len(meta)} paths, {len(keep)} finite"


def parameter_homotopy(params, repeats: int = REPEATS) -> tuple[list[float], object, str]:
    """target.solve_target alone (generic set from the disk cache), median of `repeats`."""
    from cotm_bertini.backends.target import solve_target
    from cotm_bertini.model.compiled import parametric_system

    ps = parametric_system(params.zfl)
    solve_target(ps, params)  # warm: generic set loaded (or solved) and bertini imported
    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        solved = solve_target(ps, params)
        walls.append(time.perf_counter() - start)
    info = solved.info
    return walls, solved.endpoints, f"{info['tracked']} paths tracked ({info['method']})"


def run(reference: dict[str, pd.DataFrame] | None = None) -> pd.DataFrame:
    """The peers table: printed, written to peers.csv, returned."""
    from cotm_bertini.analysis.classify import classify
    from cotm_bertini.params import make_params

    params = make_params(CASE)
    ref = reference[CASE] if reference else None
    rows = []

    walls, table = cli_end_to_end()
    rows.append(
        {
            "solver": "ours end to end (cotm-bertini solve, subprocess)",
            "seconds": median(walls),
            "runs": len(walls),
            **_counts(table, ref),
            "note": "wall " + ", ".join(f"{w:.2f}" for w in walls) + " s",
        }
    )
    print(f"  end to end: {median(walls):.2f} s", flush=True)

    seconds, endpoints = bare_bertini2(params)
    table = classify(params, endpoints)
    rows.append(
        {
            "solver": "bare bertini2 (subprocess, total degree)",
            "seconds": seconds,
            "runs": 1,
            **_counts(table, ref),
            "note": f"192 paths, {len(endpoints)} finite endpoints",
        }
    )
    print(f"  bertini2: {seconds:.2f} s", flush=True)

    seconds, endpoints, note = phcpack(params)
    table = classify(params, endpoints)
    rows.append({"solver": "PHCpack phc -b", "seconds": seconds, "runs": 1, **_counts(table, ref)})
    rows[-1]["note"] = note
    print(f"  phc: {seconds:.2f} s", flush=True)

    seconds, endpoints, note = zero_dim_solver(params)
    table = classify(params, endpoints)
    rows.append(
        {
            "solver": "Bertini 2 in-process ZeroDimSolver",
            "seconds": seconds,
            "runs": 1,
            **_counts(table, ref),
            "note": note,
        }
    )
    print(f"  ZeroDimSolver: {seconds:.2f} s", flush=True)

    walls, endpoints, note = parameter_homotopy(params)
    table = classify(params, endpoints)
    rows.append(
        {
            "solver": "ours, parameter homotopy alone (solve_target)",
            "seconds": median(walls),
            "runs": len(walls),
            **_counts(table, ref),
            "note": note,
        }
    )
    frame = pd.DataFrame(rows)
    ours = frame.loc[0, "seconds"]
    frame.insert(2, "x_ours_end_to_end", frame["seconds"] / ours)
    show(
        "4. Peers on case 3, same system (seconds: wall; ratio to our end-to-end time)",
        frame,
        {"seconds": ".2f", "x_ours_end_to_end": ".2f", "missed": ".0f"},
    )
    print("counts: distinct finite / real / physical after the package's classification")
    write_csv(frame, "peers")
    return frame


if __name__ == "__main__":
    from reference import run as reference_run

    run(reference_run())
