"""Mechanism parameters: Table 1 of the paper, case presets, validation and loading."""

from __future__ import annotations

import math
import tomllib
from dataclasses import asdict, dataclass, fields, replace
from pathlib import Path

PARAM_NAMES = ("L3", "k1", "k2", "p2x", "p3x", "p3y", "p6x", "p5x", "p5y", "L01", "L02")

PARAM_UNITS = {
    "L3": "m",
    "k1": "N/m",
    "k2": "N/m",
    "p2x": "m",
    "p3x": "m",
    "p3y": "m",
    "p6x": "m",
    "p5x": "m",
    "p5y": "m",
    "L01": "m",
    "L02": "m",
}

# Table 1 of DETC2018-85998. Points follow NOTES.md: in frame B, P2 = [p2x, 0], P3 = [p3x, p3y];
# in frame T, P6 = [p6x, 0], P5 = [p5x, p5y] (eq. (2) of the paper swaps the labels).
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

# Two points of one body closer than this (relative to L3) are "coincident".
_COINCIDENT_REL = 1e-9


class ParameterError(ValueError):
    """A parameter value or name that cannot describe a mechanism; the message is one line."""


@dataclass(frozen=True)
class Params:
    """Geometry, stiffness and free lengths of the CoTM (metres, N/m)."""

    L3: float
    k1: float
    k2: float
    p2x: float
    p3x: float
    p3y: float
    p6x: float
    p5x: float
    p5y: float
    L01: float
    L02: float

    def __post_init__(self) -> None:
        validate(self)

    @property
    def zfl(self) -> tuple[bool, bool]:
        """Whether spring 1 and spring 2 have zero free length."""
        return (self.L01 == 0.0, self.L02 == 0.0)

    def as_dict(self) -> dict[str, float]:
        """Parameters as a plain dict, in PARAM_NAMES order."""
        return asdict(self)

    def with_values(self, **values: float) -> Params:
        """A copy with some values replaced (validated)."""
        return replace(self, **values)


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
    tol = _COINCIDENT_REL * p.L3
    if abs(p.p2x) <= tol:
        raise ParameterError(f"p2x = {p.p2x!r}: point 2 coincides with point 1")
    if math.hypot(p.p3x, p.p3y) <= tol:
        raise ParameterError(f"p3x, p3y = {p.p3x!r}, {p.p3y!r}: point 3 coincides with point 1")
    if math.hypot(p.p3x - p.p2x, p.p3y) <= tol:
        raise ParameterError(f"p3x, p3y = {p.p3x!r}, {p.p3y!r}: point 3 coincides with point 2")
    if abs(p.p6x) <= tol:
        raise ParameterError(f"p6x = {p.p6x!r}: point 6 coincides with point 4")
    if math.hypot(p.p5x, p.p5y) <= tol:
        raise ParameterError(f"p5x, p5y = {p.p5x!r}, {p.p5y!r}: point 5 coincides with point 4")
    if math.hypot(p.p5x - p.p6x, p.p5y) <= tol:
        raise ParameterError(f"p5x, p5y = {p.p5x!r}, {p.p5y!r}: point 5 coincides with point 6")


def _coerce(name: str, value: object) -> float:
    if name not in PARAM_NAMES:
        raise ParameterError(f"{name}: unknown parameter (known: {' '.join(PARAM_NAMES)})")
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
    return name, _coerce(name, value.strip())


def load_toml(path: str | Path) -> dict[str, float]:
    """Read a TOML file of top-level parameter values (any subset of PARAM_NAMES)."""
    path = Path(path)
    try:
        with path.open("rb") as fh:
            data = tomllib.load(fh)
    except FileNotFoundError:
        raise ParameterError(f"--params {str(path)!r}: file not found") from None
    except IsADirectoryError:
        raise ParameterError(f"--params {str(path)!r}: is a directory, not a file") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"--params {str(path)!r}: not valid TOML ({exc})") from None
    return {name: _coerce(name, value) for name, value in data.items()}


