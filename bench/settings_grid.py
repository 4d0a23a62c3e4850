"""Run time against error over a grid of solver settings, cases 1-3, and the Pareto plot.

Each point is `pipeline.solve_in` end to end in a throw-away folder (what `pipeline.solve` does),
timed as a whole; Bertini's own seconds come from the Solved record. Error: the largest angle
distance from a reference equilibrium (bench/reference.py) to the nearest physical row found.

Where the package's parser cannot read bertini2's output (multihomogeneous start: one
homogenising variable per group; SecurityLevel 1: main_data also lists the paths at infinity), the
row says so and the bench reads Bertini's finite_solutions from the same folder and classifies
them with the package's `classify` (its time is included in the wall time).

Usage: .venv/bin/python bench/settings_grid.py [--quick]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from benchlib import (
    CASES,
    RESULTS,
    bertini_seconds_from_files,
    endpoints_from_finite_solutions,
    match,
    median,
    multihomogeneous_bezout,
    raw_error,
    show,
    write_csv,
)

# bertini2 4.0.0, measured on this 2-core machine: MPType 1 at 96 bits takes 5.7 s on case 1
# (8 paths) and 408 s on case 2 (48 paths); MPType 0 ~35 s and multihomogeneous ~45 s on case 3.
ALL = CASES


@dataclass(frozen=True)
class Point:
    """One setting of the grid and the cases it runs on."""

    name: str
    label: str
    settings: dict
    cases: tuple[str, ...] = ALL
    why: str = ""
    slow: bool = False  # --quick runs it on cases 1-2 only


GRID = (
    Point("homotopy", "engine homotopy (default)", {}),
    Point("cli_mp2", "cli MPType 2 (default tol)", {"engine": "cli"}),
    Point(
        "cli_mp2_tight",
        "cli MPType 2 tight",
        {
            "engine": "cli",
            "tracktol_before_eg": 1e-7,
            "tracktol_during_eg": 1e-8,
            "final_tol": 1e-13,
        },
    ),
    Point(
        "cli_mp1_96",
        "cli MPType 1 (Precision 96)",
        {"engine": "cli", "mptype": 1, "precision": 96},
        ("case1",),
        "case 2 took 408 s (48 paths) in bertini2 4.0.0: over the 10-minute budget",
    ),
    Point("cli_mp0", "cli MPType 0", {"engine": "cli", "mptype": 0}, slow=True),
    Point("cli_sl1", "cli SecurityLevel 1", {"engine": "cli", "security_level": 1}),
    Point(
        "cli_mhom",
        "cli multihomogeneous",
        {"engine": "cli", "variable_groups": "multihomogeneous"},
        slow=True,
    ),
)

MARKERS = {
    "homotopy": "*",
    "cli_mp2": "o",
    "cli_mp2_tight": "s",
    "cli_mp1_96": "D",
    "cli_mp0": "v",
    "cli_sl1": "^",
    "cli_mhom": "P",
}
COLOURS = {"case1": "tab:blue", "case2": "tab:orange", "case3": "tab:green"}


@dataclass
class Outcome:
    """One (case, setting) measurement and the solutions table it produced."""

    row: dict
    solutions: pd.DataFrame = field(repr=False)


def _solve_once(params, settings, paths_if_unknown: int) -> tuple[dict, pd.DataFrame, pd.DataFrame]:
    """One timed solve: (measurements, solutions table, raw finite endpoints)."""
    from cotm_bertini.analysis.classify import classify
    from cotm_bertini.backends.parse import ParseError
    from cotm_bertini.point import solve_point

    with tempfile.TemporaryDirectory(prefix="bench-grid-") as tmp:
        folder = Path(tmp) / "run"
        start = time.perf_counter()
        try:
            solved = solve_point(params, settings, folder=folder)
        except ParseError as exc:
            # Read what Bertini wrote, as the pipeline would have; classify with the package.
            variables = _variables(params)
            endpoints = endpoints_from_finite_solutions(folder, variables)
            table = classify(params, endpoints)
            wall = time.perf_counter() - start
            note = f"pipeline ParseError: {str(exc).split(': ', 1)[-1]}"
            info = {
                "wall_s": wall,
                "bertini_s": bertini_seconds_from_files(folder),
                "paths": paths_if_unknown,
                "finite_endpoints": len(endpoints),
                "status": "parse fallback",
                "note": note,
            }
            return info, table, endpoints
        wall = time.perf_counter() - start
    homotopy = solved.details.get("homotopy")
    info = {
        "wall_s": wall,
        "bertini_s": homotopy["seconds"] if homotopy else solved.details["bertini_seconds"],
        "paths": solved.counts["paths_tracked"],
        "finite_endpoints": solved.counts["finite_endpoints"],
        "status": "ok",
        "note": homotopy["method"] if homotopy else "",
    }
    return info, solved.table, solved.endpoints


def _variables(params) -> tuple[str, ...]:
    from cotm_bertini.model.compiled import polynomial_system

    return polynomial_system(params).variables


def _paths(params, settings) -> int:
    """Paths Bertini tracks for a CLI solve: total degree, or the multihomogeneous Bezout number."""
    from cotm_bertini.backends.render import variable_groups
    from cotm_bertini.model.compiled import polynomial_system

    system = polynomial_system(params)
    return multihomogeneous_bezout(system, variable_groups(system, settings))


def measure(case: str, point: Point, reference: pd.DataFrame, repeats: int = 3) -> Outcome:
    """Solve `case` with the point's settings; repeat (median) when one solve takes < 2 s."""
    from cotm_bertini.params import make_params
    from cotm_bertini.settings import Settings

    params = make_params(case)
    settings = Settings(seed=1, **point.settings)
    paths = _paths(params, settings)
    info, table, endpoints = _solve_once(params, settings, paths)
    walls, bertinis = [info["wall_s"]], [info["bertini_s"]]
    while info["wall_s"] < 2.0 and len(walls) < repeats:
        again, _, _ = _solve_once(params, settings, paths)
        walls.append(again["wall_s"])
        bertinis.append(again["bertini_s"])
    phys = table[table["physical"]]
    row = {
        "case": case,
        "setting": point.name,
        "label": point.label,
        "wall_s": median(walls),
        "bertini_s": median(bertinis),
        "runs": len(walls),
        "paths": info["paths"],
        "finite_endpoints": info["finite_endpoints"],
        "distinct": len(table),
        "real": int(table["is_real"].sum()),
        "physical": len(phys),
        **{k: v for k, v in match(reference, phys).items() if k != "found"},
        "raw_err_deg": raw_error(reference, endpoints),
        "status": info["status"],
        "note": info["note"],
    }
    return Outcome(row, table)


