"""The certificate: every reported solution proved, and the physical set proved complete.

1. Each row of the solutions table: Krawczyk in complex ball arithmetic on the polynomial system
   (`certify/roots`): a unique solution in a small box, real where the table says real.
2. Each physical equilibrium: Krawczyk on grad V = 0 in the angles (a tiny box), and its kind
   from the interval Hessian over that box (positive definite: a minimum, stable).
3. Completeness (`certify/search`): every critical point of V whose spring lengths exceed the
   reported bound is relaxed (both springs at their free lengths: a branch and bound on that
   polynomial system) or lies on the parallel curve a_1 x a_2 = 0 (enclosed by `certify/curve`,
   then searched along in one variable); each lies in one of the boxes of step 2.
   `method="torus"` runs the earlier two-dimensional branch and bound over the torus instead
   (`certify/torus`, slower; an independent route for the tests).
Any difference from the table -- a critical point it lacks, a physical row not proved, a kind
that differs -- is a contradiction: the certificate says so and the caller raises.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ...params import Params
from .roots import certify_rows
from .search import Known, search
from .torus import arb_params, box, branch_and_bound, enclosures, krawczyk_2d

SHORT = 1e-3  # springs shorter than this (times L3) are set aside: V is not smooth at length 0
MIN_WIDTH = 1e-4  # radians: the smallest box away from a known equilibrium
ROOT_BOX = 1e-7  # radians: the half-width of the box proving each equilibrium
ROOT_FAILED = "root inclusion: the Krawczyk test failed in every box tried"
KIND_FAILED = (
    "kind: the signs of the interval Hessian's determinant and first entry over the 1e-7 rad "
    "box are not decided"
)
METHODS = {
    "curve": "Krawczyk (complex balls) per solution; completeness: the relaxed equilibria by "
    "branch and bound with Krawczyk on d_i^2 = L0_i^2, the others along the parallel curve "
    "a1 x a2 = 0 (a ball-arithmetic cover of the curve, then bisection in one angle with "
    "Krawczyk on grad V)",
    "torus": "Krawczyk (complex balls) per solution; branch and bound with Krawczyk on grad V "
    "over the torus",
    "framework-torus": "Krawczyk (complex balls) per real solution on its taut set's system; "
    "consistency and kind over the proved box (ball LDL^T of the bordered Hessian); "
    "completeness: branch and bound with Krawczyk on grad V over the torus of body angles",
    "framework-rows": "Krawczyk (complex balls) per real solution on its taut set's system; "
    "consistency and kind over the proved box (ball LDL^T of the bordered Hessian); "
    "completeness not proved",
}


@dataclass(frozen=True)
class Certificate:
    """What was proved about one parameter set's solutions (see the module docstring)."""

    status: str  # "proved", "undecided" (some box not decided) or "contradiction"
    statement: str
    certified: np.ndarray  # per row of the table: a unique solution proved in its box
    certified_radius: np.ndarray  # the box half-width (normalised units), NaN if not proved
    proved_equilibria: int
    kinds: dict[int, str]  # solution_id -> kind proved by the interval Hessian
    # Every equilibrium whose springs with free lengths are all longer than this is proved
    # (`spring_bound`: the most the shortest spring may be in a box set aside; with none set
    # aside, a proved lower bound of those springs' lengths in every pose, or 0).
    shortest_spring: float
    boxes: int
    excluded_boxes: int
    undecided_boxes: list[tuple]
    contradictions: list[str] = field(default_factory=list)
    seconds: float = 0.0
    timings: dict[str, float] = field(default_factory=dict)  # rows, equilibria, completeness
    method: str = "curve"
    # solution_id -> the step that failed for a real nonsingular row not fully proved
    not_proved: dict[int, str] = field(default_factory=dict)

    def record(self) -> dict:
        """The run.json `certificate` block."""
        from ...versions import dist_version

        return {
            "status": self.status,
            "statement": self.statement,
            "method": METHODS[self.method],
            "library": f"python-flint {dist_version('python-flint', 'flint')} (arb/acb)",
            "rows_certified": int(self.certified.sum()),
            "proved_equilibria": self.proved_equilibria,
            "kinds": {str(k): v for k, v in self.kinds.items()},
            "shortest_spring_bound": self.shortest_spring,
            "boxes_examined": self.boxes,
            "excluded_boxes": self.excluded_boxes,
            "undecided_boxes": [[float(v) for v in q] for q in self.undecided_boxes],
            "contradictions": self.contradictions,
            "not_proved": {str(k): v for k, v in self.not_proved.items()},
            "seconds": self.seconds,
            "timings": self.timings,
        }


