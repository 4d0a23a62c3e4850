"""PHCpack peer route: solve a PolySystem with `phc -b` (for cross-checks and benchmarks only).

PHCpack's blackbox solver (Debian package phcpack, command `phc`) computes several root counts
(total degree, m-homogeneous and linear-product Bezout numbers, mixed and stable mixed volume),
builds the start system of the smallest one, tracks every path in double precision and refines
the ends with Newton's method (deflating singular ones). With a polyhedral start system it
tracks the paths of the torus (mixed volume) and, separately, those of roots with zero
coordinates (stable mixed volume minus mixed volume): two refined solution lists. We read every
refined list, keep the finite ends (labels regular, singular, clustered, single, multiple), drop
"no solution" (a path that diverged or failed) and "at infinity", and return them as the
endpoint table every backend produces, in the PolySystem's variable order (phc orders its symbols
by first appearance, not as declared).
"""

from __future__ import annotations

import math
import re
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import SolverError
from ..model.polynomial import PolySystem
from .endpoints import Endpoints
from .process import ProcessTimeout, run_process, tail
from .render import phc_number, polynomial_text

PHC_COMMAND = "phc"
INSTALL_HINT = "run `apt-get install phcpack` (Debian package phcpack, command `phc`)"

# phc reads i and I as the imaginary unit and e and E as exponent markers: keep names clear of them.
_SAFE_NAME = re.compile(r"^[A-DF-HJ-Za-df-hj-z][A-Za-z0-9_]*$")


class PhcError(SolverError):
    """phc failed: not installed, non-zero exit, timeout, or output without a solution list."""


class PhcNotInstalledError(PhcError):
    """The `phc` command is not on PATH."""


@dataclass(frozen=True)
class PhcResult:
    """Finite endpoints of one `phc -b` run, in the Bertini endpoint layout, and what phc did."""

    endpoints: Endpoints
    variables: tuple[str, ...]  # the PolySystem's order (the endpoint columns)
    phc_variables: tuple[str, ...]  # the order phc chose for its symbols
    seconds: float  # wall time of the phc process
    root_count: int  # paths tracked: solutions of the start system phc used
    start_system: str  # phc's heading of the start system it built
    root_counts: dict[str, int] = field(default_factory=dict)  # every bound phc computed
    labels: dict[str, int] = field(default_factory=dict)  # path ends per phc label
    phc_solution_count: int | None = None  # size of the list phc appends to its input file
    seed: int | None = None  # as phc reports it (time-based when none was given)
    version: str = ""
    input_text: str = ""  # the input file as rendered (before phc appends its solutions)
    output: str = ""  # phc's output file, verbatim


def phc_available() -> bool:
    """Whether the `phc` command of PHCpack is on PATH."""
    return shutil.which(PHC_COMMAND) is not None


# --- input ------------------------------------------------------------------------------------


def render_phc_input(system: PolySystem) -> str:
    """The phc input file: 'n n', then each polynomial terminated by ';'."""
    bad = [v for v in system.variables if not _SAFE_NAME.match(v)]
    if bad:
        raise PhcError(f"phc cannot read {bad} as variable names (e, E, i, I are reserved)")
    n, m = len(system.exponents), len(system.variables)
    lines = [f"{n} {m}"]
    for e, c in zip(system.exponents, system.coefficients, strict=True):
        lines.append(f" {polynomial_text(system.variables, e, c, phc_number)};")
    return "\n".join(lines) + "\n"


# --- output -----------------------------------------------------------------------------------

_FLOAT = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_SOL_HEAD = re.compile(r"^solution (\d+) :(.*)$")
_VALUE = re.compile(rf"^\s*(\S+)\s*:\s*({_FLOAT})\s+({_FLOAT})\s*$")
_DIAG = re.compile(
    rf"^==\s*err\s*:\s*({_FLOAT})\s*=\s*rco\s*:\s*({_FLOAT})\s*=\s*res\s*:\s*({_FLOAT})"
    r"\s*(?:=\s*(.*?)\s*)?==\s*$"
)
_FINITE_LABELS = ("regular", "singular", "clustered", "single", "multiple")


def _label_kind(label: str) -> str:
    """'finite', 'infinity' or 'failure' for one of phc's solution labels."""
    if "infinity" in label:
        return "infinity"
    if "no solution" in label:
        return "failure"
    if any(k in label for k in _FINITE_LABELS):
        return "finite"
    raise PhcError(f"unknown phc solution label {label!r}")


