"""The figures of a run folder: configurations.* and energy_map.*."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..params import Params
from .configurations import plot_configurations
from .energy_map import plot_energy_map


def plot_run(params: Params, solutions: pd.DataFrame, folder: str | Path) -> list[Path]:
    """Both figures into a run folder: configurations.{png,svg} and energy_map.{png,svg}; for a
    framework its configurations."""
    folder = Path(folder)
    if not isinstance(params, Params):
        from .framework import plot_framework

        return plot_framework(params, solutions, folder / "configurations")
    return plot_configurations(params, solutions, folder / "configurations") + plot_energy_map(
        params, solutions, folder / "energy_map"
    )
