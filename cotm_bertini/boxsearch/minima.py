"""Which critical points a search found are proved local minima: the stable equilibria of a
search that looked for them alone (`only="stable"`, boxsearch.stability).

Each point x is wrapped in a box of half-width RADIUS; the Krawczyk test proves exactly one
critical point in it, and the Hessian's enclosure over it decides: positive definite (a strict
local minimum, proved), or negative along some direction (none, proved), or neither (a
degenerate point, or one the enclosure is too wide for: not proved either way).
"""

from __future__ import annotations

import numpy as np

from ..model.intervals import Interval
from .boxes import BoxLandscape, krawczyk
from .stability import no_minimum, positive_definite

RADIUS = 1e-7  # rad: the box around each point


def proved_minima(land: BoxLandscape, points: np.ndarray) -> np.ndarray:
    """(R,) +1 where a strict local minimum is proved within RADIUS of each point (R, n), -1
    where no minimum is (the critical point there is a saddle or a maximum), 0 undecided."""
    out = np.zeros(len(points), dtype=np.int8)
    if not len(points):
        return out
    lo, hi = points - RADIUS, points + RADIUS
    _, _, states = land.enclose(Interval(lo, hi))
    H = land.hessian(Interval(lo, hi), states)
    one = krawczyk(land, lo, hi, states, h=H)[0] == 1
    out[one & positive_definite(H)] = 1
    out[no_minimum(H)] = -1
    return out
