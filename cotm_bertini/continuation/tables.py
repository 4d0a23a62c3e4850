"""A sweep's table as numpy columns: joined from its points, written as CSV, made a DataFrame.

The points' columns are joined as `pandas.concat` joins their frames (columns in order of first
appearance; a column a point lacks is empty there), and `csv_text` writes them as
`DataFrame.to_csv(index=False)` does (shortest round-trip floats, NaN and None empty,
True/False, minimal quoting), without loading pandas.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

Columns = dict[str, np.ndarray]


def concat_columns(parts: Sequence[Mapping[str, np.ndarray]]) -> Columns:
    """The rows of every part, in order; a column some part lacks is NaN (None) there."""
    names = union_names(parts)
    sizes = [len(next(iter(p.values()))) if len(p) else 0 for p in parts]
    out: Columns = {}
    for name in names:
        pieces = []
        for part, n in zip(parts, sizes, strict=True):
            if not n:
                continue  # an empty point adds no rows (and must not change a dtype)
            if name in part:
                pieces.append(np.asarray(part[name]))
            else:
                kind = next(p[name].dtype.kind for p in parts if name in p)
                pieces.append(np.full(n, np.nan) if kind == "f" else np.full(n, None, object))
        out[name] = np.concatenate(pieces) if pieces else np.zeros(0)
    return out


def _quote(text: str) -> str:
    if "," in text or '"' in text or "\r" in text or "\n" in text:
        return '"' + text.replace('"', '""') + '"'
    return text


def _cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, float):  # numpy floats too
        return "" if value != value else repr(float(value))
    return _quote(str(value))


def column_text(values: np.ndarray) -> list[str]:
    """One CSV cell per value, as pandas writes it."""
    arr = np.asarray(values)
    kind = arr.dtype.kind
    if kind == "f":
        out = list(map(repr, arr.tolist()))
        for k in np.flatnonzero(np.isnan(arr)).tolist():
            out[k] = ""
        return out
    if kind in "biu":
        return list(map(str, arr.tolist()))
    seen: dict = {}  # a point's rows repeat their method, status, kind and reason
    out = []
    for v in arr.tolist():
        key = (type(v), v) if isinstance(v, str | bool | None) else None
        if key is None:
            out.append(_cell(v))
        else:
            if key not in seen:
                seen[key] = _cell(v)
            out.append(seen[key])
    return out


def csv_text(columns: Mapping[str, Sequence]) -> str:
    """CSV text of a table given as columns of equal length (with a header line)."""
    header = ",".join(_quote(str(n)) for n in columns)
    cells = [column_text(np.asarray(v) if not isinstance(v, list) else _objects(v))
             for v in columns.values()]  # fmt: skip
    if not cells or not cells[0]:
        return header + "\n"
    return header + "\n" + "\n".join(map(",".join, zip(*cells, strict=True))) + "\n"


def _objects(values: list) -> np.ndarray:
    out = np.empty(len(values), dtype=object)
    out[:] = values
    return out


def union_names(parts: Sequence[Mapping[str, object]]) -> list[str]:
    """Every column name of the parts, in order of first appearance (as pandas.concat)."""
    names: dict[str, None] = {}
    for part in parts:
        names.update(dict.fromkeys(part))
    return list(names)


def rows_text(columns: Mapping[str, np.ndarray], names: Sequence[str]) -> str:
    """The CSV lines (no header) of a table's rows under the columns `names`, as the joined
    table is written: a column the table lacks is empty; `lost_paths` is written as the whole
    numbers it holds (pandas' Int64)."""
    n = len(next(iter(columns.values()))) if columns else 0
    if not n:
        return ""
    cells = []
    for name in names:
        if name not in columns:
            cells.append([""] * n)
        elif name == "lost_paths":
            cells.append(column_text(nullable_ints(columns[name])))
        else:
            cells.append(column_text(columns[name]))
    return "\n".join(map(",".join, zip(*cells, strict=True))) + "\n"


def nullable_ints(values: np.ndarray) -> np.ndarray:
    """Whole numbers with gaps (NaN) as pandas' Int64 writes them: 3, or empty."""
    arr = np.asarray(values)
    if arr.dtype.kind == "O":
        arr = np.array([np.nan if v is None else v for v in arr.tolist()], dtype=float)
    out = np.empty(len(arr), dtype=object)
    for k, v in enumerate(np.asarray(arr, dtype=float).tolist()):
        out[k] = None if v != v else int(v)
    return out


def to_frame(columns: Mapping[str, np.ndarray]):
    """The table as a DataFrame with the dtypes `read_table` gives sweep.csv."""
    import pandas as pd

    frame = pd.DataFrame(dict(columns))
    for col in ("reason", "kind"):
        if col in frame:
            frame[col] = frame[col].fillna("").astype(str)
    if "paths" in frame:
        frame["paths"] = frame["paths"].astype(str)
    if "lost_paths" in frame:
        frame["lost_paths"] = frame["lost_paths"].astype(float).astype("Int64")
    return frame
