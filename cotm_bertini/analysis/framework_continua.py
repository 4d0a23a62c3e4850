"""Continua of equilibria: curves of poses that are all equilibria (e.g. a spring at its free
length with every cable slack and no load), found from a solve's degenerate rows, traced to
their ends, reported apart from the isolated equilibria and counted in the Morse sum as the
components they are (docs/frameworks.md, "Continua of equilibria").

A continuum is a positive-dimensional solution set of one taut set's polynomial system F = 0:
along it the Jacobian of F loses rank. It is traced by pseudo-arclength continuation (Newton on
F = 0 and one hyperplane across the tangent) until a cable changes state (a slack one reaches its
free length, a taut one its zero tension), a length reaches zero, or the curve closes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.framework.compiled import FrameworkSystem, framework_system, slot_vector
from ..model.framework.spec import Framework
from ..model.framework.units import normalized_slots
from .framework_classify import described, local_hessian, reduced_eigh

STEP = 0.02  # first pseudo-arclength step (normalised variables: c, s of a rotation ~ 1)
STEP_MAX = 0.05
STEP_MIN = 1e-7
MAX_STEPS = 20000
RESIDUAL = 1e-11  # |F| / its largest coefficient at a point of the curve
NULL = 1e-6  # singular values below this (relative) span the Jacobian's null space
MARGIN = 1e-9  # a state margin (normalised length) below -MARGIN has crossed


@dataclass(frozen=True, eq=False)
class Continuum:
    """One traced continuum: its taut set, points along it, what ends it, its energy."""

    fs: FrameworkSystem
    dimension: int
    closed: bool
    points: np.ndarray  # solutions of fs (normalised), in order along the curve
    ends: tuple[str, ...]  # what ends it at its first and last point (none when closed)
    end_kinds: tuple[str, ...]  # per end: "slack" (a slack cable reaches L0) or "other"
    energy: np.ndarray  # V at each point (user units)
    index: int | None  # Morse index across it (None: degenerate or changing somewhere)
    columns: dict  # the pose, link and energy columns of its points (described)
    system: object  # fs's PolySystem at this point's slots, and its rows' scale
    scale: np.ndarray

    @property
    def taut(self) -> tuple[str, ...]:
        return self.fs.taut

    def morse(self) -> tuple[int | None, str]:
        """Its term in the Morse sum, or None and why it has none (docs/frameworks.md)."""
        if self.dimension != 1:
            return None, f"a {self.dimension}-dimensional continuum"
        if self.index is None:
            return None, "its Hessian across the curve is degenerate or changes sign"
        if self.closed:
            return 0, ""  # Morse-Bott circle: (-1)^index chi(S1) = 0
        if self.index == 0 and self.end_kinds == ("slack", "slack"):
            return 1, ""  # an attracting arc of minima: chi(arc) = 1 (Conley index)
        return None, "an arc of " + ("minima" if self.index == 0 else "saddles") + \
            " not ended by slack cables reaching their free length on both sides"  # fmt: skip


def find_continua(fw: Framework, parts: list, unit, tol) -> list[Continuum]:
    """The continua through the physical degenerate rows of `parts` ((columns, fs, x) per taut
    set), each traced once, ordered by taut set and pose."""
    found: list[Continuum] = []
    for cols, fs, x in parts:
        for row in np.flatnonzero(cols["physical"] & (cols["kind"] == "degenerate")):
            for sub in _systems(fw, fs, cols, row):
                xs = restrict(fs, sub, x[row].real)
                if any(c.fs.key == sub.key and on_continuum(c, xs) for c in found):
                    break
                c = _trace_from(fw, sub, xs, unit, tol)
                if c is not None:
                    found.append(c)
                    break
    return sorted(found, key=lambda c: (c.taut, tuple(np.round(c.points.min(axis=0), 6))))


def absorb(parts: list, continua: list[Continuum]) -> None:
    """Rows that lie on a continuum are no isolated equilibria: not physical, reason
    `continuum:N` (in place)."""
    for cols, fs, x in parts:
        for row in np.flatnonzero(cols["physical"] & (cols["kind"] == "degenerate")):
            for n, c in enumerate(continua, start=1):
                if set(c.taut) <= set(fs.taut) and on_continuum(c, restrict(fs, c.fs, x[row].real)):
                    cols["physical"][row] = cols["stable"][row] = False
                    cols["kind"][row] = ""
                    cols["reason"][row] = f"continuum:{n}"
                    break


def _systems(fw: Framework, fs: FrameworkSystem, cols: dict, row: int) -> list:
    """The taut sets whose curve may pass through a row: its own, and its own without the
    cables at their free length there (where the curve of the slack side ends)."""
    slots = fw.slots()
    L0 = {c: slots[f"L0_{c}"] for c in fs.taut}
    at_l0 = [c for c in fs.taut if abs(cols[f"{c}.length"][row] - L0[c]) <= 1e-6 * max(1, L0[c])]
    subs = [fs]
    if at_l0:
        subs.append(framework_system(fw, tuple(c for c in fs.taut if c not in at_l0)))
    return subs


def restrict(src: FrameworkSystem, dst: FrameworkSystem, x: np.ndarray) -> np.ndarray:
    """A solution of `src` as a point of `dst`'s variables (dst's taut set within src's)."""
    where = {v: k for k, v in enumerate(src.ps.variables)}
    return np.array([x[where[v]] for v in dst.ps.variables], dtype=float)


