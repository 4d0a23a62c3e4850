"""A compliant tensegrity framework from a TOML file: validated elements and parameter values.

Every number of the file may be a parameter name or an arithmetic expression of them. The
framework evaluates them into *slots*: the numbers its equations are written in (point
coordinates, stiffnesses, free lengths, bar lengths, load components). The equations depend on
the slots only, so any parameter (and any expression of parameters) can be swept.
"""

from __future__ import annotations

import difflib
import hashlib
import math
import re
from dataclasses import dataclass, replace
from functools import lru_cache
from itertools import combinations
from pathlib import Path

from ...errors import ParameterError
from ...params import COINCIDENT_REL, SCALE_LIMIT, read_toml
from .expressions import Expr, parse

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_TOP_KEYS = {"name", "dim", "nodes", "parameters", "ground", "bodies", "pins", "springs",
             "cables", "bars", "loads"}  # fmt: skip
_LINK_KEYS = {"spring": {"name", "a", "b", "k", "L0"}, "cable": {"name", "a", "b", "k", "L0"},
              "bar": {"name", "a", "b", "length"}}  # fmt: skip
_PIN_KEYS = {"a", "b"}
_LOAD_KEYS = {"name", "point", "force"}


@dataclass(frozen=True)
class Link:
    """A spring, cable or bar between two points (bars: `length`, else `k` and `L0`)."""

    kind: str
    name: str
    a: str
    b: str
    k: Expr | None = None
    L0: Expr | None = None
    length: Expr | None = None


@dataclass(frozen=True)
class Load:
    """A constant force on a point (V = -F . x)."""

    name: str
    point: str
    force: tuple[Expr, ...]


@dataclass(frozen=True)
class Framework:
    """Bodies, nodes, ground points, pins, bars, springs, cables and loads, with parameters."""

    name: str
    dim: int
    nodes: tuple[str, ...]
    parameters: tuple[tuple[str, float], ...]
    ground: tuple[tuple[str, tuple[Expr, ...]], ...]
    bodies: tuple[tuple[str, tuple[tuple[str, tuple[Expr, ...]], ...]], ...]
    pins: tuple[tuple[str, str], ...]
    links: tuple[Link, ...]
    loads: tuple[Load, ...]
    source: str = ""
    defaults: tuple[tuple[str, float], ...] = ()  # the file's parameter values

    def at_defaults(self) -> Framework:
        """The framework with the file's own parameter values."""
        return replace(self, parameters=self.defaults or self.parameters)

    @classmethod
    def from_toml(cls, path: str | Path) -> Framework:
        """Read and validate a framework file; errors name the element and the problem."""
        data = read_toml(path, "framework file")
        return from_dict(data, source=str(path))

    @property
    def values(self) -> dict[str, float]:
        """The parameter values, in file order."""
        return dict(self.parameters)

    def replace(self, **values: float) -> Framework:
        """A copy with some parameter values replaced (validated: known names, numbers)."""
        known = self.values
        for name, value in values.items():
            if name not in known:
                raise ParameterError(
                    f"{name}: unknown parameter of framework {self.name!r} "
                    f"(known: {' '.join(known) or 'none'})"
                )
            known[name] = _number(f"parameters.{name}", value)
        out = replace(self, parameters=tuple(known.items()))
        check_values(out)
        return out

    def as_dict(self) -> dict[str, float]:
        """The parameter values (as Params.as_dict)."""
        return self.values

    def key_fields(self) -> dict:
        """What a cached solve depends on: the whole description and the values."""
        blob = repr(replace(self, source="", defaults=()))
        return {"framework": hashlib.sha256(blob.encode()).hexdigest(), **self.values}

    def record_fields(self) -> dict:
        """The framework's entries of run.json besides the parameter values."""
        return {
            "framework": {
                "name": self.name, "source": self.source, "dim": self.dim,
                "bodies": [b for b, _ in self.bodies], "nodes": list(self.nodes),
                "pins": len(self.pins), "springs": [x.name for x in self.springs],
                "cables": [x.name for x in self.cables], "bars": [x.name for x in self.bars],
                "loads": [x.name for x in self.loads], "slots": self.slots(),
            },
            "zero_free_length": list(self.zero_free_length()),
        }  # fmt: skip

    @property
    def springs(self) -> tuple[Link, ...]:
        """The two-sided springs."""
        return tuple(x for x in self.links if x.kind == "spring")

    @property
    def cables(self) -> tuple[Link, ...]:
        """The tension-only cables."""
        return tuple(x for x in self.links if x.kind == "cable")

    @property
    def bars(self) -> tuple[Link, ...]:
        """The rigid bars (distance constraints)."""
        return tuple(x for x in self.links if x.kind == "bar")

    def body_points(self, body: str) -> dict[str, tuple[Expr, ...]]:
        """A body's points in its own frame."""
        return dict(dict(self.bodies)[body])

    def slot_fields(self) -> dict[str, tuple[str, Expr]]:
        """Each slot's field of the file and its expression (L0_top: springs.top.L0)."""
        out: dict[str, tuple[str, Expr]] = {}
        for name, coords in self.ground:
            out.update(_named_coords(f"g_{name}", f"ground.{name}", coords))
        for body, pts in self.bodies:
            for name, coords in pts:
                out.update(_named_coords(f"b_{body}_{name}", f"bodies.{body}.{name}", coords))
        for link in self.links:
            where = f"{link.kind}s.{link.name}"
            if link.kind == "bar":
                out[f"len_{link.name}"] = (f"{where}.length", link.length)
            else:
                out[f"k_{link.name}"] = (f"{where}.k", link.k)
                out[f"L0_{link.name}"] = (f"{where}.L0", link.L0)
        for load in self.loads:
            out.update(_named_coords(f"f_{load.name}", f"loads.{load.name}.force", load.force))
        return out

    def slot_expressions(self) -> dict[str, Expr]:
        """Every number of the equations as the file's expression of the parameters."""
        return {n: e for n, (_, e) in self.slot_fields().items()}

    def slots(self) -> dict[str, float]:
        """Every number of the equations, evaluated at the parameter values."""
        vals = self.values
        return {n: e.evaluate(vals) for n, e in self.slot_expressions().items()}

    def constant_slots(self) -> set[str]:
        """The slots whose expression names no parameter (the same for every parameter value)."""
        return {n for n, e in self.slot_expressions().items() if not e.names()}

    def zero_free_length(self) -> tuple[str, ...]:
        """Springs and cables whose free length is exactly 0 at these values (fewer unknowns)."""
        s = self.slots()
        return tuple(x.name for x in self.links if x.kind != "bar" and s[f"L0_{x.name}"] == 0)


