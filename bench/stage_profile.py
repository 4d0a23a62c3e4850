"""Stage profile of `make case3` (figures included): where the wall time of one solve goes.

Runs `cotm-bertini solve case3 --no-cache` (with plots, into a throw-away --out) as a subprocess,
reads the stage timings from the run folder's run.json (derive, generic, render, solve, classify,
write, plot, total) and reports process start-up and import time as total wall minus run.json
total (interpreter start, imports, request hashing, the console summary and the cache copy).
Median of 3 runs; the bare interpreter start (`python -c pass`) is shown for scale.
(Named stage_profile, not profile, so that it cannot shadow the standard library's `profile`.)

Usage: .venv/bin/python bench/stage_profile.py
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from benchlib import median, show, write_csv

STAGES = (
    "derive",
    "render",
    "bertini",
    "parse",
    "solve",
    "classify",
    "write",
    "total",
    "plot",
    "save",
)
REPEATS = 3


def one_run(out: Path, engine: str) -> dict[str, float]:
    """One `make case3`-like solve: stage seconds from run.json, wall and start-up."""
    exe = str(Path(sys.executable).with_name("cotm-bertini"))
    start = time.perf_counter()
    proc = subprocess.run(
        [exe, "solve", "case3", "--no-cache", "--engine", engine, "--out", str(out)],
        capture_output=True,
        text=True,
        check=True,
    )
    wall = time.perf_counter() - start
    line = [ln for ln in proc.stdout.splitlines() if ln.startswith("files in ")][-1]
    folder = Path(line.removeprefix("files in ").split(":", 1)[0])
    timings = json.loads((folder / "run.json").read_text())["timings"]
    row = {s: float(timings.get(s, float("nan"))) for s in STAGES}
    # run.json: `total` is the solve; `save` the run folder (copy, figures: `plot`, run.json).
    row["startup_import"] = wall - row["total"] - row["save"]
    row["wall"] = wall
    return row


def interpreter_start(repeats: int = REPEATS) -> float:
    """Median wall time of `python -c pass` with the venv's interpreter."""
    walls = []
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", "pass"], check=True)
        walls.append(time.perf_counter() - start)
    return median(walls)


def run(repeats: int = REPEATS, engine: str = "homotopy") -> pd.DataFrame:
    """The stage table: printed, written to stage_profile[-cli].csv, returned (a row a stage).

    engine "cli" is what `make case3` runs (the bertini2 command, its files kept); "homotopy" is
    the default of `cotm-bertini solve`.
    """
    with tempfile.TemporaryDirectory(prefix="bench-stages-") as tmp:
        runs = [one_run(Path(tmp) / str(k), engine) for k in range(repeats)]
    bare = interpreter_start()
    names = list(runs[0])
    table = pd.DataFrame(
        {
            "stage": names,
            "median_s": [median([r[n] for r in runs]) for n in names],
            **{f"run{k + 1}_s": [r[n] for n in names] for k, r in enumerate(runs)},
        }
    )
    wall = table.loc[table["stage"] == "wall", "median_s"].iloc[0]
    table["share_of_wall"] = table["median_s"] / wall
    show(
        f"5. Stage profile of `cotm-bertini solve case3 --no-cache --engine {engine}` "
        f"(with plots), median of {repeats}",
        table,
        {c: ".3f" for c in table.columns if c.endswith("_s")} | {"share_of_wall": ".1%"},
    )
    print(
        f"startup_import = wall - run.json total - save; bare interpreter start (python -c pass): "
        f"{bare:.3f} s"
    )
    table.attrs["interpreter_s"] = bare
    write_csv(table, "stage_profile" if engine == "homotopy" else f"stage_profile-{engine}")
    return table


if __name__ == "__main__":
    run()
    run(engine="cli")
