"""Read Bertini output files (Bertini 1.x labelled or Bertini 2 unlabelled layout) as endpoints."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import SolverError
from .endpoints import Endpoints


class ParseError(SolverError, ValueError):
    """A Bertini output file that does not have the expected layout."""


@dataclass(frozen=True)
class BertiniOutput:
    """Finite endpoints of one run (one entry per path endpoint) and what else Bertini wrote."""

    layout: str  # "bertini1" or "bertini2"
    variables: tuple[str, ...]
    endpoints: Endpoints
    finite_solutions_count: int
    failed_paths: int | None  # entries of failed_paths (Bertini 1); None where not written
    truncated_infinite: int | None  # of those, paths truncated as going to infinity


def _complex(line: str, where: str) -> complex:
    parts = line.split()
    if len(parts) != 2:
        raise ParseError(f"{where}: expected 'real imag', got {line!r}")
    try:
        return complex(float(parts[0]), float(parts[1]))
    except ValueError:
        raise ParseError(f"{where}: expected 'real imag', got {line!r}") from None


def read_solution_list(path: Path) -> np.ndarray:
    """A classic solution-list file (count, then blocks of 're im' lines), shape (n, n_vars)."""
    lines = path.read_text().split("\n")
    try:
        count = int(lines[0].split()[0])
    except (IndexError, ValueError):
        raise ParseError(f"{path}: first line should be the solution count") from None
    blocks, current = [], []
    for i, line in enumerate(lines[1:], start=2):
        if line.strip():
            current.append(_complex(line, f"{path}:{i}"))
        elif current:
            blocks.append(current)
            current = []
    if current:
        blocks.append(current)
    if len(blocks) != count:
        raise ParseError(f"{path}: header says {count} solutions, found {len(blocks)}")
    if not blocks:
        return np.empty((0, 0), dtype=complex)
    widths = {len(b) for b in blocks}
    if len(widths) != 1:
        raise ParseError(f"{path}: solutions have different lengths {sorted(widths)}")
    return np.array(blocks, dtype=complex)


def detect_layout(main_data: Path) -> str:
    """'bertini1' for the labelled main_data of Bertini 1.x, 'bertini2' for Bertini 2's."""
    head = main_data.read_text()[:400]
    if head.startswith("Number of variables:"):
        return "bertini1"
    first = head.split("\n", 1)[0].strip()
    if first.isdigit():
        return "bertini2"
    raise ParseError(f"{main_data}: neither Bertini 1.x nor Bertini 2 main_data layout")


_B1_FIELDS = {
    "Estimated condition number": ("condition_number", float),
    "Function residual": ("function_residual", float),
    "Latest Newton residual": ("newton_residual", float),
    "T value at final sample point": ("final_t", float),
    "Maximum precision utilized": ("max_precision", float),
    "Cycle number": ("cycle_number", int),
}


def _parse_bertini1(text: str, where: str) -> tuple[tuple[str, ...], list[dict]]:
    m = re.search(r"^Variables:\s*(.*)$", text, re.M)
    if not m:
        raise ParseError(f"{where}: no 'Variables:' line")
    variables = tuple(m.group(1).split())
    body = text.split("\nAt tol=")[0]
    records = []
    for block in re.split(r"^-{10,}\s*$", body, flags=re.M)[1:]:
        lines = block.strip("\n").split("\n")
        if not lines[0].strip():
            continue
        head = re.match(r"Solution (\d+) \(path number (\d+)\)", lines[0])
        if not head:
            raise ParseError(f"{where}: expected 'Solution N (path number P)', got {lines[0]!r}")
        rec: dict = {"path_number": int(head.group(2))}
        coords: list[complex] = []
        same: list[int] = []
        for line in lines[1:]:
            key, sep, value = line.partition(":")
            key = key.strip()
            if sep and key in _B1_FIELDS:
                column, convert = _B1_FIELDS[key]
                rec[column] = convert(value)
            elif key.startswith("Accuracy estimate, user's coordinates"):
                rec["accuracy_estimate"] = float(value)
            elif key.startswith("Paths with the same endpoint"):
                same = [int(x) for x in value.split()]
            elif key == "Multiplicity":
                rec["bertini_multiplicity"] = int(value)
            elif not sep and line.strip():
                coords.append(_complex(line, where))
        if len(coords) != len(variables):
            raise ParseError(
                f"{where}: solution of path {rec['path_number']} has {len(coords)} coordinates, "
                f"expected {len(variables)}"
            )
        rec["coords"] = coords
        records.append(rec)
        # Bertini 1 lists a point once; the other paths that reached it are endpoints too.
        for p in same:
            records.append({**rec, "path_number": p})
    return variables, records


