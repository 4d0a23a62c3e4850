"""Explorer pages: one self-contained HTML file per map, sweep or move, opened from disk in any
browser. The figure is plotly's (plotly.js inline, so nothing is fetched at view time); the
equilibria at every grid point, sweep point or step travel with it as float32 coordinates of
the mechanism's points, drawn on demand by a small script (templates/explore.html.j2): a
click on the map, or the slider of a sweep or move, draws the equilibria there from the run's
own table, no re-solve."""

from __future__ import annotations

import base64
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..fs import atomic_write_text
from ..model.kinematics import points as paper_points
from ..params import Params
from ..resources import page_template
from .common import param_label

KIND_CODES = {"min": 0, "saddle": 1, "max": 2}  # anything else: 3 (drawn dotted)
PAPER_GEOMETRY = ("L3", "p2x", "p3x", "p3y", "p5x", "p5y", "p6x")  # what places its points


@dataclass(frozen=True)
class Skeleton:
    """What is drawn: named points, elements (a body's outline, a link) through them, and the
    loads ({name, point: index}), drawn as arrows."""

    points: list[str]
    elements: list[dict]
    dim: int
    loads: tuple[dict, ...] = ()


def skeleton(model) -> Skeleton:
    """The paper's six points and five elements, or a framework's body points, nodes and
    ground points with its bodies and links."""
    if isinstance(model, Params):
        elements = [("bottom", "body", [0, 1, 2, 0]), ("top", "body", [3, 4, 5, 3]),
                    ("rod", "bar", [0, 3]), ("spring1", "spring", [1, 5]),
                    ("spring2", "spring", [2, 4])]  # fmt: skip
        names = [f"P{i}" for i in range(1, 7)]
        return Skeleton(names, [_element(*e) for e in elements], 2)
    names = [f"{body}.{p}" for body, pts in model.bodies for p, _ in pts]
    names += list(model.nodes) + [f"ground.{g}" for g, _ in model.ground]
    index = {n: k for k, n in enumerate(names)}
    elements = []
    for body, pts in model.bodies:
        ring = [index[f"{body}.{p}"] for p, _ in pts]
        elements.append(_element(body, "body", ring + ring[:1] if len(ring) > 2 else ring))
    for link in model.links:
        elements.append(_element(link.name, link.kind, [index[link.a], index[link.b]]))
    loads = tuple({"name": x.name, "point": index[x.point]} for x in model.loads)
    return Skeleton(names, elements, model.dim, loads)


def _element(name: str, kind: str, points: list[int]) -> dict:
    return {"name": name, "kind": kind, "points": points}


def coordinates(model, table: pd.DataFrame) -> np.ndarray:
    """(rows, points, dim): the skeleton's points in each row of a solutions-style table whose
    rows may lie at different parameter values (its columns named as the parameters)."""
    sk = skeleton(model)
    out = np.zeros((len(table), len(sk.points), sk.dim))
    for here, rows in _parameter_sets(model, table):
        out[rows] = _points(here, table.iloc[rows], sk)
    return out


def forces(model, table: pd.DataFrame) -> np.ndarray:
    """(rows, loads, dim): each load's force at each row's parameter values (the paper's
    mechanism has none)."""
    loads = getattr(model, "loads", ())
    out = np.zeros((len(table), len(loads), getattr(model, "dim", 2)))
    for here, rows in _parameter_sets(model, table) if loads else ():
        slots = here.slots()
        out[rows] = [[slots[f"f_{x.name}_{a}"] for a in "xyz"[: here.dim]] for x in loads]
    return out


def _parameter_sets(model, table: pd.DataFrame):
    """(the model at one set of parameter values, the indices of the table's rows there), for
    the parameters that are columns of the table (the paper's: those that place its points)."""
    if not len(table):
        return
    varied = [n for n in model.as_dict() if n in table.columns]
    if isinstance(model, Params):
        varied = [n for n in varied if n in PAPER_GEOMETRY]
    if not varied:
        yield model, np.arange(len(table))
        return
    keys = table[varied].to_numpy(float)
    for key, rows in pd.DataFrame(keys).groupby(list(range(keys.shape[1]))).indices.items():
        key = key if isinstance(key, tuple) else (key,)
        yield model.replace(**dict(zip(varied, key, strict=True))), rows


