"""Mechanism parameters: Table 1 of the paper, case presets, validation and loading."""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, fields
from pathlib import Path

from .errors import ParameterError

PARAM_NAMES = ("L3", "k1", "k2", "p2x", "p3x", "p3y", "p6x", "p5x", "p5y", "L01", "L02")

PARAM_UNITS = {name: "N/m" if name in ("k1", "k2") else "m" for name in PARAM_NAMES}

PARAM_MEANING = {
    "L3": "rod length, point 1 to point 4",
    "k1": "stiffness of spring 1 (points 2-6)",
    "k2": "stiffness of spring 2 (points 3-5)",
    "p2x": "point 2 = [p2x, 0] in the bottom frame B",
    "p3x": "point 3 = [p3x, p3y] in frame B",
    "p3y": "point 3 = [p3x, p3y] in frame B",
    "p6x": "point 6 = [p6x, 0] in the top frame T",
    "p5x": "point 5 = [p5x, p5y] in frame T",
    "p5y": "point 5 = [p5x, p5y] in frame T",
    "L01": "free length of spring 1 (0: zero free length)",
    "L02": "free length of spring 2 (0: zero free length)",
}

# Table 1 of DETC2018-85998. Points follow the reference notes: in frame B, P2 = [p2x, 0],
# P3 = [p3x, p3y]; in frame T, P6 = [p6x, 0], P5 = [p5x, p5y] (eq. (2) of the paper swaps labels).
TABLE1 = {
    "L3": 9.0,
    "k1": 2.81,
    "k2": 2.81,
    "p2x": 3.1875,
    "p3x": -2.5745,
    "p3y": 4.9309,
    "p6x": 4.25,
    "p5x": -0.299,
    "p5y": -3.4872,
    "L01": 0.0,
    "L02": 0.0,
}

CASES = {
    "case1": {"L01": 0.0, "L02": 0.0},
    "case2": {"L01": 11.5, "L02": 0.0},
    "case3": {"L01": 11.5, "L02": 11.5},
}

LENGTHS = ("L3", "p2x", "p3x", "p3y", "p6x", "p5x", "p5y", "L01", "L02")

# Two points of one body closer than this (relative to L3; a framework: its length unit) are
# "coincident".
COINCIDENT_REL = 1e-9
# The solvers work in units where the numbers are of order one (normalized(); a framework's
# units); a number more than this many times its unit leaves too few digits of double
# precision for the others, and the equations say nothing (Bertini then fails or finds nothing).
SCALE_LIMIT = 1e12


def check_names(given: dict[str, object], known: tuple[str, ...], what: str) -> None:
    """Refuse an unknown keyword with ParameterError naming it and listing the known ones."""
    for name in given:
        if name not in known:
            raise ParameterError(f"{name}: unknown {what} (known: {' '.join(known)})")


@dataclass(frozen=True)
class Params:
    """Geometry, stiffness and free lengths of the CoTM (metres, N/m).

    Unset fields are Table 1 as printed, L01 = L02 = 0 (= case1): the same rule as every
    command line without a case (docs/cli.md).
    """

    L3: float = TABLE1["L3"]
    k1: float = TABLE1["k1"]
    k2: float = TABLE1["k2"]
    p2x: float = TABLE1["p2x"]
    p3x: float = TABLE1["p3x"]
    p3y: float = TABLE1["p3y"]
    p6x: float = TABLE1["p6x"]
    p5x: float = TABLE1["p5x"]
    p5y: float = TABLE1["p5y"]
    L01: float = TABLE1["L01"]
    L02: float = TABLE1["L02"]

    def __new__(cls, *args: float, **values: float) -> Params:
        """Refuse an unknown or repeated field with ParameterError (not a bare TypeError)."""
        if len(args) > len(PARAM_NAMES):
            raise ParameterError(
                f"Params takes at most {len(PARAM_NAMES)} values ({' '.join(PARAM_NAMES)}), "
                f"got {len(args)}"
            )
        check_names(values, PARAM_NAMES, "parameter")
        twice = set(PARAM_NAMES[: len(args)]) & set(values)
        if twice:
            name = sorted(twice)[0]
            raise ParameterError(f"{name} = {values[name]!r}: given twice (by position and name)")
        return super().__new__(cls)

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, int) and not isinstance(value, bool):
                object.__setattr__(self, f.name, float(value))
        validate(self)

    @classmethod
    def case(cls, name: str, **overrides: float) -> Params:
        """Table 1 with a case preset of the paper ('case1', 'case2', 'case3'), then overrides."""
        return make_params(name, overrides)

    @classmethod
    def from_toml(cls, path: str | Path, case: str | None = None) -> Params:
        """Table 1 (and an optional case preset), then the values of a TOML file."""
        return make_params(case, load_toml(path))

    @property
    def zfl(self) -> tuple[bool, bool]:
        """Whether spring 1 and spring 2 have zero free length."""
        return (self.L01 == 0.0, self.L02 == 0.0)

    def as_dict(self) -> dict[str, float]:
        """Parameters as a plain dict, in PARAM_NAMES order."""
        return {name: getattr(self, name) for name in PARAM_NAMES}

    def key_fields(self) -> dict:
        """What a cached solve of these parameters depends on (the cache key's model part)."""
        return self.as_dict()

    def record_fields(self) -> dict:
        """The model's entries of run.json besides the parameter values."""
        return {"zero_free_length": {"spring1": self.zfl[0], "spring2": self.zfl[1]}}

    def replace(self, **values: float) -> Params:
        """A copy with some values replaced, validated like the command line."""
        return make_params(None, {**self.as_dict(), **values})

    def normalized(self) -> Params:
        """The same mechanism in units of L3 (lengths) and max(k1, k2) (stiffness).

        Its equilibria have the same angles; its spring lengths are the originals divided by L3.
        """
        done = self.__dict__.get("_normalized")  # kept: a sweep's point asks for it many times
        if done is None:
            k = max(self.k1, self.k2)
            done = Params(
                **{n: v / (self.L3 if n in LENGTHS else k) for n, v in self.as_dict().items()}
            )
            object.__setattr__(self, "_normalized", done)
        return done


