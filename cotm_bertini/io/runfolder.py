"""Run folders: solutions.csv, run.json, columns.md, the input file and the solver's own files."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import TYPE_CHECKING

from ..columns import reference
from ..errors import ParameterError
from ..fs import atomic_write_text, columns_csv, partial_name, timestamp, write_json
from ..versions import versions

if TYPE_CHECKING:  # the solve path only: a cache hit must not load numpy or pandas
    from ..routes.result import PointSolution

SOLUTIONS_CSV = "solutions.csv"
CONTINUA_CSV = "continua.csv"
RUN_JSON = "run.json"
COLUMNS_MD = "columns.md"
FIGURE_STEMS = ("configurations", "energy_map")
# The physical rows' columns (their physical column is all true, their reason empty).
SUMMARY_COLUMNS = ["solution_id", "gamma1_deg", "gamma2_deg", "d1", "d2", "stable", "kind"]


def solve_record(point: PointSolution, tolerances: dict, label: str, key: str | None) -> dict:
    """The run.json content of a solve (the fields a later save adds are not here)."""
    p = point.params
    record = {
        "label": label,
        "solved": timestamp(),
        "status": point.status,
        "warnings": list(point.warnings),
        "parameters": p.as_dict(),
        **p.record_fields(),
        "settings": point.settings.as_dict(),
        "seed": point.settings.seed,
        "tolerances": tolerances,
        "versions": versions(),
        "engine": point.engine,
        "details": point.details,
        "polynomial_system": point.system,
        "counts": point.counts,
        "morse": point.morse,
        "timings": dict(point.timings),
        "cache_key": key,
    }
    if point.continua:
        record["continua"] = list(point.continua)
    record["summary"] = summary_text(record, point.columns)
    return record


def summary_head(record: dict, cached: bool = False) -> str:
    """The first line of a solve's report: counts, engine and the solve's time, which for an
    answer from the cache is labelled as the time of that earlier solve."""
    c, engine = record["counts"], record["engine"]
    closed = c["closed_form_endpoints"]
    continua = c.get("continua", 0)
    seconds = f"{record['timings'].get('solve', 0.0):.2f} s"
    if cached:
        seconds = f"(cached: {seconds} when solved on {record.get('solved', '?')})"
    apart = f"; {continua} continua of equilibria apart" if continua else ""
    regions = len(record.get("details", {}).get("real_search", {}).get("free_regions", []))
    apart += f"; {regions} {_plural(regions, 'region')} of equilibria apart" if regions else ""
    only = record.get("details", {}).get("real_search", {}).get("only")
    if engine["flavour"] == "real" and only:
        return (
            f"{c['stable']} stable equilibria{apart} ({only['proved_minima']} proved strict "
            f"local minima; only the stable ones were looked for) by the real route: a branch "
            f"and bound of {c['boxes']:,} boxes over its configuration space; {seconds}"
        )
    if engine["flavour"] == "real":
        return (
            f"{c['physical']} equilibria ({c['stable']} stable{apart}; {c['distinct_solutions']}"
            f" real rows) by the real route: a branch and bound of {c['boxes']:,} boxes over its "
            f"configuration space; {seconds}"
        )
    return (
        f"{c['distinct_solutions']} distinct finite solutions "
        f"({c['real']} real, {c['physical']} physical, {c['stable']} stable" + apart + ") from "
        f"{c['finite_endpoints']} finite endpoints of {c['paths_tracked']} paths tracked"
        + (f" and {closed} computed in closed form" if closed else "")
        + f"; {engine['flavour']} ({engine['path']} {engine['version']}) {seconds}"
    )


def summary_text(record: dict, table: dict) -> str:
    """The console report of a solve: counts, the physical solutions, and how many other rows
    solutions.csv holds and why they are not physical (the caller adds a label)."""
    lines = [summary_head(record)]
    physical = [k for k, r in enumerate(table["physical"]) if r]
    lines.append(_rows_text(table, physical) if physical else "(no physical equilibrium)")
    others = len(table["physical"]) - len(physical)
    if others:
        lines.append(f"{others} other {_plural(others, 'row')} in the run folder's solutions.csv "
                     f"({_others_text(table)}; its column reason says why)")  # fmt: skip
    lines += [continuum_line(c) for c in record.get("continua", [])]
    search = record.get("details", {}).get("real_search", {})
    lines += [region_line(r) for r in search.get("free_regions", [])]
    lines += [cone_line(k, c) for k, c in enumerate(search.get("cone_points", []), start=1)]
    return "\n".join(lines)


def cone_line(k: int, c: dict) -> str:
    """A cone point in a line: the spring at zero length, the pose, the pull against k L0."""
    pose = ", ".join(f"{b} {a:.4f}" for b, a in c["angles_deg"].items()) if isinstance(
        c["angles_deg"], dict) else ", ".join(f"{a:.4f}" for a in c["angles_deg"])  # fmt: skip
    return (
        f"cone point {k}: spring {c['spring']} at zero length ({pose} deg), the others' pull "
        f"{c['pull']:.6g} < k L0 = {c['push']:.6g}: a critical point of V, not an "
        f"equilibrium row (index {c['index']}, {c['kind']}; run.json "
        "real_search.cone_points)"
    )


def region_line(r: dict) -> str:
    """A region of equilibria in a line: the nodes free to float, the others' pose, V."""
    held = ", ".join(r["held_nodes"])
    return (
        f"region {r['region']}: {', '.join(r['free_nodes'])} free to float (every cable slack "
        f"there, no load), V = {r['energy']:.6g}, neutral along the free nodes (V is flat: not "
        f"stable)"
        + (f"; {held} at one pose (run.json real_search.free_regions)" if held else "")
        + f"; {r['pieces']} boxes"
        + ("" if r["witnessed"] else "; no pose of it seen: may be empty")
    )


