"""The certificate of a framework's solve (docs/certify.md, "Frameworks").

1. Each real row: the solver's variables recovered from the row (pose, lengths, tensions; the
   multipliers the table does not list by a least-squares solve, exact since the equations are
   affine in them), then Krawczyk in ball arithmetic on its taut set's own polynomial system
   (`certify/roots`, the same code as for the paper's mechanism), the parameters entering as
   balls that hold the file's values in the framework's units.
2. Each proved physical row: its consistency (every length variable > 0, a taut cable longer
   than its free length, a slack one shorter) and its kind (the inertia of the reduced Hessian,
   `certify/inertia`) over the proved box.
3. Where the poses form a circle or a torus (with cables too: V piecewise, `framework_torus`):
   completeness by the branch and bound of `certify/torus` on V in the body angles, enclosed by
   the derivation's own generated code evaluated on balls (model.framework.ballcode).
Elsewhere the certificate says what is proved (the rows) and that completeness is not.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from flint import arb

from ...model.framework.ballcode import ball_module
from ...model.framework.compiled import FrameworkSystem, framework_system, variable_scale
from ...model.framework.spec import Framework
from ...model.framework.structure import layout
from ...model.framework.units import normalized_slots, slot_kind, units
from ..framework_classify import quaternion_columns, sign_free
from .framework_torus import torus_landscape
from .inertia import reduced_kind
from .mechanism import (
    ROOT_FAILED,
    Certificate,
    duplicates,
    kind_differences,
    not_proved_text,
    spring_bound,
    spring_clause,
)
from .roots import WORKING_BITS, ball_system_of, certify_points
from .search import Known
from .torus import Landscape, krawczyk_box, torus_search

SHORT = 1e-3  # springs shorter than this (framework length units) are set aside at cone points
MIN_WIDTH = 1e-4  # radians: the smallest box away from a known equilibrium
ROOT_BOX = 1e-7  # radians: the half-width of the box proving each equilibrium in the angles
DECIMAL = 2.0**-53  # a decimal read as a double is within this (relative) of it


def slot_balls(fw: Framework, exact: bool = False) -> list:
    """Every slot in the framework's units as a ball, in slot order: its expression evaluated in
    ball arithmetic, each number of the file (and each parameter value) a ball holding the
    decimal it was read from (a double is within half an ulp of it); with `exact`, the doubles
    themselves (the numbers as given, exact, as the paper's certificate takes them)."""
    from flint import arb

    length, stiffness = (arb(u) for u in units(fw))
    unit = {"len": length, "k": stiffness, "force": stiffness * length}
    rel = 0.0 if exact else DECIMAL

    def number(v: float):
        return arb(v, abs(v) * rel) if v and rel else arb(v)

    values = {n: number(float(v)) for n, v in fw.values.items()}
    return [
        _evaluate(e, values, number) / unit[slot_kind(name)]
        for name, e in fw.slot_expressions().items()
    ]


def _evaluate(e, values: dict, number):
    """An expression (model.framework.expressions.Expr) in ball arithmetic."""
    if e.op == "num":
        return number(e.value)
    if e.op == "name":
        return values[e.name]
    a = [_evaluate(x, values, number) for x in e.args]
    if e.op == "neg":
        return -a[0]
    ops = {"+": lambda x, y: x + y, "-": lambda x, y: x - y, "*": lambda x, y: x * y,
           "/": lambda x, y: x / y, "^": lambda x, y: x**y}  # fmt: skip
    return ops[e.op](a[0], a[1])


def _ball(v):
    """A generated function's entry as a ball (its constant entries are plain floats)."""
    return v if type(v) is arb else arb(v)


@dataclass
class _Rows:
    """What part 1 and 2 established, per row of the table."""

    certified: np.ndarray
    radius: np.ndarray
    physical: dict[int, str] = field(default_factory=dict)  # row -> yes, no, unknown
    kinds: dict[int, str] = field(default_factory=dict)  # solution_id -> proved kind
    as_doubles: list[int] = field(default_factory=list)  # proved with the doubles exact only
    failed: dict[int, str] = field(default_factory=dict)  # solution_id -> the step that failed
    boxes: dict[int, tuple] = field(default_factory=dict)  # row -> (real centre, half-widths)
    one_pose: list[str] = field(default_factory=list)  # rows proved at one pose twice


def _row_points(fw: Framework, fs: FrameworkSystem, table, rows: np.ndarray) -> tuple:
    """(the solver's variables of real rows, normalised; the numeric system): rotations from
    the angles (or quaternions), translations, nodes, lengths d, force densities w = tension / d
    and bar multipliers tension / length from the columns; then every w and mu (the pins'
    multipliers are not in the table) by least squares: the equations are affine in them."""
    cols = {}
    for v in fs.ps.variables:
        head, _, rest = v.partition("_")
        column = None
        if head in ("c", "s"):
            angle = np.radians(np.asarray(table[f"{rest}.angle_deg"], float)[rows])
            cols[v] = np.cos(angle) if head == "c" else np.sin(angle)
        elif head.startswith("q"):
            column = f"{rest}.q{head[1]}"
        elif head in ("t", "n"):
            owner, axis = rest.rsplit("_", 1)
            column = f"{owner}.{axis}"
        elif head == "d":
            column = f"{rest}.length"
        elif head in ("w", "mu") and f"{rest}.tension" in table:
            cols[v] = np.asarray(table[f"{rest}.tension"], float)[rows] / np.asarray(
                table[f"{rest}.length"], float)[rows]  # fmt: skip
        if column is not None:
            cols[v] = np.asarray(table[column], float)[rows]
        cols.setdefault(v, np.zeros(len(rows)))
    x = np.column_stack([cols[v] for v in fs.ps.variables]) / variable_scale(fs, units(fw))
    slots = normalized_slots(fw)
    system = fs.ps.instantiate([slots[n] for n in fs.ps.parameters])
    linear = [j for j, k in enumerate(fs.kinds) if k in ("k", "force")]
    for i in range(len(x) if linear else 0):
        jac = system.jacobian(x[i : i + 1])[0][:, linear].real
        rhs = -system.evaluate(x[i : i + 1])[0].real
        x[i, linear] += np.linalg.lstsq(jac, rhs, rcond=None)[0]
    return np.nan_to_num(x).astype(complex), system


def certify_rows(fw: Framework, table, P: list, exact: list) -> _Rows:
    """Parts 1 and 2 for every row (rows by position): proved, box half-width (normalised),
    and for the proved physical ones consistency and kind. `P`: the slots as balls holding the
    file's decimals; a row not proved with them is tried with `exact` (the doubles, exact) and,
    if proved so, listed in `as_doubles`."""
    n = len(table["solution_id"])
    out = _Rows(np.zeros(n, dtype=bool), np.full(n, np.nan))
    real = np.asarray(table["is_real"], dtype=bool)
    singular = np.asarray(table["singular"], dtype=bool)
    # A table read back from solutions.csv has NaN where no cable is taut (an empty field).
    sets = np.array([v if isinstance(v, str) else "" for v in table["taut_set"]], dtype=object)
    for label in sorted(set(sets)):
        rows = np.flatnonzero((sets == label) & real & ~singular)
        if not len(rows):
            continue
        fs = framework_system(fw, tuple(label.split()))
        points, system = _row_points(fw, fs, table, rows)
        for slots in (P, exact):
            todo = ~out.certified[rows]
            if not todo.any():
                break
            names = dict(zip(fw.slots(), slots, strict=True))
            proved, radius, boxes = certify_points(
                lambda fs=fs, names=names: ball_system_of(fs.ps, names), system, points[todo],
                np.ones(int(todo.sum()), bool), each=True,
            )  # fmt: skip
            for row, ok, r, proof in zip(rows[todo], proved, radius, boxes, strict=True):
                if ok:
                    out.certified[row], out.radius[row] = True, r
                    if slots is exact:
                        out.as_doubles.append(int(table["solution_id"][row]))
                    X = [_real_ball(z, r) for z, r in zip(*proof, strict=True)]
                    out.boxes[int(row)] = (np.array([float(z.real.mid()) for z in proof[0]]),
                                           np.asarray(proof[1], dtype=float))  # fmt: skip
                    _judge(fw, fs, table, int(row), X, slots, out)
        for row in rows[~out.certified[rows]]:
            out.failed[int(table["solution_id"][row])] = ROOT_FAILED
        out.one_pose += one_pose_twice(fs, table, rows[out.certified[rows]], out.boxes)
    return out


def one_pose_twice(fs: FrameworkSystem, table, rows: np.ndarray, boxes: dict) -> list[str]:
    """Proved rows of one taut set whose boxes may hold one root up to the sign of each spatial
    body's quaternion (q and -q are one pose: two rows would count one equilibrium twice),
    compared by the sign-free products q_i q_j; a product moves by at most 2 r + r^2 when its
    factors (|q_i| <= 1) move by r."""
    quaternions = quaternion_columns(fs)
    out = []
    for n, a in enumerate(rows):
        for b in rows[n + 1 :]:
            (ca, ra), (cb, rb) = boxes[int(a)], boxes[int(b)]
            r = float(ra.max() + rb.max())
            gap = np.abs(sign_free(ca[None], quaternions) - sign_free(cb[None], quaternions))
            if gap.max() <= 2 * r + r * r + 1e-12:
                ids = [int(table["solution_id"][i]) for i in (a, b)]
                out.append(f"solutions {ids[0]} and {ids[1]} are proved at one pose (up to the "
                           "sign of a quaternion): one equilibrium listed twice")  # fmt: skip
    return out


def _real_ball(z, r: float):
    """The real ball of half-width r about a proved real centre: the root is real and in the
    complex box, so it lies in this ball."""
    from flint import arb

    return arb(z.real.mid(), r)


def _judge(fw, fs, table, row: int, X: list, P: list, out: _Rows) -> None:
    """Consistency and kind of one proved real row over its box X."""
    from flint import ctx

    sid = int(table["solution_id"][row])
    bits, ctx.prec = ctx.prec, WORKING_BITS
    try:
        out.physical[row], open_links = consistency(fw, fs, X, P)
        if out.physical[row] == "unknown":
            out.failed[sid] = (f"consistency: {', '.join(open_links)} against zero or the free "
                               "length not decided over the proved box")  # fmt: skip
        if out.physical[row] == "yes":
            code, m = ball_module(fs), fs.local_size
            h = [_ball(v) for v in code.hessian(X, P)]
            g = [_ball(v) for v in code.constraint_jacobian(X, P)] if fs.constraints else []
            H = [h[i * m : (i + 1) * m] for i in range(m)]
            G = [g[i * m : (i + 1) * m] for i in range(len(g) // m)] if g else []
            out.kinds[sid] = reduced_kind(H, G)
            if out.kinds[sid] == "undecided":
                finite = all(b.is_finite() for line in H + G for b in line)
                out.failed[sid] = "kind: " + (
                    "a pivot of the ball LDL^T of the bordered Hessian contains 0" if finite
                    else "the Hessian's enclosure over the proved box is not finite")  # fmt: skip
    finally:
        ctx.prec = bits


def consistency(fw: Framework, fs: FrameworkSystem, X: list, P: list) -> tuple[str, list[str]]:
    """('yes' when the box X proves the row physical (each length variable > 0, each taut
    cable longer than its free length, each slack one shorter), 'no' when it proves it is not,
    'unknown' otherwise; the links whose condition is not decided)."""
    index = {v: j for j, v in enumerate(fs.ps.variables)}
    slot = {n: j for j, n in enumerate(fw.slots())}
    pos = ball_module(fs).positions(X, P)
    where = {p: pos[k * fw.dim : (k + 1) * fw.dim] for k, p in enumerate(fs.points)}
    verdicts, open_links = [], []
    for x in fw.links:
        if x.kind == "bar" or (x.kind == "spring" and f"d_{x.name}" not in index):
            continue  # a bar, or a spring of zero free length: no condition
        L0 = P[slot[f"L0_{x.name}"]]
        if f"d_{x.name}" in index:
            d = X[index[f"d_{x.name}"]]
        else:
            r = [_ball(a) - _ball(b) for a, b in zip(where[x.a], where[x.b], strict=True)]
            dd = sum((c * c for c in r[1:]), r[0] * r[0])
            d = dd.sqrt() if dd > 0 else dd  # only its sign matters where it may be 0
        if x.kind == "spring":
            lo, hi = 0, None
        else:
            lo, hi = (L0, None) if x.name in fs.taut else (None, L0)
        above = lo is None or d > lo
        below = hi is None or d < hi
        wrong = (lo is not None and d < lo) or (hi is not None and d > hi)
        verdicts.append("yes" if above and below else "no" if wrong else "unknown")
        open_links += [f"{x.kind} {x.name}"] if verdicts[-1] == "unknown" else []
    verdict = "no" if "no" in verdicts else "unknown" if "unknown" in verdicts else "yes"
    return verdict, open_links


def _completeness_scope(fw: Framework) -> str:
    """'' when the branch and bound applies, else why completeness is not proved."""
    lay = layout(fw)
    if fw.dim != 2 or not lay.is_torus:
        return "the configuration space is not a circle or torus"
    return ""


def certify_framework_table(
    fw: Framework, table, short: float = SHORT, min_width: float = MIN_WIDTH
) -> Certificate:
    """Prove each real row of a framework's solutions table, the consistency and kind of its
    physical rows and, where the poses form a circle or torus, the completeness of the physical
    set (module docstring). `table`: rows by position."""
    from flint import ctx

    start = time.perf_counter()
    bits, ctx.prec = ctx.prec, WORKING_BITS
    try:
        P, exact = slot_balls(fw), slot_balls(fw, exact=True)
    finally:
        ctx.prec = bits
    rows = certify_rows(fw, table, P, exact)
    t_rows = time.perf_counter()
    contradictions = _row_contradictions(table, rows)
    scope = _completeness_scope(fw)
    proof = None
    if not scope:
        land = torus_landscape(fw, P)
        known, unproved = _known(fw, table, land)
        t_known = time.perf_counter()
        balls = {k.sid: _enclosure_balls(k.enclosure) for k in known}
        proof = torus_search(land, balls, short, min_width)
        contradictions += _search_contradictions(fw, table, proof, known, unproved)
    else:
        t_known = t_rows
    t_done = time.perf_counter()
    bound, meaning = spring_bound(proof) if proof else (0.0, "none")
    bound *= units(fw)[0]
    status, statement = _verdict(table, rows, proof, scope, contradictions,
                                 spring_clause(bound, meaning))  # fmt: skip
    found = {sid for sid, boxes in proof.roots.items() if boxes} if proof else set()
    timings = {"rows": t_rows - start, "equilibria": t_known - t_rows,
               "completeness": t_done - t_known}  # fmt: skip
    return Certificate(
        status, statement, rows.certified, rows.radius,
        len(found) if proof else len(_proved_equilibria(rows)), rows.kinds, bound,
        proof.boxes if proof else 0, len(proof.excluded) if proof else 0,
        proof.undecided if proof else [], contradictions, time.perf_counter() - start, timings,
        "framework-rows" if scope else "framework-torus", dict(sorted(rows.failed.items())),
    )  # fmt: skip


def _proved_equilibria(rows: _Rows) -> list[int]:
    """The solution ids proved real, consistent and of a proved kind: equilibria, proved."""
    return sorted(sid for sid, kind in rows.kinds.items() if kind != "undecided")


def _enclosure_balls(bounds: tuple) -> tuple:
    from .torus import box

    return box(*bounds)


def _known(fw: Framework, table, land: Landscape) -> tuple[list[Known], list[int]]:
    """Each physical row proved a critical point of V in a tiny box of its body angles: (the
    proved ones, the solution ids not proved)."""
    known, failed = [], []
    bodies = layout(fw).rotations
    for row in np.flatnonzero(np.asarray(table["physical"], dtype=bool)):
        sid = int(table["solution_id"][row])
        angles = [math.radians(float(table[f"{b}.angle_deg"][row])) for b in bodies]
        q = tuple(v for a in angles for v in (a - ROOT_BOX, a + ROOT_BOX))
        verdict, image = krawczyk_box(land, q)
        if verdict != "one":
            failed.append(sid)
            continue
        bounds = []
        for e in image:
            bounds += [math.nextafter(float(e.lower()), -math.inf),
                       math.nextafter(float(e.upper()), math.inf)]  # fmt: skip
        known.append(Known(sid, q, tuple(bounds)))
    return known, failed


def _row_contradictions(table, rows: _Rows) -> list[str]:
    """Rows whose proved consistency or kind differs from the table."""
    out = []
    physical = np.asarray(table["physical"], dtype=bool)
    for row, verdict in rows.physical.items():
        sid = int(table["solution_id"][row])
        if verdict == "no" and physical[row]:
            out.append(f"solution {sid} is in the table as physical, but its proved box "
                       "breaks a length condition (a length <= 0 or a cable on the wrong side "
                       "of its free length)")  # fmt: skip
        elif verdict == "yes" and not physical[row]:
            out.append(f"solution {sid} is proved a real, consistent equilibrium, but the "
                       "table does not list it as physical")  # fmt: skip
    return out + kind_differences(table, rows.kinds) + rows.one_pose


def _search_contradictions(fw, table, proof, known: list[Known], unproved: list[int]) -> list:
    """Critical points the table lacks, overlapping proofs, physical rows not found."""
    out = []
    for q in proof.missing:
        where = ", ".join(f"{b} {math.degrees(q[2 * j]):.6f}..{math.degrees(q[2 * j + 1]):.6f}"
                          for j, b in enumerate(layout(fw).rotations))  # fmt: skip
        out.append(f"a critical point of V at {where} deg is not in the table")
    out += duplicates(known)
    found = {sid for sid, boxes in proof.roots.items() if boxes}
    bound = proof.longest_excluded * units(fw)[0]
    free = [x.name for x in fw.springs if x.name not in set(fw.zero_free_length())]
    for row in np.flatnonzero(np.asarray(table["physical"], dtype=bool)):
        sid = int(table["solution_id"][row])
        lengths = [float(table[f"{n}.length"][row]) for n in free]
        if sid in found or (lengths and min(lengths) <= bound):
            continue
        why = "its box failed the Krawczyk test" if sid in unproved else "no box holds it"
        out.append(f"solution {sid} is in the table as physical but not proved ({why})")
    return out


def _verdict(table, rows: _Rows, proof, scope: str, contradictions: list, where: str):
    """(status, statement): 'contradiction', 'undecided', 'proved' (rows and completeness) or
    'rows proved' (every real row proved; completeness not proved: `scope` says why); `where`:
    the spring-length clause of a completeness proof. Rows not proved are named with the step
    that failed (`_Rows.failed`), and only those proved are counted as proved."""
    real = np.asarray(table["is_real"], dtype=bool)
    singular = np.asarray(table["singular"], dtype=bool)
    n_rows = len(real)
    tail = (f"{int(rows.certified.sum())} of {n_rows} solutions certified "
            f"({int(singular.sum())} singular double roots cannot be; "
            f"{int((~real & ~singular).sum())} complex rows not tried: the table keeps their "
            "real parts only)")  # fmt: skip
    if rows.as_doubles:
        tail += (
            f"; solutions {sorted(rows.as_doubles)} proved for the file's numbers as "
            "doubles only (their decimals' half-ulp moves them more than the box allows)"
        )
    failed = not_proved_text(rows.failed)
    undecided = bool(rows.failed or (proof is not None and proof.undecided))
    complete = "rows proved" if proof is None else "proved"
    status = "contradiction" if contradictions else "undecided" if undecided else complete
    if status == "contradiction":
        found = f" ({_found(proof)} equilibria proved {where})" if proof else ""
        also = f"; not proved: {failed}" if failed else ""
        return status, f"CONTRADICTION: the table and the proof differ{found}; {tail}{also}"
    if proof is None:
        text = (f"proved: every certified solution is a true isolated solution of its taut "
                f"set's system within certified_radius; {len(_proved_equilibria(rows))} "
                f"physical (consistency and stability proved); completeness not proved: "
                f"{scope}")  # fmt: skip
        return status, f"{'not proved: ' + failed + '; ' if failed else ''}{text}; {tail}"
    text = (f"proved: exactly {_found(proof)} equilibria {where}; consistency and stability of "
            "each proved (ball LDL^T of the reduced Hessian)")  # fmt: skip
    if status == "undecided":
        boxes = f"{len(proof.undecided)} boxes undecided" if proof.undecided else ""
        text = (f"not proved: {'; '.join(t for t in (boxes, failed) if t)}; {_found(proof)} "
                f"equilibria proved {where}")  # fmt: skip
    return status, f"{text}; {tail}"


def _found(proof) -> int:
    return sum(1 for boxes in proof.roots.values() if boxes)
