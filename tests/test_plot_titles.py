"""Issue 27 item 5: every figure the commands write keeps its text inside the canvas, with a long
list of fixed parameters (15 of them, long names and values) in its title.

Each figure is drawn from small synthetic tables (no solve) and written by plot.common.save:
every text drawn into the PNG must have its window extent inside the figure's bbox, and the
PNG must be exactly the figure's size (no 'tight' bounding box that would enlarge the canvas
to take in a runaway title).
"""

from __future__ import annotations

import math
import struct
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from matplotlib.text import Text
from matplotlib.transforms import Bbox

from cotm_bertini.model.framework.spec import Framework, from_dict
from cotm_bertini.params import PARAM_NAMES, Params

DPI = 110  # plot.common.save's
EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "cotm.toml"
# 15 parameters the framework's geometry does not use, with long names and values.
EXTRA = {f"stiffness_of_the_auxiliary_spring_{k:02d}": 123456.789 * (k + 1) for k in range(15)}
# The paper's parameters, none at Table 1's value: the bifurcation's title lists all of them.
PAPER = Params(
    L3=9.000123,
    k1=2.8100987,
    k2=2.7794321,
    p2x=3.1875432,
    p3x=-2.5745678,
    p3y=4.9309876,
    p6x=4.2500123,
    p5x=-0.2990123,
    p5y=-3.4872345,
    L01=11.501234,
    L02=11.498765,
)


def _framework() -> Framework:
    """examples/cotm.toml with EXTRA added to its parameters."""
    import tomllib

    data = tomllib.loads(EXAMPLE.read_text())
    data["parameters"] = {**data["parameters"], **EXTRA}
    return from_dict(data, source=str(EXAMPLE))


def _png_size(path: Path) -> tuple[int, int]:
    """Width and height from a PNG's IHDR chunk."""
    head = path.read_bytes()[:24]
    assert head[:8] == b"\x89PNG\r\n\x1a\n", path
    return struct.unpack(">II", head[16:24])


def _texts_outside(fig, tmp_path: Path) -> list[str]:
    """Save `fig` as a PNG and list every text drawn into it whose window extent leaves the
    canvas (text and extent).

    The extents are taken as savefig draws each text (Text.draw wrapped): exactly the PNG's
    layout, at its dpi. Only drawn texts count: an Axis keeps tick labels for ticks outside
    its view limits that it never draws (their stale positions may lie anywhere)."""
    from cotm_bertini.plot.common import save

    drawn: list[tuple[Text, Bbox, Bbox]] = []
    real = Text.draw

    def draw(text, renderer):
        real(text, renderer)
        if text.get_visible() and text.get_text().strip():
            extent = text.get_window_extent(renderer)
            drawn.append((text, extent, text.get_figure(root=True).bbox.frozen()))

    Text.draw = draw
    try:
        (png,) = save(fig, tmp_path / "figure.png", dpi=DPI)
    finally:
        Text.draw = real
    # The canvas is the figure's own size: no 'tight' bbox enlarging it around a long title.
    size = fig.get_size_inches() * DPI
    assert np.abs(np.subtract(_png_size(png), size)).max() <= 1, (_png_size(png), size)
    titles = _titles(fig)
    assert any(text.get_text() in titles for text, _, _ in drawn)
    out = []
    for text, e, box in drawn:
        assert (box.x1, box.y1) == pytest.approx(tuple(size))
        inside = (
            e.x0 >= box.x0 - 0.5
            and e.x1 <= box.x1 + 0.5
            and e.y0 >= box.y0 - 0.5
            and e.y1 <= box.y1 + 0.5
        )
        if not inside:
            out.append(
                f"{text.get_text()[:70]!r} at x {e.x0:.0f}..{e.x1:.0f}, "
                f"y {e.y0:.0f}..{e.y1:.0f} (figure {box.x1:.0f} x {box.y1:.0f})"
            )
    return out


def _titles(fig) -> str:
    """Every title of the figure (suptitle, the Axes' titles, the figure's own texts) as one
    string."""
    texts = [fig._suptitle.get_text()] if fig._suptitle is not None else []
    texts += [t.get_text() for t in fig.texts] + [ax.get_title() for ax in fig.axes]
    return "\n".join(texts)


# ---- the figures, from small synthetic tables ------------------------------------------------


def _paper_map():
    from cotm_bertini.plot.design_map import map_figure

    x = np.linspace(0.0, 12.0, 7)
    X, Y = np.meshgrid(x, x)
    regions = pd.DataFrame({"L01": X.ravel(), "L02": Y.ravel(), "stable": (X > Y).ravel() + 1})
    t = np.linspace(0.0, 12.0, 30)
    folds = pd.DataFrame({"L01": t, "L02": t, "family": "relaxed", "kind": "fold"})
    return map_figure(PAPER, regions, folds), []