def _system(fw: Framework, fs: FrameworkSystem):
    slots_n = normalized_slots(fw)
    system = fs.ps.instantiate([slots_n[n] for n in fs.ps.parameters])
    return system, system.scale()


def _correct(system, scale, x: np.ndarray, t: np.ndarray, through: np.ndarray):
    """Newton on F = 0 and t . (x - through) = 0 from x: (the point, converged)."""
    for _ in range(12):
        F, J = system.value_and_jacobian(x)
        F, J = F[0].real / scale, J[0].real / scale[:, None]
        if np.abs(F).max() <= RESIDUAL and _ > 0:
            return x, True
        A = np.vstack([J, t])
        b = -np.concatenate([F, [t @ (x - through)]])
        x = x + np.linalg.lstsq(A, b, rcond=None)[0]
    F = system.evaluate(x)[0].real / scale
    return x, bool(np.abs(F).max() <= RESIDUAL)


def _null(system, scale, x: np.ndarray) -> np.ndarray:
    """An orthonormal basis (rows) of the null space of F's Jacobian at x."""
    J = system.jacobian(x)[0].real / scale[:, None]
    _, s, vt = np.linalg.svd(J)
    return vt[s <= NULL * max(1.0, s.max())]


def on_continuum(c: Continuum, x: np.ndarray) -> bool:
    """Whether x (a solution of c's system) lies on c: within a step of a traced point and
    Newton across the tangent there lands on x."""
    k = int(np.argmin(np.linalg.norm(c.points - x, axis=1)))
    if np.linalg.norm(c.points[k] - x) > 2 * STEP_MAX:
        return False
    system, scale = c.system, c.scale
    null = _null(system, scale, c.points[k])
    if len(null) != 1:
        return False
    y, ok = _correct(system, scale, c.points[k], null[0], x)
    return ok and np.linalg.norm(y - x) < 1e-6


def _trace_from(fw, fs, x0, unit, tol) -> Continuum | None:
    """The continuum of fs's solutions through x0, or None when x0 is an isolated solution."""
    system, scale = _system(fw, fs)
    x0, ok = _correct(system, scale, x0, np.zeros_like(x0), x0)
    null = _null(system, scale, x0) if ok else np.zeros((0, len(x0)))
    if not len(null) or not all(_moves(system, scale, x0, v) for v in null):
        return None
    if len(null) > 1:  # a surface or more: reported, not traced
        return _continuum(fw, fs, len(null), False, x0[None], ("not traced",) * 2, unit, tol)
    forward, end_f, closed = _trace(fw, fs, system, scale, x0, null[0], unit, tol)
    if closed:
        return _continuum(fw, fs, 1, True, forward, (), unit, tol)
    backward, end_b, _ = _trace(fw, fs, system, scale, x0, -null[0], unit, tol)
    points = np.vstack([backward[::-1], forward[1:]])
    return _continuum(fw, fs, 1, False, points, (end_b, end_f), unit, tol)


