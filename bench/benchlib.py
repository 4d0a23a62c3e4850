"""Shared helpers of the benchmark suite: tables, CSV files, matching, bare bertini2 runs."""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd

BENCH = Path(__file__).resolve().parent
RESULTS = BENCH / "results"
CASES = ("case1", "case2", "case3")
MATCH_DEG = 1e-6  # a found equilibrium within this of a reference one (deg, both angles) is it


def show(title: str, frame: pd.DataFrame, floats: dict[str, str] | None = None) -> None:
    """Print a titled table; `floats` maps column -> format spec (default .3g)."""
    floats = floats or {}
    shown = frame.copy()
    for col in shown.columns:
        if pd.api.types.is_float_dtype(shown[col]):
            spec = floats.get(col, ".3g")
            shown[col] = [("" if pd.isna(v) else format(v, spec)) for v in shown[col]]
    print(f"\n== {title} ==")
    print(shown.to_string(index=False) if len(shown) else "(no rows)")


def write_csv(frame: pd.DataFrame, name: str) -> Path:
    """bench/results/<name>.csv (the folder is git-ignored)."""
    RESULTS.mkdir(parents=True, exist_ok=True)
    path = RESULTS / f"{name}.csv"
    frame.to_csv(path, index=False)
    print(f"-> {path.relative_to(BENCH.parent)}")
    return path


def timed(fn: Callable, *args, **kwargs) -> tuple[object, float]:
    """fn(*args, **kwargs) and its wall time in seconds."""
    start = time.perf_counter()
    value = fn(*args, **kwargs)
    return value, time.perf_counter() - start


def torus_gap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Largest angle difference (deg, mod 360) between rows of a (n, 2) and b (m, 2): (n, m)."""
    d = np.abs(a[:, None, :] - b[None, :, :]) % 360.0
    return np.minimum(d, 360.0 - d).max(axis=2)


def match(reference: pd.DataFrame, found: pd.DataFrame) -> dict:
    """Compare found physical equilibria (gamma1_deg, gamma2_deg) with the reference ones.

    missed: reference equilibria with no found one within MATCH_DEG; extras: found ones with no
    reference within MATCH_DEG; worst_err_deg: the largest distance from a reference equilibrium
    to its nearest found one (so a miss shows as a large error).
    """
    ref = reference[["gamma1_deg", "gamma2_deg"]].to_numpy(dtype=float)
    got = found[["gamma1_deg", "gamma2_deg"]].to_numpy(dtype=float)
    if len(got) == 0:
        return {"found": 0, "missed": len(ref), "extras": 0, "worst_err_deg": np.inf}
    gap = torus_gap(ref, got)
    nearest = gap.min(axis=1)
    return {
        "found": len(got),
        "missed": int((nearest > MATCH_DEG).sum()),
        "extras": int((gap.min(axis=0) > MATCH_DEG).sum()),
        "worst_err_deg": float(nearest.max()) if len(ref) else 0.0,
    }


def raw_error(reference: pd.DataFrame, endpoints) -> float:
    """Worst distance (deg) from a reference equilibrium to the nearest raw solver endpoint
    (angles from the real parts of c_i, s_i as the solver returned them, before any refinement).
    `endpoints`: the package's Endpoints table."""
    if len(endpoints) == 0:
        return float("inf")
    frame = endpoints.frame()
    c1, s1, c2, s2 = (frame[v].to_numpy(dtype=complex).real for v in ("c1", "s1", "c2", "s2"))
    got = np.degrees(np.column_stack([np.arctan2(s1, c1), np.arctan2(s2, c2)])) % 360.0
    ref = reference[["gamma1_deg", "gamma2_deg"]].to_numpy(dtype=float)
    return float(torus_gap(ref, got).min(axis=1).max())


def median(values: list[float]) -> float:
    """Median of a non-empty list."""
    return float(np.median(values))


# --- Bertini 2 as a bare command ------------------------------------------------------------


