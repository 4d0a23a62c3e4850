"""Shared by the figures: atomic writing of PNG/SVG/PDF, titles, labels, styles.

matplotlib is used through its object-oriented API (`Figure`, no pyplot): the global backend is
never switched, and only the plot modules import it.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterable, Mapping
from pathlib import Path

import matplotlib
import numpy as np
import pandas as pd
from matplotlib import cbook
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.font_manager import FontProperties
from matplotlib.text import Text
from matplotlib.textpath import text_to_path

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


# A title (or caption) fills at most this share of its room: the outlines are measured, and
# hinting draws the PNG's text up to ~3 % wider than its outline.
_TITLE_SHARE = 0.92
_LINE_SPACING = 1.2  # matplotlib's: a line of text is 1.2 font sizes high


def set_title(target: Figure | Axes, text: str, fontsize: float = 10, **kw) -> Text:
    """A figure's suptitle or an Axes' title, broken to fit (see fit_text), so no title runs
    off the figure; the figure grows by the height of the lines the breaks add."""
    fig = target if isinstance(target, Figure) else target.get_figure(root=True)
    room = fig.get_figwidth()  # a suptitle is centred on the figure
    if isinstance(target, Axes):
        # An Axes' title is centred on the Axes: its columns' share of the figure (a title
        # wider than the Axes makes the layout move the Axes in, off its colour bar's side).
        spec = target.get_subplotspec()
        cols = spec.get_gridspec().ncols if spec else 1
        span = spec.colspan.stop - spec.colspan.start if spec else 1
        room *= span / cols
    wrapped = fit_text(text, room, fontsize, kw.get("fontweight", "normal"))
    added = wrapped.count("\n") - text.count("\n")
    if added:  # the figure was sized for the title as written: keep the plots' room
        fig.set_figheight(fig.get_figheight() + added * _LINE_SPACING * fontsize / 72.0)
    if isinstance(target, Figure):
        return target.suptitle(wrapped, fontsize=fontsize, **kw)
    return target.set_title(wrapped, fontsize=fontsize, **kw)


def fit_text(text: str, room: float, fontsize: float, fontweight: str = "normal") -> str:
    """`text` with every line wider than `_TITLE_SHARE` of `room` (inches) broken between list
    items, or between words where one item is wider than that."""
    prop = FontProperties(size=fontsize, weight=fontweight)
    width = _TITLE_SHARE * 72.0 * room
    return "\n".join(_wrap(line, width, prop) for line in text.split("\n"))


def _wrap(line: str, width: float, prop: FontProperties) -> str:
    """`line` on as few lines of at most `width` points as the greedy fill needs, balanced:
    the narrowest width (not under the widest item) that needs no more lines."""
    if _width(line, prop) <= width:
        return line
    count = len(_fill(line, width, prop))
    lo = min(width, max(_width(item, prop) for item in _items(line)))
    hi = width
    for _ in range(8):  # bisection to within width / 256
        mid = (lo + hi) / 2
        lo, hi = (lo, mid) if len(_fill(line, mid, prop)) <= count else (mid, hi)
    return "\n".join(_fill(line, hi, prop))


def _fill(line: str, width: float, prop: FontProperties) -> list[str]:
    """Greedy fill: list items joined while they fit in `width` points; an item wider than
    that on lines of its own, broken between words."""
    out: list[str] = []
    for piece in _items(line):
        if out and _width(f"{out[-1]} {piece}", prop) <= width:
            out[-1] += f" {piece}"
            continue
        words = piece.split(" ")
        out.append(words[0])
        for word in words[1:]:
            if _width(f"{out[-1]} {word}", prop) <= width:
                out[-1] += f" {word}"
            else:
                out.append(word)
    return out


def _items(line: str) -> list[str]:
    """`line` split after each ", " or "; " outside brackets: "k1 = 2.81" and "V(g1, g2)" stay
    whole."""
    items, depth, start = [], 0, 0
    for i, char in enumerate(line):
        depth += (char in "([{") - (char in ")]}")
        if char in ",;" and depth == 0 and line[i + 1 : i + 2] == " ":
            items.append(line[start : i + 1])
            start = i + 2
    return [*items, line[start:]]


def _width(text: str, prop: FontProperties) -> float:
    """The width of one line of text in points (mathtext measured as drawn)."""
    ismath = "TeX" if matplotlib.rcParams["text.usetex"] else cbook.is_math_text(text)
    return text_to_path.get_text_width_height_descent(text, prop, ismath)[0]


def values_line(values: Mapping[str, float], leave_out: Iterable[str] = ()) -> str:
    """Parameter values as "name = value, ..." (the ones in `leave_out` left out)."""
    skip = set(leave_out)
    return ", ".join(f"{name} = {v:g}" for name, v in values.items() if name not in skip)


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


def cube(limits: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """Axis limits widened to a cube around their middle: one scale on every axis of a 3-D
    panel (a flat pose stays flat, not blown up to its round-off)."""
    half = max(hi - lo for lo, hi in limits) / 2
    return [((lo + hi) / 2 - half, (lo + hi) / 2 + half) for lo, hi in limits]
