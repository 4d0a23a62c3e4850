"""One stable state followed quasi-statically along an actuator path, snapping where it ends.

Written once for every model through the barriers' driver model (analysis/barriers.Flow: the
paper's angles on the torus, a framework's state on its constraint set). At each step the
state is continued by Newton's method on grad V = 0 from the previous step's state, accepted
only while the (reduced) Hessian stays positive definite, Newton converges and the state moves
less than MAX_MOVE: the state is still a minimum, on the same branch. A refused step is
halved; once the step is shorter than LOCATE (in path position, 1 a segment) the state has
ended there. A fold if the softest eigenvalue has fallen below FOLD_EIG (normalised units), a
cable switch if a cable is within SWITCH_GAP of its free length (V is piecewise; a state that
crosses a switch smoothly is followed through it), else unexplained (reported). The snap: just
past the end, a kick of KICK along the softest eigenvector, to the side of lower energy, then
gradient flow (analysis/barriers.descend) to the minimum the state falls into. A descent that
ends nowhere (no minimum within its steps) ends the move; one that ends within SAME_STATE of
where it began (`degenerate`: a cusp or a pitchfork on the path, where the state goes on without
falling but which branch it takes is not the model's to say) goes on with a warning: reported,
never guessed.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..analysis.barriers import Flow, descend, newton_done
from ..errors import ParameterError
from ..progress import Progress
from .path import ActuatorPath

NEWTON_ITERATIONS = 40
NEWTON_RANGE = 0.1  # a Newton step longer than this (local coordinates) is refused
MAX_MOVE = 0.1  # a step moving the state farther (local coordinates) is refined
LOCATE = 1e-10  # path position: a state's end is located to this
FOLD_EIG = 1e-3  # softest normalised eigenvalue at an end below this: a fold
SWITCH_GAP = 1e-6  # |d - L0| under this (length units) at an end: a cable switch
KICK = 1e-3  # the first step off a fold along its soft direction (local coordinates)
SAME_STATE = 1e-4  # a descent ending this close to where the state ended fell nowhere


WARNINGS = {
    "unexplained": "with neither a soft Hessian nor a cable at its switch",
    "degenerate": "at a singular point it passes without falling (a cusp or a pitchfork on the "
    "path): it goes on to the minimum next to it, a branch the model does not choose",
}


@dataclass(frozen=True)
class Snap:
    """Where the followed state ended (path position `s`, just past it `s_after`) and the
    minimum it fell into (`after` None: the descent found none)."""

    s: float
    s_after: float
    kind: str  # fold, cable_switch, unexplained or degenerate
    before: np.ndarray
    after: np.ndarray | None
    released: float  # J: V(before) - V(after), both at s_after
    softest: float  # the softest normalised eigenvalue of the state at s
    cable_gap: float  # the smallest |d - L0| of a cable at s (length units)
    descent_steps: int


@dataclass
class Followed:
    """What the follower did: one entry a recorded state (path position, state, event)."""

    s: list[float] = field(default_factory=list)
    states: list[np.ndarray] = field(default_factory=list)
    events: list[str] = field(default_factory=list)  # step, snap_from or snap_to
    snaps: list[Snap] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    newton_solves: int = 0
    refused: int = 0

    def add(self, s: float, x: np.ndarray, event: str) -> None:
        """Record the state x at path position s."""
        self.s.append(float(s))
        self.states.append(np.array(x, dtype=float))
        self.events.append(event)


def settle(flow: Flow, x: np.ndarray) -> np.ndarray | None:
    """The minimum of V that Newton's method reaches from x (None: the Hessian is not positive
    definite on the way, a step is too long, the state moves too far or Newton stalls)."""
    y, moved, last = np.array(x, dtype=float), 0.0, np.inf
    for _ in range(NEWTON_ITERATIONS):
        step = flow.newton(y, flow.gradient(y))
        if step is None:
            return None
        size = float(np.abs(step).max())
        moved += size
        if size > NEWTON_RANGE or moved > MAX_MOVE:
            return None
        y = flow.move(y, step)
        if newton_done(size, last, flow.newton_tol):
            return y if flow.newton(y, flow.gradient(y)) is not None else None
        last = size
    return None


def follow(
    flow_at: Callable[[dict[str, float]], Flow],
    path: ActuatorPath,
    x0: np.ndarray,
    steps: int,
    progress: bool = False,
) -> Followed:
    """Follow the minimum x0 (a state at the path's first waypoint) along the path, `steps`
    recorded steps a segment, snapping where it ends (see the module docstring)."""
    out = Followed()
    x = settle(flow_at(path.at(0.0)), x0)
    if x is None:
        raise ParameterError("state: not a minimum of V at the path's start (Newton fails there)")
    out.add(0.0, x, "step")
    grid = np.linspace(0.0, path.segments, steps * path.segments + 1)
    s, h = 0.0, float(grid[1])
    with Progress("move", len(grid) - 1, "steps", force=progress) as report:
        for target in grid[1:]:
            while s < target:
                h = min(h, target - s)
                y = settle(flow_at(path.at(s + h)), x)
                out.newton_solves += 1
                if y is not None:
                    x, s, h = y, s + h, 2 * h
                    continue
                out.refused += 1
                if h > LOCATE:
                    h /= 2
                    continue
                snap = _snap(flow_at, path, s, s + h, x)
                out.snaps.append(snap)
                out.add(s, x, "snap_from")
                if snap.after is None:
                    out.warnings.append(
                        f"the snap at path position {s:.10g} ({_values(path, s)}) ends at no "
                        f"minimum within {snap.descent_steps} descent steps: the move stops there"
                    )
                    return out
                if snap.kind in WARNINGS:
                    out.warnings.append(f"the state ended at path position {s:.10g} "
                                        f"({_values(path, s)}) {WARNINGS[snap.kind]}")  # fmt: skip
                x, s, h = snap.after, s + h, float(grid[1])
                out.add(s, x, "snap_to")
            out.add(target, x, "step")
            report.update(1)
    return out


def _values(path: ActuatorPath, s: float) -> str:
    return ", ".join(f"{n} = {v:.10g}" for n, v in path.at(s).items())


def _snap(flow_at, path: ActuatorPath, s: float, s_after: float, x: np.ndarray) -> Snap:
    """The end of the followed state at s (a state located to LOCATE) and where it falls."""
    before, after = flow_at(path.at(s)), flow_at(path.at(s_after))
    eig, vec = before.eigh(x)
    softest = float(eig.min()) / before.hessian_unit if len(eig) else 0.0
    gap = before.cable_gap(x)
    if gap < SWITCH_GAP * before.length_unit:
        kind = "cable_switch"
    elif softest < FOLD_EIG:
        kind = "fold"
    else:
        kind = "unexplained"
    start = x
    if len(eig):
        kicks = [after.move(x, sign * KICK * vec[:, 0]) for sign in (1.0, -1.0)]
        start = min(kicks, key=after.energy)
    d = descend(after, start)
    end = d.path[-1] if d.converged else None
    released = after.energy(x) - after.energy(end) if end is not None else float("nan")
    if end is not None and float(np.abs(end - x).max()) < SAME_STATE:
        kind = "degenerate"  # it fell nowhere: a cusp or a pitchfork on the path
    return Snap(s, s_after, kind, np.array(x), end, released, softest, gap, len(d.path) - 1)