def _plural(n: int, word: str) -> str:
    return word if n == 1 else word + "s"


def _others_text(table: dict) -> str:
    """The rows a solve's report leaves out, counted by their reason (complex, negative_d,
    cable_pushes, ...: the element's name after the colon dropped), most first."""
    reasons: dict[str, int] = {}
    for phys, why in zip(table["physical"], table["reason"], strict=True):
        if not phys:
            name = str(why or "not physical").split(":", 1)[0]
            reasons[name] = reasons.get(name, 0) + 1
    ranked = sorted(reasons.items(), key=lambda kv: (-kv[1], kv[0]))
    return "not physical: " + ", ".join(f"{n} {why}" for why, n in ranked)


def continuum_line(c: dict) -> str:
    """One continuum of equilibria in a line: its taut set, shape, stability, energy, extent,
    what ends it and its term in the Morse sum."""
    extent = ", ".join(f"{p} {lo:.4f}..{hi:.4f}" for p, (lo, hi) in c["extent"].items())
    ends = "; ".join(
        "(" + ", ".join(f"{v:.4f}" for k, v in e.items() if k != "by") + f") where {e['by']}"
        for e in c["ends"]
    )
    term = c["morse_term"]
    return (
        f"continuum {c['continuum']} (taut set {c['taut_set']}): a {c['dimension']}-dim "
        f"{c['shape']} of {c['kind']}, energy {c['energy']:.4f}"
        + (f"; {extent}" if extent else "")
        + (f"; ends {ends}" if ends else "")
        + (f"; Morse term {term}" if term is not None else f"; no Morse term: {c['morse_note']}")
    )


def continua_columns(continua: list[dict]) -> dict[str, list]:
    """continua.csv: one row per continuum (docs/columns.md)."""
    pose = list(continua[0]["extent"])
    cols: dict[str, list] = {}
    for c in continua:
        ends = c["ends"] or [{}, {}]
        row = {k: c[k] for k in ("continuum", "taut_set", "dimension", "shape", "kind",
                                 "index_across", "energy", "energy_spread")}  # fmt: skip
        for p in pose:
            row[f"{p}.min"], row[f"{p}.max"] = c["extent"].get(p, [None, None])
        for n, e in enumerate(ends, start=1):
            row[f"end{n}_by"] = e.get("by", "")
            row.update({f"end{n}.{p}": e.get(p) for p in pose})
        row.update(points=c["points"], morse_term=c["morse_term"], morse_note=c["morse_note"])
        for k, v in row.items():
            cols.setdefault(k, []).append(v)
    return cols


