"""Energy barriers between the stable states of a solve (cb.barriers)."""

from __future__ import annotations

import json
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from ..columns import reference
from ..fs import atomic_write_text, new_folder, write_csv
from ..params import Params
from .solutions import Solutions, paper_only

BARRIERS_CSV = "barriers.csv"


@dataclass(frozen=True)
class Barriers:
    """Every saddle's two descents and barriers (`table`, see docs/columns.md), `pairs` (the
    lowest saddle of each pair of minima: their barrier), and the paths (deg) by saddle_id.
    Both tables are indexed by saddle_id, as the solutions table is by solution_id."""

    params: Params
    solutions: pd.DataFrame
    table: pd.DataFrame
    paths: dict = field(repr=False)
    seconds: float = 0.0

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
            if not r.converged or pd.isna(r.min_a) or pd.isna(r.min_b):
                out.append(f"saddle {r.saddle_id}: a descent did not end at a listed minimum")
            if r.crosses_zero_length:
                out.append(f"saddle {r.saddle_id}: a descent passes a spring of zero length")
        return out

    def plot(self, path: str | Path) -> list[Path]:
        """The energy map with the descent paths (PNG and SVG, or the one suffix given)."""
        from ..plot.common import save
        from ..plot.energy_map import barrier_figure

        return save(barrier_figure(self.params, self.solutions, self.paths), path)

    def save(self, folder: str | Path, plots: bool = True) -> Path:
        """barriers.csv, columns.md, barriers.json [, barriers.png/svg] in a new folder, built
        under a hidden name and renamed when complete."""
        with new_folder(folder) as work:
            write_csv(work / BARRIERS_CSV, self.table)
            atomic_write_text(work / "columns.md", reference("barriers"))
            record = {"params": self.params.as_dict(), "seconds": self.seconds,
                      "warnings": self.warnings, "command": sys.argv[:]}  # fmt: skip
            atomic_write_text(work / "barriers.json", json.dumps(record, indent=2))
            if plots:
                self.plot(work / "barriers")
        return Path(folder)


def barriers(res: Solutions) -> Barriers:
    """For a solve: every physical saddle's descents to the minima, and the barriers."""
    from ..analysis.barriers import saddle_connections

    paper_only(res, "barriers")
    t0 = time.perf_counter()
    table, paths = saddle_connections(res.params, res.table)
    table = table.set_axis(pd.Index(table["saddle_id"].to_numpy(dtype=int)), axis=0)
    return Barriers(res.params, res.table, table, paths, time.perf_counter() - t0)