def _parse_list(lines: list[str], k: int) -> tuple[tuple[str, ...], list[dict]]:
    """One solution list whose header 'count nvar' is at lines[k]."""
    try:
        count, nvar = (int(x) for x in lines[k].split()[:2])
    except (IndexError, ValueError):
        raise PhcError(f"phc solution list: bad header {lines[k : k + 1]!r}") from None
    records: list[dict] = []
    order: tuple[str, ...] | None = None
    i = k + 1
    while i < len(lines) and len(records) < count:
        head = _SOL_HEAD.match(lines[i].strip())
        if not head:
            i += 1
            continue
        rec: dict = {"number": int(head.group(1)), "status": head.group(2).strip()}
        i += 1
        values: dict[str, complex] = {}
        names: list[str] = []
        while i < len(lines):
            line = lines[i].strip()
            i += 1
            if line.startswith("t :"):
                re_, im_ = line[3:].split()[:2]
                rec["t"] = complex(float(re_), float(im_))
            elif line.startswith("m :"):
                rec["m"] = int(line[3:].split()[0])
            elif line.startswith("the solution for t"):
                for _ in range(nvar):
                    mv = _VALUE.match(lines[i]) if i < len(lines) else None
                    if not mv:
                        raise PhcError(f"phc solution {rec['number']}: bad line {lines[i]!r}")
                    names.append(mv.group(1))
                    values[mv.group(1)] = complex(float(mv.group(2)), float(mv.group(3)))
                    i += 1
            elif line.startswith("=="):
                md = _DIAG.match(line)
                if not md:
                    raise PhcError(f"phc solution {rec['number']}: bad diagnostics {line!r}")
                rec["err"], rec["rco"], rec["res"] = (float(md.group(j)) for j in (1, 2, 3))
                rec["label"] = (md.group(4) or "").strip()
                break
        if "label" not in rec or "t" not in rec or "m" not in rec or len(values) != nvar:
            raise PhcError(f"phc solution {rec['number']} is incomplete")
        if order is None:
            order = tuple(names)
        elif tuple(names) != order:
            raise PhcError(f"phc solution {rec['number']}: variables {names} differ from {order}")
        rec["values"] = values
        records.append(rec)
    if len(records) != count:
        raise PhcError(f"phc solution list announces {count} solutions, found {len(records)}")
    return order or (), records


def parse_solutions(text: str) -> tuple[tuple[str, ...], list[dict]]:
    """Every refined 'THE SOLUTIONS' list of a phc output: variable order, one dict per path end.

    phc -b writes a raw list after path tracking and a refined one, labelled per solution,
    after Newton's method; with a polyhedral start system it also tracks the paths of the
    stable mixed volume (roots with zero coordinates) and refines them in a list of their own.
    Each dict holds path (1, 2, ... over the refined lists in file order), number, t, m, values
    (name -> complex), err, rco, res and label ('real regular', 'no solution', ...).
    """
    lines = text.split("\n")
    order: tuple[str, ...] | None = None
    records: list[dict] = []
    for k, line in enumerate(lines):
        if not line.startswith("THE SOLUTIONS :"):
            continue
        j = k + 1
        while j < len(lines) and not lines[j].strip():
            j += 1
        # A refined list: after the header and the bar, entries start 'solution N :'.
        probe = [ln for ln in lines[j + 1 : j + 4] if not ln.startswith("=====")]
        if not probe or not _SOL_HEAD.match(probe[0].strip()):
            continue
        names, recs = _parse_list(lines, j)
        if order is not None and recs and names != order:
            raise PhcError(f"phc solution lists disagree on the variables: {names} vs {order}")
        order = order or (names if recs else None)
        records.extend(recs)
    if order is None and not records:
        if "THE SOLUTIONS :" not in text:
            raise PhcError("phc output has no 'THE SOLUTIONS' section")
    for n, rec in enumerate(records, start=1):
        rec["path"] = n
    return order or (), records


def appended_solution_count(input_text: str) -> int | None:
    """How many solutions phc -b appended to its input file (its own final list), if any."""
    m = re.search(r"^THE SOLUTIONS :\s*\n\s*(\d+)\s+\d+", input_text, re.M)
    return int(m.group(1)) if m else None


_ROOT_COUNTS = {
    "total degree": "total_degree",
    "mixed volume": "mixed_volume",
    "stable mixed volume": "stable_mixed_volume",
    "general linear-product Bezout number": "linear_product_bezout",
}


