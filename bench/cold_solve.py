"""The cold solve against a bare bertini2 solve of the same case, in one run (issue 46, item 4).

`cotm-bertini solve case3 --no-cache --no-plots --quiet` in a fresh process (the derived
equations and the generic set cached, as after any first solve: the cost a user pays each time),
interleaved with the bare `bertini2` command on case 3's total-degree input, so that both see the
same load; median of `--repeats`. Beside them: the split of the cold solve's wall into the solve
itself (run.json `total`), its run folder (`save`) and the rest (interpreter start, imports,
exit), the bare interpreter (`python -c pass`), the import times of the heavy modules and whether
sympy was imported at all (python -X importtime).

Benchmarks, not tests: nothing is asserted; figures are printed and written to
bench/results/cold_solve.csv.
Usage: .venv/bin/python bench/cold_solve.py [--case case3] [--repeats 5]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pandas as pd
from benchlib import median, run_bertini2, show, write_csv

HEAVY = ("numpy", "pandas", "bertini", "sympy", "cotm_bertini.point", "cotm_bertini.cli")


def _cli(case: str, out: str) -> list[str]:
    exe = str(Path(sys.executable).with_name("cotm-bertini"))
    return [exe, "solve", case, "--no-cache", "--no-plots", "--quiet", "--out", out]


def cold_solve(case: str, out: str) -> dict[str, float]:
    """One fresh-process solve: its wall, and run.json's solve (`total`) and `save` seconds."""
    start = time.perf_counter()
    proc = subprocess.run(_cli(case, out), capture_output=True, text=True, check=True)
    wall = time.perf_counter() - start
    folder = Path(proc.stdout.strip().splitlines()[-1])  # --quiet: the run folder only
    timings = json.loads((folder / "run.json").read_text())["timings"]
    return {"wall": wall, "total": timings["total"], "save": timings.get("save", 0.0)}


def bare_bertini2(case: str) -> float:
    """One bare bertini2 solve of the case's total-degree input: its wall seconds."""
    from cotm_bertini.backends.render import render_input
    from cotm_bertini.model.compiled import polynomial_system
    from cotm_bertini.params import Params
    from cotm_bertini.settings import Settings

    params = Params.case(case)
    text = render_input(polynomial_system(params), Settings(seed=1, engine="cli"),
                        params.as_dict())  # fmt: skip
    with tempfile.TemporaryDirectory(prefix="bench-bare-") as tmp:
        return run_bertini2(text, Path(tmp) / "run")


def import_trace(case: str, out: str) -> dict[str, object]:
    """python -X importtime of one cold solve: the heavy modules' cumulative import seconds
    (the first import of each), their sum over top-level imports, and whether sympy came."""
    args = [sys.executable, "-X", "importtime", "-m", "cotm_bertini.cli", *_cli(case, out)[1:]]
    proc = subprocess.run(args, capture_output=True, text=True, check=True)
    found: dict[str, float] = {}
    top = 0.0
    for line in proc.stderr.splitlines():
        parts = line.removeprefix("import time:").split("|")
        if len(parts) != 3 or not parts[1].strip().isdigit():
            continue
        name, seconds = parts[2].rstrip(), int(parts[1]) / 1e6
        if not name.startswith("  "):  # top level: its children are inside its figure
            top += seconds
        found.setdefault(name.strip(), seconds)
    out_ = {f"import {n} (s)": found.get(n, "not imported") for n in HEAVY}
    out_["imports, all top-level (s)"] = top
    out_["sympy imported"] = "sympy" in found
    return out_


def _interpreter() -> float:
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", "pass"], check=True)
    return time.perf_counter() - start


def run(case: str = "case3", repeats: int = 5) -> dict:
    """The cold solve and the bare bertini2 solve, interleaved: the table of figures."""
    with tempfile.TemporaryDirectory(prefix="bench-cold-") as tmp:
        cold_solve(case, tmp)  # warm: the compiled equations and the generic set
        load = [os.getloadavg()[0]]
        solves, bare, python = [], [], []
        for _ in range(repeats):
            bare.append(bare_bertini2(case))
            solves.append(cold_solve(case, tmp))
            python.append(_interpreter())
        load.append(os.getloadavg()[0])
        imports = import_trace(case, tmp)
    wall, b = median([s["wall"] for s in solves]), median(bare)
    total, save = median([s["total"] for s in solves]), median([s["save"] for s in solves])
    out = {
        f"cold solve {case} --no-cache --no-plots (s, median)": wall,
        "  of which the solve (run.json total; its lazy imports inside)": total,
        "  of which the run folder (run.json save)": save,
        "  of which start-up, imports, exit": wall - total - save,
        f"bare bertini2 {case}, total degree (s, median)": b,
        "cold solve / bare bertini2": wall / b,
        "python -c pass (s, median)": median(python),
        **imports,
        "load average (1 min) before, after": f"{load[0]:.2f}, {load[1]:.2f}",
        "runs": "solves " + ", ".join(f"{s['wall']:.2f}" for s in solves)
        + "; bare " + ", ".join(f"{v:.2f}" for v in bare),
    }  # fmt: skip
    shown = {k: f"{v:.3g}" if isinstance(v, float) else str(v) for k, v in out.items()}
    table = pd.DataFrame({"what": list(shown), "value": list(shown.values())})
    show(f"Cold solve against bare bertini2, {case} (fresh processes, interleaved)", table)
    write_csv(table, "cold_solve")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", default="case3", choices=("case1", "case2", "case3"))
    ap.add_argument("--repeats", type=int, default=5, help="interleaved pairs (default 5)")
    args = ap.parse_args()
    run(args.case, args.repeats)


if __name__ == "__main__":
    main()