def _kind(params: Params, pa, g: tuple[float, float]) -> str:
    """The kind of the critical point in the tiny box around g, from the interval Hessian."""
    q = (g[0] - ROOT_BOX, g[0] + ROOT_BOX, g[1] - ROOT_BOX, g[1] + ROOT_BOX)
    _, h = enclosures(pa, *box(*q))
    det = h[0][0] * h[1][1] - h[0][1] * h[1][0]
    if det < 0:
        return "saddle"
    if det > 0 and h[0][0] > 0:
        return "min"
    if det > 0 and h[0][0] < 0:
        return "max"
    return "undecided"


def _equilibria(params: Params, table) -> tuple[list[Known], dict, list[int]]:
    """Each physical row proved in a tiny box: (the proved ones, kinds by solution_id, rows
    not proved)."""
    pa = arb_params(params)
    known, kinds, failed = [], {}, []
    phys = np.flatnonzero(np.asarray(table["physical"], dtype=bool))
    for row in phys:
        g1 = math.radians(float(table["gamma1_deg"][row]))
        g2 = math.radians(float(table["gamma2_deg"][row]))
        q = (g1 - ROOT_BOX, g1 + ROOT_BOX, g2 - ROOT_BOX, g2 + ROOT_BOX)
        verdict, enclosure = krawczyk_2d(params, pa, q)
        sid = int(table["solution_id"][row])
        if verdict == "one":
            bounds = []
            for e in enclosure:
                bounds += [math.nextafter(float(e.lower()), -math.inf),
                           math.nextafter(float(e.upper()), math.inf)]  # fmt: skip
            known.append(Known(sid, q, tuple(bounds)))
            kinds[sid] = _kind(params, pa, (g1, g2))
        else:
            failed.append(sid)
    return known, kinds, failed


def certify_table(
    params: Params, table, short: float = SHORT, min_width: float = MIN_WIDTH,
    method: str = "curve",
) -> Certificate:  # fmt: skip
    """Prove each row of a solutions table and the completeness of its physical rows."""
    start = time.perf_counter()
    certified, radius = certify_rows(params, table)
    t_rows = time.perf_counter()
    known, kinds, unproved = _equilibria(params, table)
    t_known = time.perf_counter()
    proof = _completeness(params, known, short * params.L3, min_width, method)
    t_done = time.perf_counter()
    bound, meaning = spring_bound(proof)
    contradictions = [
        f"a critical point of V in gamma1 {math.degrees(q[0]):.6f}..{math.degrees(q[1]):.6f}, "
        f"gamma2 {math.degrees(q[2]):.6f}..{math.degrees(q[3]):.6f} deg is not in the table"
        for q in proof.missing
    ]
    contradictions += duplicates(known)
    found = {sid for sid, boxes in proof.roots.items() if boxes}
    aside = bound if meaning == "aside" else 0.0
    contradictions += _unmatched_rows(params, table, found | set(), unproved, aside)
    contradictions += kind_differences(table, kinds)
    singular = np.asarray(table["singular"], dtype=bool)
    open_rows = int((~certified & ~singular).sum())
    undecided = bool(proof.undecided) or open_rows > 0 or "undecided" in kinds.values()
    status = "contradiction" if contradictions else "undecided" if undecided else "proved"
    where = spring_clause(bound, meaning, " m", "both springs")
    failed = {int(s): ROOT_FAILED for s in np.asarray(table["solution_id"])[~certified & ~singular]}
    failed.update({s: KIND_FAILED for s, k in kinds.items() if k == "undecided"})
    statement = _statement(len(found), where, certified, singular, status, proof, open_rows)
    statement += f"; not proved: {not_proved_text(failed)}" if failed else ""
    timings = {"rows": t_rows - start, "equilibria": t_known - t_rows,
               "completeness": t_done - t_known}  # fmt: skip
    return Certificate(
        status, statement, certified, radius, len(found), kinds, bound, proof.boxes,
        len(proof.excluded), proof.undecided, contradictions, time.perf_counter() - start,
        timings, method, dict(sorted(failed.items())),
    )  # fmt: skip


def not_proved_text(failed: dict[int, str]) -> str:
    """The rows not proved, each with the step that failed ('' for none)."""
    return "; ".join(f"solution {s} ({why})" for s, why in sorted(failed.items()))


def _completeness(params: Params, known: list[Known], short: float, min_width: float,
                  method: str):  # fmt: skip
    """The search for critical points outside the known equilibria's boxes (`method`: 'curve',
    along the parallel curve, or 'torus', the two-dimensional branch and bound)."""
    if method == "curve":
        return search(params, known, short, min_width)
    if method != "torus":
        raise ValueError(f"method {method!r}: 'curve' or 'torus'")
    from .curve import interval

    balls = {k.sid: (interval(*k.enclosure[:2]), interval(*k.enclosure[2:])) for k in known}
    return branch_and_bound(params, balls, short, min_width)