def _moves(system, scale, x0, v, h: float = 1e-3) -> bool:
    """Whether the solutions go on along null direction v (a curve), not back to x0 (an
    isolated singular root)."""
    y, ok = _correct(system, scale, x0 + h * v, v, x0 + h * v)
    return ok  # the hyperplane holds y at distance h along v from x0


def _margins(fw: Framework, fs: FrameworkSystem, X: np.ndarray, unit, tol) -> tuple:
    """Per point, every state condition as a margin (>= 0 holds; normalised lengths) and each
    margin's (what crossing it means, its kind)."""
    cols = described(fw, fs, X, unit, tol)[0]
    slots, L = fw.slots(), unit[0]
    out, names = [], []
    for x in fw.links:
        if x.kind == "bar" or f"{x.name}.length" not in cols:
            continue
        length, L0 = cols[f"{x.name}.length"] / L, slots[f"L0_{x.name}"] / L
        if x.kind == "cable" and x.name not in fs.taut:
            out.append(L0 - length)
            names.append((f"cable {x.name} reaches its free length (turns taut)", "slack"))
        elif x.kind == "cable":
            out.append(length - L0)
            names.append((f"cable {x.name} reaches its free length (turns slack)", "other"))
        if L0 > 0 and x.kind == "spring":
            out.append(length)
            names.append((f"spring {x.name} reaches zero length", "other"))
    return np.array(out).T.reshape(len(X), -1), names


def _trace(fw, fs, system, scale, x0, t, unit, tol) -> tuple:
    """Points from x0 along tangent t until a margin crosses zero or the curve closes:
    (points, what ends it, closed)."""
    points, h, length = [x0], STEP, 0.0
    x = x0
    for _ in range(MAX_STEPS):
        y, ok = _correct(system, scale, x + h * t, t, x + h * t)
        t_new = _null(system, scale, y) if ok else np.zeros((0, len(x)))
        if len(t_new) != 1 or abs(t_new[0] @ t) < 0.9:
            h /= 2
            if h < STEP_MIN:
                return np.array(points), "a singular point (the curve branches or ends)", False
            continue
        margin, names = _margins(fw, fs, y[None], unit, tol)
        if (margin[0] < -MARGIN).any():
            end, what = _bisect(fw, fs, system, scale, x, t, h, unit, tol)
            return np.array([*points, end]), names[what][0], False
        length += np.linalg.norm(y - x)
        x, t = y, t_new[0] * np.sign(t_new[0] @ t)
        points.append(x)
        if length > 4 * STEP_MAX and np.linalg.norm(x - x0) < 1.5 * h:
            return np.array(points), "", True
        h = min(h * 1.5, STEP_MAX)
    return np.array(points), f"not ended within {MAX_STEPS} steps", False


def _bisect(fw, fs, system, scale, x, t, h, unit, tol) -> tuple[np.ndarray, int]:
    """The point between x and a step h along t where the first margin reaches zero."""
    lo, hi, best = 0.0, h, x
    what = 0
    for _ in range(60):
        mid = (lo + hi) / 2
        y, ok = _correct(system, scale, x + mid * t, t, x + mid * t)
        margin = _margins(fw, fs, y[None], unit, tol)[0][0]
        if ok and (margin >= -MARGIN * 1e-3).all():
            lo, best = mid, y
        else:
            hi = mid
            what = int(np.argmin(margin))
        if hi - lo < 1e-13:
            break
    return best, what


def _continuum(fw, fs, dim, closed, points, ends, unit, tol) -> Continuum:
    """A Continuum with its energy and its Morse index across the curve at every point."""
    cols = described(fw, fs, points, unit, tol)[0]
    kinds = tuple("slack" if e.startswith("cable") and "turns taut" in e else "other"
                  for e in ends)  # fmt: skip
    index = _index_across(fw, fs, points, tol) if dim == 1 else None
    system, scale = _system(fw, fs)
    return Continuum(fs, dim, closed, points, ends, kinds, cols["energy"], index, cols, system,
                     scale)  # fmt: skip