def _framework_map():
    from cotm_bertini.plot.design_map import map_figure

    fw = _framework()
    x = np.linspace(0.0, 12.0, 7)
    X, Y = np.meshgrid(x, x)
    regions = pd.DataFrame({"L01": X.ravel(), "L02": Y.ravel(), "stable": (X > 6).ravel() + 1})
    folds = pd.DataFrame(
        {
            "L01": [6.0, 6.1, 6.2, 3.0],
            "L02": [0.0, 6.0, 12.0, 3.0],
            "kind": ["fold", "fold", "fold", "cusp"],
            "changes_stable_count": [True, True, True, False],
            "curve_id": [0, 0, 0, -1],
            "arc": [0.0, 1.0, 2.0, 0.0],
        }
    )
    items = [f"{n} = {v:g}" for n, v in fw.values.items() if n not in ("L01", "L02")]
    return map_figure(fw, regions, folds, ("L01", "L02")), items


def _sweep_table(param: str, values: np.ndarray) -> pd.DataFrame:
    rows = []
    for k, v in enumerate(values):
        for branch, g, stable in ((0, 30.0, True), (1, 200.0, False)):
            rows.append(
                {
                    "point": k,
                    param: v,
                    "branch": branch,
                    "gamma1_deg": g + 3 * k,
                    "gamma2_deg": g + k,
                    "rod.angle_deg": g + 3 * k,
                    "top.angle_deg": g + k,
                    "is_real": True,
                    "physical": True,
                    "stable": stable,
                }
            )
    return pd.DataFrame(rows)


def _bifurcation():
    from cotm_bertini.plot.bifurcation import bifurcation_figure

    fixed = PAPER.as_dict()
    items = [f"{n} = {fixed[n]:g}" for n in PARAM_NAMES if n != "L01"]
    return bifurcation_figure(_sweep_table("L01", np.linspace(0, 12, 9)), "L01", fixed=fixed), items


def _counts():
    from cotm_bertini.plot.counts import sweep_counts_figure

    px, py = list(EXTRA)[:2]
    rows = [
        {px: x, py: y, "is_real": True, "physical": True, "stable": x > y}
        for x in range(4)
        for y in range(3)
    ]
    return sweep_counts_figure(pd.DataFrame(rows), [px, py]), []


def _solutions(n: int) -> pd.DataFrame:
    """n physical equilibria of the paper's mechanism (angles only: the titles are tested)."""
    return pd.DataFrame(
        {
            "solution_id": range(n),
            "gamma1_deg": np.linspace(20, 300, n),
            "gamma2_deg": np.linspace(200, 40, n),
            "is_real": True,
            "physical": True,
            "reason": "",
            "stable": [k % 2 == 0 for k in range(n)],
            "kind": ["min" if k % 2 == 0 else "saddle" for k in range(n)],
        }
    )


def _configurations():
    from cotm_bertini.plot.configurations import configurations_figure

    return configurations_figure(PAPER, _solutions(2)), []


def _no_equilibrium():
    """The configurations of no physical equilibrium: the parameters as a caption, with
    values as wide as :g prints them."""
    from cotm_bertini.plot.configurations import configurations_figure

    wide = Params(L3=1.2345678e5, k1=1.2345678e-3, k2=2.3456789e3, L01=1.2345678e6, L02=2.3456789e6)
    fig = configurations_figure(wide, _solutions(0))
    return fig, ["L01 = 1.23457e+06 m"]


def _energy_map():
    from cotm_bertini.plot.energy_map import energy_map_figure

    return energy_map_figure(PAPER, _solutions(3), n=30), []


def _barrier_map():
    from cotm_bertini.plot.energy_map import barrier_figure

    path = np.column_stack([np.linspace(100, 380, 20), np.linspace(50, 120, 20)])
    return barrier_figure(PAPER, _solutions(3), {1: (path, path[::-1])}, n=30), []


def _captured(module, call):
    """The figure a plot_* function of `module` hands to save (written by the real save)."""
    import importlib

    mod = importlib.import_module(f"cotm_bertini.plot.{module}")
    figures = []
    real = mod.save
    mod.save = lambda fig, path: figures.append(fig) or real(fig, path)
    try:
        call(mod)
    finally:
        mod.save = real
    return figures[0]