def duplicates(known: list[Known]) -> list[str]:
    """Two rows proved in overlapping enclosures may be one equilibrium: a contradiction (any
    number of angles)."""

    def centre_half(k: Known, j: int) -> tuple[float, float]:
        lo, hi = k.enclosure[2 * j], k.enclosure[2 * j + 1]
        return 0.5 * (lo + hi), 0.5 * (hi - lo)

    out = []
    for n, a in enumerate(known):
        for b in known[n + 1 :]:
            overlap = True
            for j in range(len(a.enclosure) // 2):
                (ca, ha), (cb, hb) = centre_half(a, j), centre_half(b, j)
                overlap &= abs((ca - cb + math.pi) % (2 * math.pi) - math.pi) <= ha + hb
            if overlap:
                out.append(f"solutions {a.sid} and {b.sid} are proved in overlapping boxes: "
                           "they may be one equilibrium")  # fmt: skip
    return out


def _unmatched_rows(params, table, found: set, unproved: list, bound: float) -> list[str]:
    """Physical rows with springs longer than the bound that the proof did not find."""
    out = []
    free = {1: params.L01, 2: params.L02}
    for row in np.flatnonzero(np.asarray(table["physical"], dtype=bool)):
        sid = int(table["solution_id"][row])
        lengths = [float(table[f"d{i}"][row]) for i in (1, 2) if free[i]]
        if sid in found or (lengths and min(lengths) <= bound):
            continue  # proved, or where springs are too short to be looked at
        why = "its box failed the Krawczyk test" if sid in unproved else "no box holds it"
        out.append(f"solution {sid} is in the table as physical but not proved ({why})")
    return out


def kind_differences(table, kinds: dict[int, str]) -> list[str]:
    out = []
    for row, sid in enumerate(np.asarray(table["solution_id"], dtype=int)):
        proved = kinds.get(int(sid))
        said = str(table["kind"][row])
        if proved and proved != "undecided" and proved != said:
            out.append(
                f"solution {sid}: the table says {said}, the interval Hessian proves {proved}"
            )
    return out


def spring_bound(proof) -> tuple[float, str]:
    """(the bound on the springs with free lengths that a completeness search proves, what it
    is): 'aside' (boxes were set aside: the most the shortest spring may be in any of them),
    'floor' (none: a lower bound of every such spring's length over every box searched, so
    none reaches zero length), 'none' (no spring has a free length: 0) or 'open' (one may reach
    zero length in an undecided box: 0). Either way every equilibrium whose springs are all
    longer than the bound is proved."""
    if proof.excluded:
        return proof.longest_excluded, "aside"
    if proof.shortest_length == math.inf:
        return 0.0, "none"
    return (proof.shortest_length, "floor") if proof.shortest_length > 0 else (0.0, "open")


def spring_clause(bound: float, meaning: str, unit: str = "", springs: str = "every spring",
                  ) -> str:  # fmt: skip
    """The statement's words for `spring_bound` (an upper bound rounded up, a lower bound
    rounded down, to three digits)."""
    if meaning == "aside":
        return f"with {springs} longer than {_three_digits(bound, up=True)}{unit}"
    if meaning == "floor":
        return (f"(every spring with a free length is longer than "
                f"{_three_digits(bound, up=False)}{unit} in every pose: none reaches zero "
                "length)")  # fmt: skip
    if meaning == "none":
        return "(no spring has a free length)"
    return "(a spring with a free length may reach zero length in an undecided box)"


def _three_digits(x: float, up: bool) -> str:
    """x to three significant digits, rounded up or down (so a bound stays a bound)."""
    step = 10.0 ** (math.floor(math.log10(x)) - 2)
    n = math.ceil(x / step * (1 + 1e-12)) if up else math.floor(x / step * (1 - 1e-12))
    return f"{n * step:.3g}"


def _statement(n, where, certified, singular, status, proof, open_rows) -> str:
    text = f"proved: exactly {n} equilibria {where}; stability of each proved (interval Hessian)"
    if status == "undecided":
        text = (f"not proved: {len(proof.undecided)} boxes undecided, {open_rows} nonsingular "
                f"solutions not certified; {n} equilibria proved {where}")  # fmt: skip
    elif status == "contradiction":
        text = f"CONTRADICTION: the table and the proof differ ({n} equilibria proved {where})"
    return (
        f"{text}; {int(certified.sum())} of {len(certified)} solutions certified "
        f"({int(singular.sum())} singular double roots cannot be)"
    )