def warm_up() -> pd.DataFrame:
    """First solves of the process (imports, engine start, generic sets): timed, not graded."""
    from cotm_bertini.params import make_params
    from cotm_bertini.point import solve_point
    from cotm_bertini.settings import Settings

    rows = []
    for case in CASES:
        start = time.perf_counter()
        solve_point(make_params(case), Settings(seed=1))
        rows.append({"case": case, "first_solve_s": time.perf_counter() - start})
    start = time.perf_counter()
    solve_point(make_params("case1"), Settings(seed=1, engine="cli"))
    rows.append({"case": "case1 (cli)", "first_solve_s": time.perf_counter() - start})
    return pd.DataFrame(rows)


def run(reference: dict[str, pd.DataFrame], quick: bool = False) -> dict[tuple[str, str], Outcome]:
    """The whole grid: printed, written to settings_grid.csv, plotted; outcomes by (case, name)."""
    cold = warm_up()
    outcomes: dict[tuple[str, str], Outcome] = {}
    skipped = []
    for case in CASES:
        for point in GRID:
            cases = point.cases
            if quick and point.slow:
                cases = ("case1", "case2")
            if case not in cases:
                skipped.append(f"{point.name} {case}" + (f" ({point.why})" if point.why else ""))
                continue
            outcomes[case, point.name] = measure(case, point, reference[case])
            r = outcomes[case, point.name].row
            print(
                f"  {case} {point.name:<14} {r['wall_s']:7.2f} s  physical {r['physical']:2d}  "
                f"worst {r['worst_err_deg']:.1e} deg",
                flush=True,
            )
    table = pd.DataFrame([o.row for o in outcomes.values()])
    show(
        "2. Run time against error (wall: pipeline end to end, median of up to 3; "
        f"bertini: solver only; error vs reference, match within {1e-6:g} deg)",
        table.drop(columns=["label", "note"]),
        {"wall_s": ".2f", "bertini_s": ".2f", "worst_err_deg": ".1e", "raw_err_deg": ".1e"},
    )
    notes = sorted({r["note"] for r in (o.row for o in outcomes.values()) if "Error" in r["note"]})
    if notes:
        print(
            "parse fallback: the package's parser failed, the bench read Bertini's "
            "finite_solutions from the run folder and classified them with the package:"
        )
        print("\n".join(f"  {n}" for n in notes))
    print("paths: for cli multihomogeneous, the m-hom Bezout number (bertini2 prints no count)")
    show("first solves of the process (not graded)", cold, {"first_solve_s": ".2f"})
    if skipped:
        print("not run: " + "; ".join(skipped))
    write_csv(table, "settings_grid")
    plot(table, RESULTS / "time_vs_error.png")
    return outcomes


