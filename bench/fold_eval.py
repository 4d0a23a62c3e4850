"""Per-path cost of the fold systems (issue 28, item 5): Bertini 2's microseconds per function
evaluation and per Jacobian of each example's fold system, written as expanded terms (before)
and with the fold condition as minors in subfunctions (after: model/framework/folds.py,
_with_subfunctions), at random complex points; then seconds a path of the witness homotopy on
the first N start points of our linear-product start (the multihomogeneous count Bertini's own
ZeroDimSolver uses), and whether both forms end at the same points, there and on a parameter
homotopy between two random complex lines from the finite ends. Benchmarks: nothing asserted.

Usage: python bench/fold_eval.py [--systems cotm fourbar] [--paths 20] [--seed 1]
(--paths 0: evaluations only, seconds).
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import sys
import time
import timeit

import numpy as np
import pandas as pd
from benchlib import BENCH, show, write_csv

ROOT = BENCH.parent
SYSTEMS = {"cotm": ("L01", "L02", ()), "fourbar": ("ex", "ey", ("lift", "tie"))}


def _us(fn, number: int = 2000, repeat: int = 5) -> float:
    """Microseconds a call: the best of `repeat` runs of `number` calls."""
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number * 1e6


def _per_call(system, points: list, t: complex | None) -> tuple[float, float]:
    """(us an evaluation, us a Jacobian) of a parsed Bertini system, cycling over `points`."""
    args = (lambda p: (p,)) if t is None else (lambda p: (p, t))
    out = []
    for method in (system.eval, system.eval_jacobian):
        cycle = itertools.cycle(points)
        out.append(_us(lambda m=method, c=cycle: m(*args(next(c)))))
    return out[0], out[1]


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / np.max(np.abs(np.asarray(a))))


def _crand(rng, n: int) -> np.ndarray:
    return (rng.normal(size=n) + 1j * rng.normal(size=n)) / np.sqrt(2)


def _evaluations(ps, groups, rng) -> list[dict]:
    """Rows of the table: the witness system at a random complex line and the parameter
    homotopy between two, each expanded and structured."""
    import bertini

    from cotm_bertini.backends.render import render_parameter_homotopy, render_system

    n, k = len(ps.variables), len(ps.parameters)
    sysx = ps.instantiate(_crand(rng, k))
    plain_ps = dataclasses.replace(ps, structured=None)
    start, target = (dict(zip(ps.parameters, _crand(rng, k), strict=True)) for _ in range(2))
    points, t = [_crand(rng, n) for _ in range(64)], complex(0.3, 0.2)
    rows = []
    for what, texts, tt in (
        ("system", (render_system(dataclasses.replace(sysx, structured=None), groups),
                    render_system(sysx, groups)), None),
        ("param. homotopy", (render_parameter_homotopy(plain_ps, start, target),
                             render_parameter_homotopy(ps, start, target)), t),
    ):  # fmt: skip
        before, after = (bertini.parse.system(text) for text in texts)
        call = (lambda s, p: s.eval(p)) if tt is None else (lambda s, p, t=tt: s.eval(p, t))
        diff = max(_rel(call(before, p), call(after, p)) for p in points[:8])
        (eb, jb), (ea, ja) = _per_call(before, points, tt), _per_call(after, points, tt)
        rows.append({"form": what, "us_eval_before": eb, "us_eval_after": ea,
                     "eval_ratio": eb / ea, "us_jac_before": jb, "us_jac_after": ja,
                     "jac_ratio": jb / ja, "max_rel_diff": diff})  # fmt: skip
    return rows


def _paths(ps, groups, count: int, seed: int) -> dict:
    """Seconds a path of the witness homotopy on `count` start points, both forms, and the
    largest difference of their finite ends; then a parameter homotopy from those ends to
    another random complex line, both forms, and the largest difference of its ends."""
    from cotm_bertini.backends.homotopy import _SUCCESS, tracked_paths
    from cotm_bertini.backends.render import render_parameter_homotopy, render_system
    from cotm_bertini.backends.start_system import gamma_homotopy_text, linear_product_start

    rng = np.random.default_rng((seed, 5))
    line0, line1 = (dict(zip(ps.parameters, _crand(rng, 4), strict=True)) for _ in range(2))
    sysx = ps.instantiate([line0[n] for n in ps.parameters])
    lp = linear_product_start(sysx, groups, seed)
    starts, gamma = next(lp.chunks(count))[:, lp.declared], np.exp(2j * np.pi * rng.random())
    names = [[sysx.variables[k] for k in g] for g in lp.groups]  # the homotopy's groups
    out, ends = {}, {}
    for label, system in (("before", dataclasses.replace(sysx, structured=None)), ("after", sysx)):
        t0 = time.perf_counter()
        res = tracked_paths((gamma_homotopy_text(system, lp, gamma),
                             render_system(system, names)), starts, "double", {})  # fmt: skip
        res["points"] = res["points"][:, np.argsort(lp.declared)]
        out[f"s_path_{label}"] = (time.perf_counter() - t0) / count
        ends[label] = res
    ok = [i for i in range(count) if all(ends[w]["codes"][i] == _SUCCESS and
                                         ends[w]["finite"][i] for w in ends)]  # fmt: skip
    pts = {w: ends[w]["points"][ok] for w in ends}
    out["witness_finite"] = len(ok)
    out["witness_max_diff"] = float(np.max(np.abs(pts["before"] - pts["after"]), initial=0.0))
    if ok:
        target = ps.instantiate([line1[n] for n in ps.parameters])
        forms = {
            "before": (
                dataclasses.replace(ps, structured=None),
                dataclasses.replace(target, structured=None),
            ),
            "after": (ps, target),
        }
        moved = {}
        for label, (form, tgt) in forms.items():
            t0 = time.perf_counter()
            texts = (render_parameter_homotopy(form, line0, line1), render_system(tgt))
            moved[label] = tracked_paths(texts, pts["after"], "double", {})
            out[f"s_param_path_{label}"] = (time.perf_counter() - t0) / len(ok)
        fin = [i for i in range(len(ok)) if all(moved[w]["finite"][i] for w in moved)]
        a, b = (moved[w]["points"][fin] for w in ("before", "after"))
        out["param_finite"] = len(fin)
        out["param_max_diff"] = float(np.max(np.abs(a - b), initial=0.0))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--systems", nargs="+", default=list(SYSTEMS), choices=list(SYSTEMS))
    ap.add_argument("--paths", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    sys.path.insert(0, str(ROOT))
    import cotm_bertini as cb
    from cotm_bertini.backends.start_system import bezout_number
    from cotm_bertini.catastrophe.framework_folds import _degrees, _groups
    from cotm_bertini.model.framework.folds import curve_system

    rows, paths = [], []
    for name in args.systems:
        x, y, taut = SYSTEMS[name]
        cs = curve_system(cb.Framework.from_toml(ROOT / "examples" / f"{name}.toml"), taut, x, y)
        groups = _groups(cs, args.seed)
        count = bezout_number(_degrees(cs, args.seed, groups), [len(g) for g in groups])
        rng = np.random.default_rng(args.seed)
        for row in _evaluations(cs.ps, groups, rng):
            rows.append({"system": name, "terms": len(cs.ps.coeffs[-1]),
                         "witness_paths": count, **row})  # fmt: skip
        if args.paths:
            paths.append({"system": name, "paths": args.paths,
                          **_paths(cs.ps, groups, args.paths, args.seed)})  # fmt: skip
    frame = pd.DataFrame(rows)
    show("fold systems: Bertini 2 us per evaluation / Jacobian, expanded (before) and with "
         "subfunctions (after)", frame, {"max_rel_diff": ".1e"})  # fmt: skip
    write_csv(frame, "fold_eval")
    if paths:
        show(f"seconds a path (double precision, first {args.paths} start points), "
             "endpoints compared", pd.DataFrame(paths), {"witness_max_diff": ".1e",
                                                          "param_max_diff": ".1e"})  # fmt: skip


if __name__ == "__main__":
    main()