def _named_coords(prefix: str, where: str, coords: tuple[Expr, ...]) -> dict:
    return {f"{prefix}_{'xyz'[k]}": (f"{where}[{k}]", e) for k, e in enumerate(coords)}


def _number(where: str, value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ParameterError(f"{where} = {value!r}: must be a number")
    try:
        out = float(value)
    except ValueError:
        raise ParameterError(f"{where} = {value!r}: must be a number") from None
    if not math.isfinite(out):
        raise ParameterError(f"{where} = {value!r}: must be finite")
    return out


def _name(where: str, value: object) -> str:
    if not isinstance(value, str) or not _NAME.match(value):
        raise ParameterError(
            f"{where} = {value!r}: a name must start with a letter and hold only letters, "
            "digits and _"
        )
    return value


def check_keys(where: str, table: dict, known: set[str]) -> None:
    """Refuse a key the table does not know, in one line naming the table and the nearest
    known key (a misspelt key would otherwise surface as a missing one, or not at all)."""
    for key in table:
        if key in known:
            continue
        close = nearest_key(str(key), known)
        hint = f"did you mean {close!r}?" if close else f"known: {', '.join(sorted(known))}"
        raise ParameterError(f"{where}: unknown key {key!r} ({hint})")


def nearest_key(key: str, known: set[str]) -> str | None:
    """The known key `key` was probably meant to be: the same but for case, one that starts
    the other (dimension: dim), else the closest by difflib; None if none is close."""
    lower = key.lower()
    for test in (lambda k: k.lower() == lower, lambda k: lower.startswith(k.lower())
                 or k.lower().startswith(lower)):  # fmt: skip
        found = sorted(k for k in known if test(k))
        if found:
            return found[0]
    # Keys are short (a, b, k, L0): half the letters in common is close (LO for L0).
    close = difflib.get_close_matches(key, sorted(known), n=1, cutoff=0.5)
    return close[0] if close else None


def _element(section: str, k: int, entry: dict) -> str:
    """An entry of [[section]] as a message names it: springs[2], or springs[2] (top)."""
    name = entry.get("name")
    return f"{section}[{k}]" + (f" ({name})" if isinstance(name, str) else "")


def _table(where: str, value: object) -> dict:
    if not isinstance(value, dict):
        raise ParameterError(f"{where}: expected a table, got {type(value).__name__}")
    return value


def _point_coords(where: str, value: object, dim: int, params: set[str]) -> tuple[Expr, ...]:
    if not isinstance(value, list):
        raise ParameterError(f"{where} = {value!r}: expected a list of {dim} coordinates")
    if len(value) != dim:
        raise ParameterError(
            f"{where} = {value!r}: {len(value)} coordinates in a dim = {dim} framework"
        )
    return tuple(_expr(f"{where}[{k}]", v, params) for k, v in enumerate(value))


def _expr(where: str, value: object, params: set[str]) -> Expr:
    expr = parse(value, where)
    unknown = sorted(expr.names() - params)
    if unknown:
        raise ParameterError(
            f"{where} = {value!r}: parameter {unknown[0]!r} is not defined in [parameters]"
        )
    return expr


def from_dict(data: dict, source: str = "") -> Framework:
    """A validated Framework from the parsed TOML tables."""
    check_keys("the framework file's top level", data, _TOP_KEYS)
    dim = data.get("dim", 2)
    if dim not in (2, 3) or isinstance(dim, bool):
        raise ParameterError(f"dim = {dim!r}: expected 2 (planar) or 3 (spatial)")
    name = _name("name", data.get("name", Path(source).stem or "framework"))
    parameters = tuple(
        (_name(f"parameters.{k}", k), _number(f"parameters.{k}", v))
        for k, v in _table("parameters", data.get("parameters", {})).items()
    )
    params = {k for k, _ in parameters}
    nodes = data.get("nodes", [])
    if not isinstance(nodes, list):
        raise ParameterError(f"nodes = {nodes!r}: expected a list of names")
    nodes = tuple(_name(f"nodes[{k}]", n) for k, n in enumerate(nodes))
    ground = tuple(
        (_name(f"ground.{k}", k), _point_coords(f"ground.{k}", v, dim, params))
        for k, v in _table("ground", data.get("ground", {})).items()
    )
    bodies = tuple(
        (_name(f"bodies.{b}", b), _body(b, pts, dim, params))
        for b, pts in _table("bodies", data.get("bodies", {})).items()
    )
    fw = Framework(
        name=name, dim=dim, nodes=nodes, parameters=parameters, ground=ground, bodies=bodies,
        pins=_pins(data.get("pins", [])), links=_links(data, params),
        loads=_loads(data.get("loads", []), dim, params), source=source, defaults=parameters,
    )  # fmt: skip
    check_elements(fw)
    check_names(fw)
    check_values(fw)
    return fw


def check_elements(fw: Framework) -> None:
    """Something that moves and something that acts on it: else the file names no mechanism."""
    missing = []
    if not fw.bodies and not fw.nodes:
        missing.append("no bodies or nodes (nothing moves)")
    if not fw.links and not fw.loads:
        missing.append("no springs, cables, bars or loads (nothing acts)")
    if missing:
        raise ParameterError(
            f"framework {fw.name!r}{' (' + fw.source + ')' if fw.source else ''} has no "
            f"elements: {' and '.join(missing)}; docs/frameworks.md shows a file's sections"
        )


def _body(body: str, pts: object, dim: int, params: set[str]) -> tuple:
    pts = _table(f"bodies.{body}", pts)
    if not pts:
        raise ParameterError(f"bodies.{body}: a body needs at least one point")
    return tuple(
        (_name(f"bodies.{body}.{k}", k), _point_coords(f"bodies.{body}.{k}", v, dim, params))
        for k, v in pts.items()
    )


def _entries(section: str, value: object) -> list[dict]:
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise ParameterError(f"{section}: expected [[{section}]] tables")
    return value


def _pins(value: object) -> tuple[tuple[str, str], ...]:
    out = []
    for k, pin in enumerate(_entries("pins", value), start=1):
        check_keys(f"pins[{k}]", pin, _PIN_KEYS)
        if "a" not in pin or "b" not in pin:
            raise ParameterError(f"pins[{k}]: expects exactly the keys a and b")
        out.append((str(pin["a"]), str(pin["b"])))
    return tuple(out)


def _links(data: dict, params: set[str]) -> tuple[Link, ...]:
    out = []
    for kind, section in (("spring", "springs"), ("cable", "cables"), ("bar", "bars")):
        for k, entry in enumerate(_entries(section, data.get(section, [])), start=1):
            where = f"{section}[{k}]"
            check_keys(_element(section, k, entry), entry, _LINK_KEYS[kind])
            need = ("a", "b", "length") if kind == "bar" else ("a", "b", "k", "L0")
            for key in need:
                if key not in entry:
                    raise ParameterError(f"{where}: missing {key}")
            name = _name(f"{where}.name", entry.get("name", f"{kind}{k}"))
            exprs = {key: _expr(f"{section}.{name}.{key}", entry[key], params)
                     for key in need[2:]}  # fmt: skip
            out.append(Link(kind, name, str(entry["a"]), str(entry["b"]), **exprs))
    return tuple(out)


def _loads(value: object, dim: int, params: set[str]) -> tuple[Load, ...]:
    out = []
    for k, entry in enumerate(_entries("loads", value), start=1):
        check_keys(_element("loads", k, entry), entry, _LOAD_KEYS)
        name = _name(f"loads[{k}].name", entry.get("name", f"load{k}"))
        if "point" not in entry or "force" not in entry:
            raise ParameterError(f"loads.{name}: needs point and force")
        force = _point_coords(f"loads.{name}.force", entry["force"], dim, params)
        out.append(Load(name, str(entry["point"]), force))
    return tuple(out)


def point_names(fw: Framework) -> set[str]:
    """Every point a pin, link or load may name."""
    names = {f"ground.{g}" for g, _ in fw.ground} | set(fw.nodes)
    names |= {f"{b}.{p}" for b, pts in fw.bodies for p, _ in pts}
    return names


def owner(point: str) -> str:
    """The entity a point belongs to: 'ground', a body's name, or the node itself."""
    return point.split(".", 1)[0]


def check_names(fw: Framework) -> None:
    """Unique names, known points, no element joining a point to its own entity."""
    entities = ["ground", *fw.nodes, *(b for b, _ in fw.bodies)]
    for name in set(entities):
        if entities.count(name) > 1:
            raise ParameterError(f"{name}: used twice as a node, body or 'ground'")
    elements = [x.name for x in fw.links] + [x.name for x in fw.loads]
    for name in elements:
        if elements.count(name) > 1:
            raise ParameterError(f"{name}: two springs, cables, bars or loads share this name")
    known = point_names(fw)
    uses = [
        (f"pins[{k}].{s}", p)
        for k, pin in enumerate(fw.pins, 1)
        for s, p in zip("ab", pin, strict=True)
    ]
    uses += [(f"{x.kind}s.{x.name}.{s}", p) for x in fw.links for s, p in (("a", x.a), ("b", x.b))]
    uses += [(f"loads.{x.name}.point", x.point) for x in fw.loads]
    for where, point in uses:
        if point not in known:
            raise ParameterError(
                f"{where} = {point!r}: unknown point (use ground.NAME, BODY.NAME or a node name)"
            )
    pairs = [(f"pins[{k}]", a, b) for k, (a, b) in enumerate(fw.pins, 1)]
    pairs += [(f"{x.kind}s.{x.name}", x.a, x.b) for x in fw.links]
    for where, a, b in pairs:
        if owner(a) == owner(b):
            raise ParameterError(f"{where}: {a!r} and {b!r} are on the same {owner(a)!r}")


def check_values(fw: Framework) -> None:
    """Every slot finite, stiffness > 0, free lengths >= 0, bar lengths > 0, no body or element
    of zero size, every number within double precision's reach. Run on the values as set (the
    file's, --set, replace, each point of a sweep), so a parameter is refused as the literal it
    stands for would be, and the line names the parameter."""
    s, fields = fw.slots(), fw.slot_fields()
    for name, value in s.items():
        if not math.isfinite(value):
            where, expr = fields[name]
            at = ", ".join(f"{p} = {v:.15g}" for p, v in fw.parameters if p in expr.names())
            raise ParameterError(
                f"{where} = {expr.source()!r}: evaluates to {value!r}{' at ' + at if at else ''}"
                " (a division by zero, or a negative number to a fractional power)"
            )
    for x in fw.links:
        rules = [("len_", "> 0")] if x.kind == "bar" else [("k_", "> 0"), ("L0_", ">= 0")]
        for prefix, rule in rules:
            slot = prefix + x.name
            if s[slot] < 0 or (s[slot] == 0 and rule == "> 0"):
                raise _refusal(fw, [slot], f"{fields[slot][0]} = {s[slot]!r}", f": must be {rule}")
    check_geometry(fw)
    check_scale(fw)


def _refusal(
    fw: Framework, slots: list[str], subject: str, problem: str, holds=None
) -> ParameterError:
    """One line: the parameters behind `slots` with their values ("L1 = 0: makes ..."), what
    they make and the problem (-1e+15, not -1000000000000000.0); a literal of the file is named
    by `subject` alone. `holds(fw)`,
    if given, says whether the problem persists at other values: a parameter is named only if
    moving it away ends the problem (h of a mast [0, 0, h] does not make it a line)."""
    exprs = fw.slot_expressions()
    used = set().union(*(exprs[n].names() for n in slots))
    if holds is not None:
        used = {p for p in used if not holds(_moved(fw, p))}
    who = ", ".join(f"{p} = {v:.15g}" for p, v in fw.parameters if p in used)
    return ParameterError(f"{who}: makes {subject}{problem}" if who else f"{subject}{problem}")


def _moved(fw: Framework, name: str) -> Framework:
    """The framework with one parameter moved well away from its value (not validated)."""
    moved = tuple(
        (p, v * 1.618 + 0.577 * (abs(v) + 1) if p == name else v) for p, v in fw.parameters
    )
    return replace(fw, parameters=moved)


def _frame_points(fw: Framework) -> dict[str, list[tuple[str, list[str], tuple[float, ...]]]]:
    """Per rigid frame (the ground, each body): its points, their slots and coordinates."""
    vals, out = fw.values, {}
    frames = [("ground", "g_", fw.ground)] + [(b, f"b_{b}_", p) for b, p in fw.bodies]
    for frame, prefix, pts in frames:
        out[frame] = [
            (f"{frame}.{n}", [f"{prefix}{n}_{'xyz'[k]}" for k in range(len(c))],
             tuple(e.evaluate(vals) for e in c))
            for n, c in pts
        ]  # fmt: skip
    return out


def _flat(coords: list[tuple[float, ...]], tol: float) -> str | None:
    """'coincide' if a body's points (two or more) do, 'lie on one line' if they lie on one
    line (which matters in space only), else None."""
    if len(coords) < 2:
        return None  # a one-point body: refused by its derivation (its rotation moves nothing)
    first = coords[0]
    far = max(coords, key=lambda c: math.dist(c, first))
    reach = math.dist(far, first)
    if reach <= tol:
        return "coincide"
    u = [(a - b) / reach for a, b in zip(far, first, strict=True)]
    off = 0.0
    for c in coords:
        d = [a - b for a, b in zip(c, first, strict=True)]
        along = sum(x * y for x, y in zip(d, u, strict=True))
        off = max(off, math.dist(d, [along * x for x in u]))
    return "lie on one line" if off <= tol else None


_FLAT_WHY = {
    "coincide": "nothing then fixes its rotation (a body needs two distinct points)",
    "lie on one line": "nothing resists its spin about that line (a spatial body needs three "
    "points not on one line)",
}


def _joined(fw: Framework, frames: dict, tol: float) -> dict[str, str]:
    """Each point's class of points that are one point in every pose: joined by pins, or
    coincident points of one frame (`frames`: _frame_points); a class is named by a member."""
    parent = {p: p for pts in frames.values() for p, _, _ in pts} | {n: n for n in fw.nodes}

    def find(p: str) -> str:
        while parent[p] != p:
            p = parent[p]
        return p

    for a, b in fw.pins:
        parent[find(a)] = find(b)
    for pts in frames.values():
        for (p, _, c), (q, _, d) in combinations(pts, 2):
            if math.dist(c, d) <= tol:
                parent[find(p)] = find(q)
    return {p: find(p) for p in parent}


def check_geometry(fw: Framework) -> None:
    """No body whose points coincide (or, spatial, lie on one line: nothing fixes its rotation,
    or its spin about that line) and no spring, cable or bar whose two ends are one point in
    every pose: at such values an equation loses every term, and a continuum of equilibria or
    none is all there is to find. The line names the parameters that make it so."""
    tol = COINCIDENT_REL * units(fw)[0]
    frames = _frame_points(fw)

    def flat(f: Framework, body: str, points=None) -> str | None:
        what = _flat([c for _, _, c in (points or _frame_points(f))[body]], tol)
        return None if what == "lie on one line" and fw.dim == 2 else what

    for body, pts in fw.bodies:
        what = flat(fw, body, frames)
        if what is not None:
            names = [p for p, _ in pts]
            listed = ", ".join(names[:-1]) + " and " + names[-1]
            raise _refusal(
                fw, [f"b_{body}_{n}_{'xyz'[k]}" for n in names for k in range(fw.dim)],
                f"body {body}'s points {listed} {what}", f"; {_FLAT_WHY[what]}",
                holds=lambda f, b=body: flat(f, b) is not None,
            )  # fmt: skip
    same = _joined(fw, frames, tol)
    for x in fw.links:
        if same[x.a] == same[x.b]:
            joined = [p for p in same if same[p] == same[x.a]]
            slots = [n for n in fw.slot_fields() if any(_is_slot_of(n, p) for p in joined)]
            raise _refusal(
                fw, slots, f"{x.kind}s.{x.name}'s ends {x.a} and {x.b} meet in every pose",
                f" (pins and coincident points of one body or the ground join "
                f"{', '.join(joined)}); "
                + ("no pose holds its length" if x.kind == "bar" else "its pull has no direction"),
                holds=lambda f, x=x: (s := _joined(f, _frame_points(f), tol))[x.a] == s[x.b],
            )  # fmt: skip


def _is_slot_of(slot: str, point: str) -> bool:
    """Whether `slot` is a coordinate of `point` (ground.a: g_a_x, bar1.tip: b_bar1_tip_y)."""
    frame, _, name = point.partition(".")
    prefix = f"g_{name}_" if frame == "ground" else f"b_{frame}_{name}_"
    return bool(name) and slot.startswith(prefix) and len(slot) == len(prefix) + 1


# How each slot scales with the length unit L and the stiffness unit k.
_SLOT_KINDS = {"g_": "len", "b_": "len", "len_": "len", "L0_": "len", "k_": "k", "f_": "force"}


def slot_kind(name: str) -> str:
    """len, k or force: how a slot scales."""
    return next(kind for prefix, kind in _SLOT_KINDS.items() if name.startswith(prefix))


def scale_of(kind: str, length: float, stiffness: float) -> float:
    """The unit of a quantity of this kind: rot 1, len L, k k, force k L."""
    return {"rot": 1.0, "len": length, "k": stiffness, "force": stiffness * length}[kind]


@lru_cache(maxsize=256)
def units(fw: Framework) -> tuple[float, float]:
    """(length unit, stiffness unit): the largest length and the largest k at the file's values
    (the framework is solved in these units; units.py)."""
    slots = fw.at_defaults().slots()
    lengths = [abs(v) for n, v in slots.items() if slot_kind(n) == "len" and v != 0]
    ks = [v for n, v in slots.items() if n.startswith("k_")]
    return (max(lengths) if lengths else 1.0), (max(ks) if ks else 1.0)


_UNIT_NAMES = {"len": "length unit", "k": "stiffness unit", "force": "force unit (k L)"}


def check_scale(fw: Framework) -> None:
    """Refuse values the equations cannot hold in double precision: a number over SCALE_LIMIT
    times the file's own unit of its kind, or a bar length or stiffness under 1/SCALE_LIMIT of
    it. The message names the parameters behind the number."""
    length, stiffness = units(fw)
    fields = fw.slot_fields()
    for name, value in fw.slots().items():
        unit = scale_of(slot_kind(name), length, stiffness)
        ratio = abs(value) / unit
        tiny = name.startswith(("len_", "k_")) and ratio < 1 / SCALE_LIMIT
        if ratio <= SCALE_LIMIT and not tiny:
            continue
        bound = f"under {1 / SCALE_LIMIT:g}" if tiny else f"over {SCALE_LIMIT:g}"
        raise _refusal(
            fw, [name], f"{fields[name][0]} = {value:.6g}",
            f", {bound} times the file's {_UNIT_NAMES[slot_kind(name)]} {unit:.6g}; double "
            "precision cannot solve that (keep every number within 1e12 of the file's own "
            "values)",
        )  # fmt: skip