def validate(p: Params) -> None:
    """Raise ParameterError naming the first field whose value cannot describe a mechanism."""
    for f in fields(p):
        v = getattr(p, f.name)
        if isinstance(v, bool) or not isinstance(v, int | float):
            raise ParameterError(f"{f.name} = {v!r}: must be a number")
        if not math.isfinite(v):
            raise ParameterError(f"{f.name} = {v!r}: must be finite")
    if p.L3 <= 0:
        raise ParameterError(f"L3 = {p.L3!r}: the rod length must be > 0")
    for name in ("k1", "k2"):
        if getattr(p, name) <= 0:
            raise ParameterError(f"{name} = {getattr(p, name)!r}: a spring constant must be > 0")
    for name in ("L01", "L02"):
        if getattr(p, name) < 0:
            raise ParameterError(f"{name} = {getattr(p, name)!r}: a free length must be >= 0")
    _check_scale(p)
    _check_distinct_points(p, COINCIDENT_REL * p.L3)


def _check_scale(p: Params) -> None:
    """Every length within SCALE_LIMIT times L3, the spring constants within SCALE_LIMIT of
    each other (the units the target is solved in: normalized())."""
    for name in LENGTHS[1:]:
        if abs(getattr(p, name)) > SCALE_LIMIT * p.L3:
            raise ParameterError(
                f"{name} = {getattr(p, name)!r}: over {SCALE_LIMIT:g} times the rod length "
                f"L3 = {p.L3!r}; double precision cannot solve that"
            )
    small, large = sorted(("k1", "k2"), key=lambda n: getattr(p, n))
    if getattr(p, large) > SCALE_LIMIT * getattr(p, small):
        raise ParameterError(
            f"{large} = {getattr(p, large)!r}: over {SCALE_LIMIT:g} times {small} = "
            f"{getattr(p, small)!r}; double precision cannot solve that"
        )


def _check_distinct_points(p: Params, tol: float) -> None:
    pairs = (
        ("p2x", abs(p.p2x), "point 2 coincides with point 1"),
        ("p3x, p3y", math.hypot(p.p3x, p.p3y), "point 3 coincides with point 1"),
        ("p3x, p3y", math.hypot(p.p3x - p.p2x, p.p3y), "point 3 coincides with point 2"),
        ("p6x", abs(p.p6x), "point 6 coincides with point 4"),
        ("p5x, p5y", math.hypot(p.p5x, p.p5y), "point 5 coincides with point 4"),
        ("p5x, p5y", math.hypot(p.p5x - p.p6x, p.p5y), "point 5 coincides with point 6"),
    )
    for names, gap, what in pairs:
        if gap <= tol:
            values = ", ".join(repr(getattr(p, n.strip())) for n in names.split(","))
            raise ParameterError(f"{names} = {values}: {what}")


def coerce(name: str, value: object) -> float:
    """One parameter value as a float; ParameterError names the field and the value."""
    check_names({name: value}, PARAM_NAMES, "parameter")
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ParameterError(f"{name} = {value!r}: must be a number")
    try:
        return float(value)
    except ValueError:
        raise ParameterError(f"{name} = {value!r}: must be a number") from None


def parse_assignment(text: str) -> tuple[str, float]:
    """Parse one `NAME=VALUE` command-line assignment."""
    name, sep, value = text.partition("=")
    name = name.strip()
    if not sep:
        raise ParameterError(f"--set {text!r}: expected NAME=VALUE")
    return name, coerce(name, value.strip())


def load_toml(path: str | Path, option: str = "path") -> dict[str, float]:
    """Read a TOML file of top-level parameter values (any subset of PARAM_NAMES); errors name
    `option` (the Python argument, or the command line's `--params`)."""
    data = read_toml(path, option)
    return {name: coerce(name, value) for name, value in data.items()}


def read_toml(path: str | Path, option: str) -> dict:
    """A TOML file's tables; a missing file, a folder or bad TOML is one ParameterError naming
    `option` and the path."""
    path = Path(path)
    try:
        with path.open("rb") as fh:
            data = tomllib.load(fh)
    except FileNotFoundError:
        raise ParameterError(f"{option} {str(path)!r}: file not found") from None
    except IsADirectoryError:
        raise ParameterError(f"{option} {str(path)!r}: is a directory, not a file") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{option} {str(path)!r}: not valid TOML ({exc})") from None
    return data


def make_params(case: str | None = None, overrides: dict[str, object] | None = None) -> Params:
    """Table 1, then the case preset (L01/L02), then user overrides, validated."""
    values = dict(TABLE1)
    if case is not None:
        if case not in CASES:
            raise ParameterError(f"case = {case!r}: expected one of {', '.join(CASES)}")
        values.update(CASES[case])
    for name, value in (overrides or {}).items():
        values[name] = coerce(name, value)
    return Params(**values)