def summary_columns(table: dict) -> list[str]:
    """The columns the console shows of the physical rows: the paper's, or for a framework its
    pose columns (angles, quaternions, then node coordinates; at most six) with energy and
    classification."""
    if all(n in table for n in SUMMARY_COLUMNS):
        return SUMMARY_COLUMNS
    parts = [n.split(".") for n in table if n.count(".") == 1]
    oriented = {p[0] for p in parts if p[1] in ("angle_deg", "qw")}
    pose = [".".join(p) for p in parts if p[1] in ("angle_deg", "qw", "qx", "qy", "qz")]
    # Entities with no orientation are nodes: their coordinates are their pose.
    pose += [".".join(p) for p in parts if p[1] in ("x", "y", "z") and p[0] not in oriented]
    return ["solution_id", *pose[:6], "energy", "stable", "kind"]


def _rows_text(table: dict, rows: list[int]) -> str:
    """Solutions as an aligned text table (angles wrapped after rounding to 4 digits,
    so 359.99996 prints as 0.0000, not 360.0000)."""

    def fmt(name: str, value) -> str:
        if isinstance(value, float):
            if name.startswith("gamma") or name.endswith("angle_deg"):
                value = round(value, 4) % 360.0
            return f"{value:.4f}"
        return str(value)

    names = summary_columns(table)
    cells = [[fmt(n, table[n][k].item() if hasattr(table[n][k], "item") else table[n][k])
              for n in names] for k in rows]  # fmt: skip
    widths = [max(len(n), *(len(r[j]) for r in cells)) for j, n in enumerate(names)]
    head = " ".join(n.rjust(w) for n, w in zip(names, widths, strict=True))
    body = [" ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)) for r in cells]
    return "\n".join([head, *body])


def write_solution_files(folder: Path, point: PointSolution) -> None:
    """solutions.csv, columns.md and the input file (unless the solver wrote it)."""
    atomic_write_text(folder / SOLUTIONS_CSV, columns_csv(point.columns))
    if point.continua:
        atomic_write_text(folder / CONTINUA_CSV, columns_csv(continua_columns(point.continua)))
    paper = "gamma1_deg" in point.columns
    tables = ("solutions", "counts") if paper else ("framework", "framework_counts")
    tables += ("framework_continua",) * bool(point.continua)
    atomic_write_text(folder / COLUMNS_MD, reference(*tables))
    if not (folder / "input").exists():
        atomic_write_text(folder / "input", point.input_text)


def read_record(folder: Path) -> dict:
    """A run folder's run.json."""
    return json.loads((Path(folder) / RUN_JSON).read_text())


def read_solutions(folder: Path):
    """A run folder's solutions.csv as the table a fresh solve returns."""
    from ..analysis.classify import read_table

    return read_table(Path(folder) / SOLUTIONS_CSV)


def figure_files(folder: Path) -> list[Path]:
    """The figures present in a run folder."""
    return sorted(p for p in Path(folder).iterdir() if p.stem in FIGURE_STEMS and p.is_file())


def start_copy(source: Path, dest: Path, with_figures: bool) -> Path:
    """Copy a run folder's files into the hidden working folder of `dest` (which must not exist,
    or be an empty folder); `finish_copy` renames it into place."""
    dest = Path(dest)
    if dest.exists() and (not dest.is_dir() or any(dest.iterdir())):
        raise ParameterError(f"save {str(dest)!r}: exists and is not an empty folder")
    work = partial_name(dest)
    skip = set() if with_figures else {p.name for p in figure_files(source)}
    shutil.copytree(source, work, ignore=lambda _d, names: [n for n in names if n in skip])
    return work


def finish_copy(work: Path, dest: Path, record: dict) -> Path:
    """Write run.json into the working folder and rename it to `dest`: complete or absent."""
    write_json(work / RUN_JSON, record)
    if dest.exists():
        dest.rmdir()
    work.rename(dest)
    return dest
