"""A compliant tensegrity framework from a TOML file: validated elements and parameter values.

Every number of the file may be a parameter name or an arithmetic expression of them. The
framework evaluates them into *slots*: the numbers its equations are written in (point
coordinates, stiffnesses, free lengths, bar lengths, load components). The equations depend on
the slots only, so any parameter (and any expression of parameters) can be swept.
"""

from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass, replace
from functools import lru_cache
from pathlib import Path

from ...errors import ParameterError
from ...params import SCALE_LIMIT, read_toml
from .expressions import Expr, parse

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_TOP_KEYS = {"name", "dim", "nodes", "parameters", "ground", "bodies", "pins", "springs",
             "cables", "bars", "loads"}  # fmt: skip
_LINK_KEYS = {"spring": {"name", "a", "b", "k", "L0"}, "cable": {"name", "a", "b", "k", "L0"},
              "bar": {"name", "a", "b", "length"}}  # fmt: skip


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

    def slot_expressions(self) -> dict[str, Expr]:
        """Every number of the equations as the file's expression of the parameters."""
        out: dict[str, Expr] = {}
        for name, coords in self.ground:
            out.update(_named_coords(f"g_{name}", coords))
        for body, pts in self.bodies:
            for name, coords in pts:
                out.update(_named_coords(f"b_{body}_{name}", coords))
        for link in self.links:
            if link.kind == "bar":
                out[f"len_{link.name}"] = link.length
            else:
                out[f"k_{link.name}"] = link.k
                out[f"L0_{link.name}"] = link.L0
        for load in self.loads:
            out.update(_named_coords(f"f_{load.name}", load.force))
        return out

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


def _named_coords(prefix: str, coords: tuple[Expr, ...]) -> dict[str, Expr]:
    return {f"{prefix}_{'xyz'[k]}": e for k, e in enumerate(coords)}


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
    extra = sorted(set(data) - _TOP_KEYS)
    if extra:
        raise ParameterError(f"{extra[0]}: unknown section (known: {' '.join(sorted(_TOP_KEYS))})")
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
    check_names(fw)
    check_values(fw)
    return fw


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
        extra = sorted(set(pin) - {"a", "b"})
        if extra or "a" not in pin or "b" not in pin:
            raise ParameterError(f"pins[{k}]: expects exactly the keys a and b")
        out.append((str(pin["a"]), str(pin["b"])))
    return tuple(out)


def _links(data: dict, params: set[str]) -> tuple[Link, ...]:
    out = []
    for kind, section in (("spring", "springs"), ("cable", "cables"), ("bar", "bars")):
        for k, entry in enumerate(_entries(section, data.get(section, [])), start=1):
            where = f"{section}[{k}]"
            extra = sorted(set(entry) - _LINK_KEYS[kind])
            if extra:
                raise ParameterError(f"{where}.{extra[0]}: unknown key for a {kind}")
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
    """Stiffness > 0, free lengths >= 0, bar lengths > 0, every slot finite."""
    s = fw.slots()
    for name, value in s.items():
        if not math.isfinite(value):
            raise ParameterError(f"{name} = {value!r}: evaluates to a non-finite number")
    for x in fw.links:
        where = f"{x.kind}s.{x.name}"
        if x.kind == "bar":
            if s[f"len_{x.name}"] <= 0:
                raise ParameterError(f"{where}.length = {s[f'len_{x.name}']!r}: must be > 0")
            continue
        if s[f"k_{x.name}"] <= 0:
            raise ParameterError(f"{where}.k = {s[f'k_{x.name}']!r}: must be > 0")
        if s[f"L0_{x.name}"] < 0:
            raise ParameterError(f"{where}.L0 = {s[f'L0_{x.name}']!r}: must be >= 0")
    check_scale(fw)


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
    exprs = fw.slot_expressions()
    for name, value in fw.slots().items():
        unit = scale_of(slot_kind(name), length, stiffness)
        ratio = abs(value) / unit
        tiny = name.startswith(("len_", "k_")) and ratio < 1 / SCALE_LIMIT
        if ratio <= SCALE_LIMIT and not tiny:
            continue
        used = sorted(exprs[name].names())
        who = ", ".join(f"{p} = {fw.values[p]!r}" for p in used) or f"{name} = {value!r}"
        bound = f"under {1 / SCALE_LIMIT:g}" if tiny else f"over {SCALE_LIMIT:g}"
        raise ParameterError(
            f"{who}: makes {name} = {value:.6g}, {bound} times the file's "
            f"{_UNIT_NAMES[slot_kind(name)]} {unit:.6g}; double precision cannot solve that "
            "(keep every number within 1e12 of the file's own values)"
        )
