"""Energy barriers between the stable states of a solve (cb.barriers): the paper's mechanism or
any framework, through one driver (analysis/barriers.py)."""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..analysis.barriers import MAX_STEPS, saddle_connections
from ..columns import reference
from ..errors import ParameterError
from ..fs import atomic_write_text, new_folder, write_csv
from ..model.framework.spec import Framework
from ..motion.flows import flow_of
from ..params import Params
from .solutions import Solutions

BARRIERS_CSV = "barriers.csv"


@dataclass(frozen=True)
class Barriers:
    """Every saddle's two descents and barriers (`table`, see docs/columns.md), `pairs` (the
    lowest saddle of each pair of minima: their barrier), and the paths by saddle_id (the
    paper's mechanism: (n, 2) arrays of angles in deg; a framework: DataFrames with `arc`,
    `energy`, the pose columns and link lengths of solutions.csv). Both tables are indexed by
    saddle_id, as the solutions table is by solution_id."""

    params: Params | Framework
    solutions: pd.DataFrame
    table: pd.DataFrame
    paths: dict = field(repr=False)
    seconds: float = 0.0
    max_steps: int = MAX_STEPS

    @property
    def pairs(self) -> pd.DataFrame:
        """One row per pair of distinct minima joined by a saddle: the lowest such saddle."""
        return self.table[self.table.lowest]

    @property
    def warnings(self) -> list[str]:
        """Descents that did not converge or did not end at a listed minimum, and paths through
        a spring of (near) zero length."""
        out = []
        for _, r in self.table.iterrows():
            if not r.converged:
                out.append(f"saddle {r.saddle_id}: a descent did not converge in "
                           f"{self.max_steps} steps")  # fmt: skip
            elif pd.isna(r.min_a) or pd.isna(r.min_b):
                out.append(f"saddle {r.saddle_id}: a descent did not end at a listed minimum")
            if r.crosses_zero_length:
                out.append(f"saddle {r.saddle_id}: a descent passes a spring of zero length")
        return out

    def plot(self, path: str | Path) -> list[Path]:
        """The paper's mechanism: the energy map with the descent paths; a framework: V along
        each descent (PNG and SVG, or the one suffix given)."""
        from ..plot.common import save

        if isinstance(self.params, Params):
            from ..plot.energy_map import barrier_figure

            return save(barrier_figure(self.params, self.solutions, self.paths), path)
        from ..plot.barrier_profile import barrier_profile_figure

        return save(barrier_profile_figure(self.params, self.table, self.paths), path)

    def save(self, folder: str | Path, plots: bool = True) -> Path:
        """barriers.csv, columns.md, barriers.json [, barriers.png/svg] in a new folder, built
        under a hidden name and renamed when complete."""
        with new_folder(folder) as work:
            write_csv(work / BARRIERS_CSV, self.table)
            table = "barriers" if isinstance(self.params, Params) else "framework_barriers"
            atomic_write_text(work / "columns.md", reference(table))
            record = {"params": self.params.as_dict(), **self.params.record_fields(),
                      "max_steps": self.max_steps, "seconds": self.seconds,
                      "warnings": self.warnings, "command": sys.argv[:]}  # fmt: skip
            atomic_write_text(work / "barriers.json", json.dumps(record, indent=2))
            if plots:
                self.plot(work / "barriers")
        return Path(folder)


def barriers(res: Solutions, max_steps: int = MAX_STEPS) -> Barriers:
    """For a solve (the paper's mechanism or a framework): every physical saddle's descents to
    the minima, and the barriers; each descent takes at most `max_steps` steps."""
    if isinstance(max_steps, bool) or not isinstance(max_steps, int | np.integer) or max_steps < 1:
        raise ParameterError(f"max_steps = {max_steps!r}: expected a whole number >= 1")
    if res.settings.only != "all":
        raise ParameterError(
            f"only = {res.settings.only!r}: barriers are read off the saddles between the "
            "minima, which that solve did not look for; solve with only='all'"
        )
    t0 = time.perf_counter()
    table, paths = saddle_connections(flow_of(res.params, res.table), res.table, int(max_steps))
    table = table.set_axis(pd.Index(table["saddle_id"].to_numpy(dtype=int)), axis=0)
    return Barriers(res.params, res.table, table, paths, time.perf_counter() - t0,
                    int(max_steps))  # fmt: skip