def _framework_pose(fw: Framework, n: int) -> pd.DataFrame:
    """n poses of the cotm framework: rod at angle a, top at angle b (points from the file)."""
    v = fw.values
    rows = []
    for k in range(n):
        a, b = math.radians(30 + 40 * k), math.radians(200 - 25 * k)
        tip = np.array([v["L3"] * math.cos(a), v["L3"] * math.sin(a)])
        rot = np.array([[math.cos(b), -math.sin(b)], [math.sin(b), math.cos(b)]])
        pts = {
            "rod.p1": (0.0, 0.0),
            "rod.p4": tip,
            "top.p4": tip,
            "top.p6": tip + rot @ [v["p6x"], 0.0],
            "top.p5": tip + rot @ [v["p5x"], v["p5y"]],
        }
        row = {
            "solution_id": k,
            "physical": True,
            "stable": k == 0,
            "kind": "min" if k == 0 else "saddle",
            "energy": 1234.56789 * (k + 1),
        }
        for name, (x, y) in pts.items():
            row |= {f"{name}.x": x, f"{name}.y": y}
        rows.append(row)
    return pd.DataFrame(rows)


def _framework_configurations(n: int):
    def figure(tmp_path: Path):
        fw = _framework()
        fig = _captured(
            "framework", lambda m: m.plot_framework(fw, _framework_pose(fw, n), tmp_path / "c.png")
        )
        return fig, [f"{k} = {v:g}" for k, v in fw.values.items()]

    return figure


def _framework_sweep(tmp_path: Path):
    fw = _framework()
    table = _sweep_table("L01", np.linspace(0, 12, 9))
    fig = _captured(
        "framework_sweep", lambda m: m.plot_framework_sweep(fw, table, "L01", tmp_path / "s.png")
    )
    return fig, [f"{k} = {v:g}" for k, v in fw.values.items() if k != "L01"]


def _barrier_profile():
    from cotm_bertini.plot.barrier_profile import barrier_profile_figure

    fw = _framework()
    table = pd.DataFrame({"saddle_id": [1], "lowest": [True], "min_a": [0], "min_b": [2]})
    arc = np.linspace(0.0, 1.0, 10)
    side = pd.DataFrame({"arc": arc, "energy": 5.0 - arc**2})
    fig = barrier_profile_figure(fw, table.set_index("saddle_id"), {1: (side, side)})
    return fig, [f"{k} = {v:g}" for k, v in fw.values.items()]


FIGURES = {
    "paper map": lambda tmp: _paper_map(),
    "framework map": lambda tmp: _framework_map(),
    "bifurcation": lambda tmp: _bifurcation(),
    "2-D counts": lambda tmp: _counts(),
    "configurations": lambda tmp: _configurations(),
    "configurations, none physical": lambda tmp: _no_equilibrium(),
    "energy map": lambda tmp: _energy_map(),
    "barrier map": lambda tmp: _barrier_map(),
    "framework configurations, no pose": _framework_configurations(0),
    "framework configurations, one pose": _framework_configurations(1),
    "framework configurations, five poses": _framework_configurations(5),
    "framework sweep": _framework_sweep,
    "barrier profile": lambda tmp: _barrier_profile(),
}


@pytest.mark.parametrize("kind", list(FIGURES))
def test_every_text_stays_inside_the_figure(kind, tmp_path):
    """Every text (titles, labels, legends) inside the saved canvas; the title keeps every
    fixed parameter whole ("name = value" on one line)."""
    fig, items = FIGURES[kind](tmp_path)
    assert _texts_outside(fig, tmp_path) == []
    titles = _titles(fig)
    for item in items:
        assert any(item in line for line in titles.splitlines()), (item, titles)


def test_a_long_title_is_broken_between_items_only():
    """set_title breaks a line wider than the figure after ", " (never inside "name = value"
    where each item fits), keeps a line that fits as it is, drops nothing, and grows the
    figure by one line's height for each line it adds."""
    from matplotlib.figure import Figure

    from cotm_bertini.plot.common import set_title

    short = "a: 1 equilibrium"
    line = ", ".join(f"{n} = {v:g}" for n, v in EXTRA.items())
    for width in (5.0, 1.5):
        fig = Figure(figsize=(width, 3.0))
        lines = set_title(fig, f"{short}\n{line}", fontsize=10).get_text().split("\n")
        assert lines[0] == short and len(lines) > 3
        assert " ".join(lines[1:]) == line
        assert fig.get_figheight() == pytest.approx(3.0 + (len(lines) - 2) * 12 / 72)
        if width == 5.0:  # each item fits: every break is between two
            assert all(part.endswith(",") for part in lines[1:-1])
            assert len(lines) - 1 == len(EXTRA) or any(part.count(" = ") > 1 for part in lines)