def make_params(
    case: str | None = None,
    overrides: dict[str, float] | None = None,
) -> Params:
    """Table 1, then the case preset (L01/L02), then user overrides, validated."""
    values = dict(TABLE1)
    if case is not None:
        if case not in CASES:
            raise ParameterError(f"case = {case!r}: expected one of {', '.join(CASES)}")
        values.update(CASES[case])
    for name, value in (overrides or {}).items():
        values[name] = _coerce(name, value)
    return Params(**values)


def spring_vectors_cs(params: Params, c1, s1, c2, s2) -> dict:
    """Spring vectors 2 -> 6, 3 -> 5 and the rod 1 -> 4 in frame B from c_i, s_i (any dtype)."""
    import numpy as np  # here, so that loading parameters stays light (cache hits need no numpy)

    p = params
    p4 = np.stack([p.L3 * c1, p.L3 * s1], axis=-1)
    p6 = p4 + np.stack([c2 * p.p6x, s2 * p.p6x], axis=-1)
    p5 = p4 + np.stack([c2 * p.p5x - s2 * p.p5y, s2 * p.p5x + c2 * p.p5y], axis=-1)
    return {
        "spring1": p6 - np.array([p.p2x, 0.0]),
        "spring2": p5 - np.array([p.p3x, p.p3y]),
        "rod": p4,
    }


LENGTHS = ("L3", "p2x", "p3x", "p3y", "p6x", "p5x", "p5y", "L01", "L02")


def normalized(params: Params) -> Params:
    """The same mechanism in units of L3 (lengths) and max(k1, k2) (stiffness).

    Its equilibria have the same angles; its spring lengths are the originals divided by L3.
    """
    k = max(params.k1, params.k2)
    return Params(
        **{n: v / (params.L3 if n in LENGTHS else k) for n, v in params.as_dict().items()}
    )


def zero_length_points(params: Params, variables: tuple[str, ...]) -> list[list[complex]]:
    """Solver-variable points where a spring with L0 > 0 has zero length (the d = 0 artefacts).

    For spring i: P4 = L3 (c1, s1) on the unit circle with |a - P4| = |q| (a, q: the spring's
    anchors in frames B and T), then R(gamma2) q = a - P4 gives (c2, s2); d_i = 0 and the other
    spring's d_j = +-sqrt(|P_j|^2) (complex square root of the sum of squares). Complex ones
    included; each is a double root of the multiplied-through system.
    """
    import numpy as np

    out = []
    anchors = {
        1: ((params.p2x, 0.0), (params.p6x, 0.0)),
        2: ((params.p3x, params.p3y), (params.p5x, params.p5y)),
    }
    for i in (1, 2):
        if f"d{i}" not in variables:
            continue
        a, q = (np.array(v, dtype=complex) for v in anchors[i])
        norm_a = np.sqrt(a @ a)
        e = a / norm_a
        e_perp = np.array([-e[1], e[0]])
        alpha = ((a @ a) + params.L3**2 - q @ q) / (2 * params.L3 * norm_a)
        for beta in (np.sqrt(1 - alpha**2 + 0j), -np.sqrt(1 - alpha**2 + 0j)):
            u = alpha * e + beta * e_perp
            w = a - params.L3 * u
            c2 = (q @ w) / (q @ q)
            s2 = (q[0] * w[1] - q[1] * w[0]) / (q @ q)
            point = {"c1": u[0], "s1": u[1], "c2": c2, "s2": s2, f"d{i}": 0j}
            j = 3 - i
            if f"d{j}" in variables:
                vec = spring_vectors_cs(params, u[0], u[1], c2, s2)[f"spring{j}"]
                dj = np.sqrt(vec @ vec)
                out += [[{**point, f"d{j}": sign * dj}[v] for v in variables] for sign in (1, -1)]
            else:
                out.append([point[v] for v in variables])
    return out
