"""What a framework's equations depend on, without sympy: the layout of its unknowns (which
pins place what), the structure key of a taut set, and the derivation's result as plain data."""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass
from functools import cache, lru_cache
from pathlib import Path

from ...errors import ParameterError
from ...fs import files_hash
from .spec import Framework, owner
from .units import constants


@dataclass(frozen=True)
class Layout:
    """Which unknowns a framework has once pins have placed what they can."""

    rotations: tuple[str, ...]  # every body
    translations: tuple[str, ...]  # bodies whose translation is unknown
    free_nodes: tuple[str, ...]
    placed_by: tuple[tuple[str, str, str], ...]  # (entity, its pinned point, the point it is at)
    closing_pins: tuple[int, ...]  # pins left as constraints (0-based)

    @property
    def is_torus(self) -> bool:
        """Only rotations: the configuration space of a planar framework is a circle or torus."""
        return not (self.translations or self.free_nodes or self.closing_pins)


@lru_cache(maxsize=256)
def layout(fw: Framework) -> Layout:
    """Place bodies and nodes through pins to placed entities, in file order, until none moves."""
    placed = {"ground"}
    placed_by, used = [], set()
    changed = True
    while changed:
        changed = False
        for k, (a, b) in enumerate(fw.pins):
            if k in used:
                continue
            for src, dst in ((a, b), (b, a)):
                if owner(src) in placed and owner(dst) not in placed:
                    placed.add(owner(dst))
                    placed_by.append((owner(dst), dst, src))
                    used.add(k)
                    changed = True
                    break
    bodies = tuple(b for b, _ in fw.bodies)
    return Layout(
        rotations=bodies,
        translations=tuple(b for b in bodies if b not in placed),
        free_nodes=tuple(n for n in fw.nodes if n not in placed),
        placed_by=tuple(placed_by),
        closing_pins=tuple(k for k in range(len(fw.pins)) if k not in used),
    )


def rotation_names(dim: int, body: str) -> list[str]:
    """Solver variable names of a body's rotation."""
    return [f"c_{body}", f"s_{body}"] if dim == 2 else [f"q{a}_{body}" for a in "wxyz"]


def active_links(fw: Framework, taut: tuple[str, ...]) -> list:
    """The springs and the taut cables, in the file's order (the links that pull)."""
    return [x for x in fw.links if x.kind == "spring" or (x.kind == "cable" and x.name in taut)]


def structure(fw: Framework, taut: tuple[str, ...]) -> dict:
    """What the equations depend on: topology, taut cables, zero free lengths, constant slots."""
    return {
        "dim": fw.dim,
        "nodes": list(fw.nodes),
        "ground": [g for g, _ in fw.ground],
        "bodies": [[b, [p for p, _ in pts]] for b, pts in fw.bodies],
        "pins": [list(p) for p in fw.pins],
        "links": [[x.kind, x.name, x.a, x.b] for x in fw.links],
        "loads": [[x.name, x.point] for x in fw.loads],
        "taut": sorted(taut),
        "zfl": sorted(fw.zero_free_length()),
        "constants": constants(fw),
    }


@dataclass(frozen=True)
class Derived:
    """The derivation's result as plain data (JSON-able), with the generated numpy source."""

    system: dict  # ParametricSystem.to_json()
    kinds: list[str]  # per variable: rot, len, k or force (how it scales with the units)
    descriptions: list[str]  # per equation: what it balances or constrains
    free: list[str]  # identically zero equations: directions nothing resists
    points: list[str]  # positions() returns these points' coordinates, in this order
    local_size: int  # size of the local coordinates of the Hessian
    constraints: int  # rows of the constraint Jacobian
    source: str  # numpy source: positions, hessian, constraint_jacobian, first_order
    active: list[str]  # springs and taut cables, in the order first_order gives them
    cones: dict  # spring -> ParametricSystem JSON of its zero-length poses (two-body torus)


_SOURCES = tuple(
    Path(__file__).resolve().parent.parent / f
    for f in (
        "framework/derive.py",
        "framework/planar.py",
        "framework/structure.py",
        "framework/spec.py",
        "framework/units.py",
        "symbolic.py",
        "../literals.py",
        "polynomial.py",
    )
)


@cache
def source_hash() -> str:
    """A hash of the derivation's code: an edit derives every structure again."""
    return files_hash(_SOURCES)


def structure_key(fw: Framework, taut: tuple[str, ...]) -> str:
    """Content hash of a structure and the derivation code."""
    # Keyed on what the structure depends on (not on every value): a sweep's points share it.
    return _structure_key(fw.at_defaults(), fw.zero_free_length(), tuple(taut))


@lru_cache(maxsize=256)
def _structure_key(defaults: Framework, zfl: tuple[str, ...], taut: tuple[str, ...]) -> str:
    s = {**structure(defaults, taut), "zfl": sorted(zfl)}
    blob = json.dumps({"s": s, "code": source_hash()}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:16]


def check_mobility(fw: Framework, derived) -> None:
    """Refuse a framework that moves freely with every cable taut (a continuum of equilibria);
    `derived`: a Derived or a FrameworkSystem (both list the free directions)."""
    if derived.free:
        raise ParameterError(
            f"framework {fw.name!r} can move freely: nothing resists {derived.free[0]} "
            "(a continuum of equilibria; add a spring, cable, bar or pin)"
        )