def run_bertini2(input_text: str, folder: Path, timeout: float = 900.0) -> float:
    """Write `input` into a new folder and run the bertini2 binary there; its wall seconds."""
    from cotm_bertini.backends.engine import child_environment, find_engine

    eng = find_engine()
    folder.mkdir(parents=True)
    (folder / "input").write_text(input_text)
    start = time.perf_counter()
    proc = subprocess.run(
        [eng.path, "input"],
        cwd=folder,
        env=child_environment(eng, None),
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    seconds = time.perf_counter() - start
    if proc.returncode != 0:
        tail = " | ".join((proc.stderr or proc.stdout).strip().splitlines()[-4:])
        raise RuntimeError(f"bertini2 exited with {proc.returncode}: {tail}")
    return seconds


def endpoints_from_finite_solutions(folder: Path, variables: tuple[str, ...]):
    """Bertini's finite_solutions (user coordinates) as an endpoint table for classify().

    For output layouts the package's parser does not read (several homogenising variables of a
    multihomogeneous start; SecurityLevel 1, where main_data also lists the paths at infinity).
    No per-path metadata: condition numbers are left to classify's own Jacobian.
    """
    from cotm_bertini.backends.endpoints import Endpoints
    from cotm_bertini.backends.parse import read_solution_list

    pts = read_solution_list(folder / "finite_solutions")
    pts = pts.reshape(len(pts), len(variables))
    records = [
        # accuracy: Bertini's default final tolerance
        {"path_number": k, "final_t": 0.0, "accuracy_estimate": 1e-11, "coords": p}
        for k, p in enumerate(pts)
    ]
    return Endpoints.from_records(tuple(variables), records)


def bertini_seconds_from_files(folder: Path) -> float:
    """Bertini's run time from file times: `input` written just before, stdout-files after."""
    done = [p.stat().st_mtime for p in folder.iterdir() if p.name != "input"]
    return max(done) - (folder / "input").stat().st_mtime if done else float("nan")


def multihomogeneous_bezout(system, groups: list[list[str]]) -> int:
    """Paths of a multihomogeneous start: coefficient of prod z_j^|G_j| in prod_i sum_j d_ij z_j."""
    import sympy as sp

    z = sp.symbols(f"z0:{len(groups)}")
    index = {v: k for k, v in enumerate(system.variables)}
    product = sp.Integer(1)
    for exps in system.exponents:
        degs = [int(exps[:, [index[v] for v in g]].sum(axis=1).max()) for g in groups]
        product *= sum(d * zj for d, zj in zip(degs, z, strict=True))
    monomial = sp.Mul(*[zj ** len(g) for zj, g in zip(z, groups, strict=True)])
    return int(sp.Poly(sp.expand(product), *z).coeff_monomial(monomial))


def example_system(name: str, taut: tuple[str, ...] | None = None):
    """The system of examples/<name>.toml's taut set `taut` (default: its first with isolated
    equilibria), its start centre and groups."""
    import cotm_bertini as cb
    from cotm_bertini.model.framework.compiled import framework_system, variable_groups
    from cotm_bertini.model.framework.taut_sets import taut_sets
    from cotm_bertini.model.framework.units import normalized_slots

    fw = cb.Framework.from_toml(BENCH.parent / "examples" / f"{name}.toml")
    if taut is not None:
        fs = framework_system(fw, taut)
    else:
        fs = next(f for f in (framework_system(fw, t) for t in taut_sets(fw)) if not f.free)
    centre = normalized_slots(fw.at_defaults())
    return fs.ps, {n: centre[n] for n in fs.ps.parameters}, variable_groups(fs)


def same_points(a: np.ndarray, b: np.ndarray, tol: float = 1e-8) -> bool:
    """The two sets of points agree (each row of a has a distinct match in b, relative tol)."""
    if a.shape != b.shape:
        return False
    left = list(range(len(b)))
    for p in a:
        d = [np.abs(b[k] - p).max() / (1 + np.abs(p).max()) for k in left]
        if min(d) > tol:
            return False
        left.pop(int(np.argmin(d)))
    return True


def cli_seconds(args: list[str], env: dict) -> float:
    """Seconds of one `cotm-bertini` run end to end (no cache of results, no figures)."""
    cli = str(Path(sys.executable).with_name("cotm-bertini"))
    t0 = time.perf_counter()
    subprocess.run([cli, *args, "--no-cache", "--no-plots", "--quiet"], check=True, env=env,
                   cwd=tempfile.mkdtemp(), capture_output=True)  # fmt: skip
    return time.perf_counter() - t0