def root_counts(text: str) -> dict[str, int]:
    """The bounds of phc's 'ROOT COUNTS' section (total degree, m-homogeneous, mixed volume)."""
    out: dict[str, int] = {}
    for m in re.finditer(r"^\s*(\w[\w -]*?)\s*:\s*(\d+)\s*$", text, re.M):
        key = m.group(1).strip()
        if key in _ROOT_COUNTS:
            out.setdefault(_ROOT_COUNTS[key], int(m.group(2)))
        elif key.endswith("-homogeneous Bezout number"):
            out.setdefault(key.split("-")[0] + "_homogeneous_bezout", int(m.group(2)))
    return out


def endpoints_from_records(
    records: list[dict], variables: tuple[str, ...], phc_variables: tuple[str, ...]
) -> Endpoints:
    """Finite path ends as the endpoint table, in the system's variable order."""
    if set(phc_variables) != set(variables) and records:
        raise PhcError(f"phc variables {phc_variables} are not the system's {variables}")
    keep = [r for r in records if _label_kind(r["label"]) == "finite"]
    rows = [
        {
            "path_number": r["path"],
            "condition_number": 1.0 / r["rco"] if r["rco"] > 0 else math.inf,
            "function_residual": r["res"],
            "final_t": r["t"].real,
            "accuracy_estimate": r["err"],
            # phc: m > 1 for a multiple root, 0 for a lone singular one, -k when clustered with k.
            "bertini_multiplicity": max(r["m"], 1),
            "coords": [r["values"][v] for v in variables],
        }
        for r in keep
    ]
    return Endpoints.from_records(variables, rows)


# --- running phc ------------------------------------------------------------------------------


def _run(cmd: list[str], folder: Path, timeout: float):
    try:
        return run_process(cmd, folder, timeout)
    except ProcessTimeout as exc:
        written = folder / "output"
        log = written.read_text(errors="replace") if written.is_file() else ""
        raise PhcError(
            f"phc timed out after {timeout:g} s; last output: {tail(exc.stdout + log, 8)}"
        ) from None


def solve_phc(system: PolySystem, timeout: float = 600, seed: int | None = None) -> PhcResult:
    """Solve `system` with `phc -b` in a fresh temporary folder; finite endpoints only."""
    exe = shutil.which(PHC_COMMAND)
    if exe is None:
        raise PhcNotInstalledError(f"PHCpack's `{PHC_COMMAND}` is not on PATH: {INSTALL_HINT}")
    if seed is not None and seed < 1:
        raise ValueError(f"phc seed must be a positive integer (phc -0N), got {seed}")
    cmd = [exe, "-b"] + ([f"-0{int(seed)}"] if seed is not None else []) + ["input", "output"]
    input_text = render_phc_input(system)
    with tempfile.TemporaryDirectory(prefix="cotm-phc-") as tmp:
        folder = Path(tmp)
        (folder / "input").write_text(input_text)
        proc = _run(cmd, folder, timeout)
        code, console, seconds = proc.returncode, proc.stdout + proc.stderr, proc.seconds
        written = folder / "output"
        text = written.read_text(errors="replace") if written.is_file() else ""
        appended = appended_solution_count((folder / "input").read_text(errors="replace"))
    if code != 0 or not text:
        raise PhcError(
            f"phc exited with code {code}"
            + ("" if text else " and wrote no output file")
            + f": {tail(console + text, 8)}"
        )
    try:
        phc_vars, records = parse_solutions(text)
    except PhcError as exc:
        raise PhcError(f"{exc}; phc said: {tail(console + text, 8)}") from None
    labels: dict[str, int] = {}
    for r in records:
        labels[r["label"]] = labels.get(r["label"], 0) + 1
    starts = re.findall(r"^((?:[A-Z-]+ )*START SYSTEM[A-Z -]*?)\s*:", text, re.M)
    seed_m = re.search(r"Seed used in random number generators\s*:\s*(\d+)", text)
    version = re.search(r"PHCv([\d.]+)", text)
    return PhcResult(
        endpoints=endpoints_from_records(records, system.variables, phc_vars),
        variables=tuple(system.variables),
        phc_variables=phc_vars,
        seconds=seconds,
        root_count=len(records),
        start_system=starts[0] if starts else "",
        root_counts=root_counts(text),
        labels=labels,
        phc_solution_count=appended,
        seed=int(seed_m.group(1)) if seed_m else seed,
        version=version.group(1) if version else "",
        input_text=input_text,
        output=text,
    )
