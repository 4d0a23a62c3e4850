"""The energy flow of a solve's mechanism (analysis/barriers.py's driver model): the paper's
PaperFlow or a framework's FrameworkFlow, with the solve's minima to say where a descent ended.
Barriers descend on it at the solve's parameter values; a move at every step of its path."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..analysis.barriers import Flow, PaperFlow
from ..model.framework.spec import Framework
from ..params import Params

MATCH_POSE = 1e-7  # a framework's descent end this close (match coordinates) is that minimum


def flow_of(model: Params | Framework, table: pd.DataFrame) -> Flow:
    """The driver's model of `model` (the paper's Params or a cb.Framework) at its values;
    `table` (its solutions) names the minima a state can be matched to."""
    if isinstance(model, Params):
        return PaperFlow(model, table)
    from ..analysis.framework_flow import FrameworkFlow
    from ..continuation.framework import pose_names

    return FrameworkFlow(model, pose_names(model), _matcher(model, table))


def _matcher(fw: Framework, table: pd.DataFrame):
    """Which physical minimum of `table` a descent's end row is: the nearest in the sweeps'
    match coordinates (cos, sin of angles, quaternions, positions and link lengths over the
    length unit), if within MATCH_POSE."""
    from ..continuation.framework import match_coordinates

    phys = table[table.physical.astype(bool)]
    minima = phys[phys.kind == "min"]
    ref = match_coordinates(fw, minima.assign(point=0)).real if len(minima) else None

    def match(rows: pd.DataFrame) -> int | None:
        if ref is None:
            return None
        end = rows.assign(point=0, is_real=True, max_imag=0.0)
        dist = np.abs(ref - match_coordinates(fw, end).real[0]).max(axis=1)
        k = int(np.argmin(dist))
        return int(minima.solution_id.iloc[k]) if dist[k] < MATCH_POSE else None

    return match