def _points(model, rows: pd.DataFrame, sk: Skeleton) -> np.ndarray:
    """The skeleton's points of rows at one parameter set."""
    if isinstance(model, Params):
        g1, g2 = np.radians(rows.gamma1_deg.to_numpy(float)), np.radians(rows.gamma2_deg)
        pts = paper_points(model, np.cos(g1), np.sin(g1), np.cos(g2), np.sin(g2))
        return np.stack([np.broadcast_arrays(*pts[i], g1)[:2] for i in range(1, 7)], axis=1
                        ).transpose(2, 1, 0)  # fmt: skip
    axes = "xyz"[: model.dim]
    slots = model.slots()
    out = np.zeros((len(rows), len(sk.points), model.dim))
    for k, name in enumerate(sk.points):
        if name.startswith("ground."):
            g = name.split(".", 1)[1]
            out[:, k] = [slots[f"g_{g}_{a}"] for a in axes]
        else:
            out[:, k] = rows[[f"{name}.{a}" for a in axes]].to_numpy(float)
    return out


def table_columns(model, table: pd.DataFrame) -> dict[str, np.ndarray]:
    """The columns listed under a drawing: energy, lengths and tensions."""
    if isinstance(model, Params):
        names = ["energy", "d1", "d2", "spring1_force", "spring2_force"]
    else:
        names = ["energy"] + [f"{x.name}.{q}" for x in model.links for q in ("length", "tension")]
    return {n: table[n].to_numpy(float) for n in names if n in table.columns}


def _floats(values: np.ndarray) -> str:
    return base64.b64encode(np.ascontiguousarray(values, dtype="<f4").tobytes()).decode()


def page_data(model, rows: pd.DataFrame, point: np.ndarray, points: int) -> dict:
    """The drawing data of a page: `rows` (physical rows, any order) grouped by `point` (their
    index among `points` sweep points, grid points or steps)."""
    order = np.argsort(point, kind="stable")
    rows, point = rows.iloc[order].reset_index(drop=True), np.asarray(point)[order]
    sk = skeleton(model)
    kind = [KIND_CODES.get(str(k), 3) for k in rows.get("kind", pd.Series(["min"] * len(rows)))]
    stable = rows["stable"].astype(bool) if "stable" in rows else pd.Series([True] * len(rows))
    return {
        "skeleton": {"points": sk.points, "elements": sk.elements, "loads": list(sk.loads)},
        "dim": sk.dim, "forces": _floats(forces(model, rows)),
        "start": np.searchsorted(point, np.arange(points)).tolist(),
        "count": np.bincount(point, minlength=points).tolist(),
        "id_name": "solution_id" if "solution_id" in rows else "step",
        "sid": rows["solution_id" if "solution_id" in rows else "step"].astype(int).tolist(),
        "kind": kind, "stable": stable.astype(int).tolist(),
        **_split_fixed(coordinates(model, rows)),
        "columns": {n: _floats(v) for n, v in table_columns(model, rows).items()},
    }  # fmt: skip


def _split_fixed(xyz: np.ndarray) -> dict:
    """The points that sit still in every row (a ground point, the paper's bottom body) sent
    once (`fixed`: {index: coordinates}); the others as float32 (`coords`: rows x moving
    points x dim, in the order of `moving`)."""
    still = [bool(len(xyz)) and bool((xyz[:, p] == xyz[0, p]).all()) for p in range(xyz.shape[1])]
    moving = [p for p, s in enumerate(still) if not s]
    return {"fixed": {str(p): xyz[0, p].tolist() for p, s in enumerate(still) if s},
            "moving": moving, "coords": _floats(xyz[:, moving])}  # fmt: skip


def write_page(path: str | Path, title: str, note: str, figure, data: dict,
               slider: str = "", draw: bool = False) -> Path:  # fmt: skip
    """explore.html: the template filled with the figure, the data and plotly.js, written
    atomically."""
    import jinja2
    from plotly.offline import get_plotlyjs

    data = {**data, "figure": json.loads(figure.to_json())}
    text = jinja2.Template(page_template("explore.html.j2")).render(
        title=title, note=note, plotly_js=get_plotlyjs(), slider=slider, draw=draw,
        slider_max=len((data.get("track") or data).get("labels", [0])) - 1,
        data=json.dumps(data, separators=(",", ":")).replace("</", "<\\/"),
    )  # fmt: skip
    out = Path(path)
    atomic_write_text(out, text)
    return out


def axis_title(name: str) -> str:
    """An axis title: the parameter and its unit (the paper's), or the name as in the file."""
    return param_label(name)
