"""Shared by the figures: atomic writing of PNG/SVG/PDF, labels, styles.

matplotlib is used through its object-oriented API (`Figure`, no pyplot): the global backend is
never switched, and only the plot modules import it.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from ..fs import file_mode
from ..params import PARAM_UNITS, Params

FORMATS = ("png", "svg")
SUFFIXES = (".png", ".svg", ".pdf")


def save(fig: Figure, path: str | Path, dpi: int = 110) -> list[Path]:
    """Write `<path>.png` and `<path>.svg`, or only `path` if it ends in .png, .svg or .pdf;
    each file through a temporary file and os.replace."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.suffix.lower() in SUFFIXES:
        targets = [path]
    else:
        targets = [path.with_name(f"{path.name}.{fmt}") for fmt in FORMATS]
    for target in targets:
        fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.", suffix=".tmp")
        os.fchmod(fd, file_mode())  # as an ordinary file (mkstemp's are 0600)
        os.close(fd)
        try:
            # Reproducible SVG: fixed id salt, no date stamp.
            with matplotlib.rc_context({"svg.hashsalt": "cotm-bertini"}):
                fig.savefig(tmp, format=target.suffix[1:].lower(), dpi=dpi, metadata={"Date": None})
            os.replace(tmp, target)
        except BaseException:
            Path(tmp).unlink(missing_ok=True)
            raise
    return targets


def describe(params: Params) -> str:
    """One line with the parameters a figure depends on most."""
    return (
        f"L3 = {params.L3:g} m, k1 = {params.k1:g} N/m, k2 = {params.k2:g} N/m, "
        f"L01 = {params.L01:g} m, L02 = {params.L02:g} m"
    )


def param_label(name: str) -> str:
    """An axis label: the parameter and its unit."""
    unit = PARAM_UNITS.get(name)
    return f"{name} ({unit})" if unit else name


def flag(table: pd.DataFrame, column: str) -> np.ndarray:
    """A boolean column as a numpy array (False where missing or NaN)."""
    if column not in table:
        return np.zeros(len(table), dtype=bool)
    return table[column].fillna(False).astype(bool).to_numpy()


def physical_rows(solutions: pd.DataFrame) -> pd.DataFrame:
    """The physical rows of a solutions table (none if the column is missing)."""
    if len(solutions) == 0 or "physical" not in solutions:
        return solutions.iloc[0:0]
    return solutions[solutions["physical"].astype(bool)]