def pareto(points: np.ndarray) -> np.ndarray:
    """Indices of the points (time, error) not dominated by another, sorted by time."""
    order = np.lexsort((points[:, 1], points[:, 0]))
    front, best = [], np.inf
    for i in order:
        if points[i, 1] < best:
            front.append(i)
            best = points[i, 1]
    return np.array(front, dtype=int)


ERROR_FLOOR = 1e-16  # errors below this are drawn at it (log axis)


PANELS = (
    ("worst_err_deg", "reported equilibria (after the package's Newton refinement)"),
    ("raw_err_deg", "raw solver endpoints (before refinement)"),
)


def plot(table: pd.DataFrame, path: Path) -> None:
    """Log-log time against worst error: one marker per setting and case, Pareto front per case;
    left the reported equilibria, right the raw endpoints the solver returned."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    fig = Figure(figsize=(13, 5.8))
    FigureCanvasAgg(fig)
    labels = dict(zip(table["setting"], table["label"], strict=False))
    for k, (column, title) in enumerate(PANELS):
        ax = fig.add_subplot(1, 2, k + 1)
        for case, group in table.groupby("case"):
            err = group[column].to_numpy(dtype=float)
            err = np.where(np.isfinite(err), np.maximum(err, ERROR_FLOOR), 1e3)
            wall = group["wall_s"].to_numpy(dtype=float)
            for (_, r), e in zip(group.iterrows(), err, strict=True):
                ax.scatter(
                    r["wall_s"],
                    e,
                    marker=MARKERS[r["setting"]],
                    s=130 if r["setting"] == "homotopy" else 60,
                    color=COLOURS[case],
                    edgecolor="black" if r["missed"] else "none",
                    linewidth=1.5,
                    zorder=3,
                )
            front = pareto(np.column_stack([wall, err]))
            xs = np.append(wall[front], wall.max() * 1.3)  # the front runs on to the slowest
            ys = np.append(err[front], err[front][-1])
            ax.step(xs, ys, where="post", color=COLOURS[case], ls="--", lw=1.2)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time of pipeline.solve (s)")
        ax.set_ylabel("worst angle error against the 40-digit reference (deg)")
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
    handles = [
        Line2D([], [], ls="", marker=MARKERS[s], color="grey", label=labels[s], markersize=8)
        for s in MARKERS
        if s in labels
    ]
    handles += [
        Line2D([], [], ls="--", color=c, label=f"{k} Pareto front") for k, c in COLOURS.items()
    ]
    fig.axes[1].legend(handles=handles, fontsize=8, loc="best")
    fig.suptitle("CoTM equilibria: run time against error (black edge: equilibria missed)")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    print(f"-> {path.relative_to(RESULTS.parent.parent)}")


def main() -> None:
    from reference import run as reference_run

    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true", help="slow settings on cases 1-2 only")
    args = ap.parse_args()
    run(reference_run(), quick=args.quick)


if __name__ == "__main__":
    main()