def _index_across(fw, fs, points, tol) -> int | None:
    """The number of negative reduced-Hessian eigenvalues when exactly one is zero (along the
    curve) at every point and that number never changes, else None."""
    P = slot_vector(normalized_slots(fw))
    H, G = local_hessian(fs, points, P)
    found = set()
    for k in range(len(points)):
        eig = reduced_eigh(H[k], G[k])[0]
        limit = tol.hessian * max(1.0, float(np.abs(H[k]).max()))
        if int((np.abs(eig) <= limit).sum()) != 1:
            return None
        found.add(int((eig < -limit).sum()))
    return found.pop() if len(found) == 1 else None


def continuum_record(c: Continuum, n: int) -> dict:
    """What run.json, continua.csv and the console say of continuum n (docs/frameworks.md)."""
    term, why = c.morse()
    shape = "closed curve" if c.closed else "arc" if c.dimension == 1 else "not traced"
    kind = {0: "neutral minima", None: "degenerate across the curve"}.get(
        c.index, f"neutral saddles (index {c.index} across)"
    )
    pose = [n for n in c.columns if n.endswith(".angle_deg")]
    ends = [] if c.closed else [
        {"by": by, **{p: float(c.columns[p][k]) for p in pose}}
        for by, k in zip(c.ends, (0, -1), strict=True)
    ]  # fmt: skip
    return {"continuum": n, "taut_set": " ".join(c.taut) or "none", "dimension": c.dimension,
            "shape": shape, "kind": kind, "index_across": c.index,
            "energy": float(np.mean(c.energy)),
            "energy_spread": float(np.ptp(c.energy)), "extent": _extent(c), "ends": ends,
            "points": len(c.points), "morse_term": term, "morse_note": why}  # fmt: skip


def _extent(c: Continuum) -> dict[str, list[float]]:
    """Each body angle's range along the curve (degrees, from its lower end; the interior
    extremes refined on the curve by golden section), [0, 360] where it winds around."""
    out = {}
    for body in [n[:-10] for n in c.columns if n.endswith(".angle_deg")]:
        k = (c.fs.ps.variables.index(f"c_{body}"), c.fs.ps.variables.index(f"s_{body}"))
        turn = np.unwrap(np.arctan2(c.points[:, k[1]], c.points[:, k[0]]))
        if np.ptp(turn) >= 2 * np.pi - 1e-6:
            out[f"{body}.angle_deg"] = [0.0, 360.0]
            continue
        lo = _refined(c, k, turn, int(np.argmin(turn)), -1.0)
        hi = _refined(c, k, turn, int(np.argmax(turn)), 1.0)
        start = np.degrees(lo) % 360.0
        out[f"{body}.angle_deg"] = [float(start), float(start + np.degrees(hi - lo))]
    return out


def _refined(c: Continuum, k, turn, i: int, sign: float) -> float:
    """The extreme of an angle near traced point i (unwrapped like `turn`): the point itself at
    an end of an arc, else the extreme over the curve within a step of it."""
    if not c.closed and i in (0, len(c.points) - 1):
        return float(turn[i])
    x = c.points[i]
    t = _null(c.system, c.scale, x)[0]

    def angle(s: float) -> float:
        y = _correct(c.system, c.scale, x + s * t, t, x + s * t)[0]
        a = np.arctan2(y[k[1]], y[k[0]])
        return float(turn[i] + (a - turn[i] + np.pi) % (2 * np.pi) - np.pi)

    a, b, g = -STEP_MAX, STEP_MAX, (np.sqrt(5) - 1) / 2
    for _ in range(60):
        m1, m2 = b - g * (b - a), a + g * (b - a)
        if sign * angle(m1) > sign * angle(m2):
            b = m2
        else:
            a = m1
    return sign * max(sign * angle((a + b) / 2), sign * turn[i])