def _parse_bertini2(text: str, where: str) -> tuple[tuple[str, ...], list[dict]]:
    lines = text.split("\n")
    n = int(lines[0])
    names = lines[1].split()
    if len(names) != n:
        raise ParseError(f"{where}: {n} variables announced, {len(names)} named")
    # Each variable group has its own homogenizing variable, listed just before the group.
    owner, current = {}, None
    for i, v in enumerate(names):
        if v.startswith("HOM_VAR"):
            current = i
        elif current is None:
            raise ParseError(f"{where}: variable {v} comes before any homogenizing variable")
        else:
            owner[i] = current
    user = sorted(owner)
    variables = tuple(names[i] for i in user)
    records, i = [], 2
    while True:
        while i < len(lines) and not lines[i].strip():
            i += 1
        if i >= len(lines) or not re.fullmatch(r"\d+", lines[i].strip()):
            break  # the blocks end where the printed target system begins
        md = lines[i : i + 13]
        try:
            rec = {
                "path_number": int(md[0]),
                "condition_number": float(md[2]),
                "function_residual": float(md[3]),
                "newton_residual": float(md[4]),
                "final_t": _complex(md[5], where).real,
                "max_precision": float(md[6]),
                "accuracy_estimate": float(md[9]),
                "cycle_number": int(md[10]),
                "bertini_multiplicity": int(md[11]),
            }
            codes = md[12].split()
        except (ValueError, IndexError):
            raise ParseError(f"{where}: malformed endpoint block at line {i + 1}") from None
        if any(c != "0" for c in codes):
            raise ParseError(f"{where}: endpoint at line {i + 1} has failure codes {codes}")
        j = i + 13
        while j < len(lines) and not lines[j].strip():
            j += 1
        raw = [_complex(lines[j + k], f"{where}:{j + k + 1}") for k in range(n)]
        rec["coords"] = [
            raw[k] / raw[owner[k]] if raw[owner[k]] != 0 else complex("nan") for k in user
        ]
        records.append(rec)
        i = j + n
    return variables, records


def read_output(folder: Path) -> BertiniOutput:
    """Parse main_data (either layout), checked against finite_solutions, and failed_paths."""
    folder = Path(folder)
    main = folder / "main_data"
    if not main.is_file():
        raise ParseError(f"{folder}: no main_data")
    layout = detect_layout(main)
    text = main.read_text()
    parser = _parse_bertini1 if layout == "bertini1" else _parse_bertini2
    variables, records = parser(text, str(main))

    finite = read_solution_list(folder / "finite_solutions")
    coords = np.array([r.pop("coords") for r in records], dtype=complex).reshape(
        len(records), len(variables)
    )
    if len(records) > len(finite):
        # With SecurityLevel 1, main_data also lists the endpoints at infinity: keep the ones
        # Bertini itself calls finite.
        keep = [
            k
            for k in range(len(records))
            if np.isfinite(coords[k]).all()
            and len(finite)
            and (
                np.abs(finite - coords[k]).max(axis=1) <= 1e-6 * (1 + np.abs(coords[k]).max())
            ).any()
        ]
        records = [records[k] for k in keep]
        coords = coords[keep]
    if len(records) != len(finite):
        raise ParseError(
            f"{folder}: main_data has {len(records)} finite endpoints, "
            f"finite_solutions has {len(finite)}"
        )
    for rec, point in zip(records, coords, strict=True):
        rec["coords"] = point
    records.sort(key=lambda r: r["path_number"])
    endpoints = Endpoints.from_records(variables, records)

    failed = infinite = None
    fp = folder / "failed_paths"
    if fp.is_file():
        text = fp.read_text()
        failed = len(re.findall(r"^Path Number", text, re.M))
        infinite = len(re.findall(r"^Path was truncated .* exceed", text, re.M))
    return BertiniOutput(layout, variables, endpoints, len(finite), failed, infinite)
