"""What a sweep is: one or two parameters over given values, the rest fixed, the solver settings."""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import asdict, dataclass, field
from functools import lru_cache
from itertools import product

from .._version import __version__
from ..errors import ParameterError
from ..params import PARAM_NAMES, Params, make_params
from ..settings import Settings

# Parameters with a documented default range (the paper's Figs 5-6 sweep L01 over 0-12 m).
DEFAULT_RANGES = {"L01": (0.0, 12.0), "L02": (0.0, 12.0)}


def _values(name: str, option: str, values) -> tuple[float, ...]:
    try:
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise ParameterError(f"{option} for {name}: expected numbers, got {values!r}") from None
    if not out:
        raise ParameterError(f"{option} for {name}: no values")
    bad = [v for v in out if not math.isfinite(v)]
    if bad:
        raise ParameterError(f"{option} for {name}: {bad[0]!r} is not finite")
    if len(set(out)) != len(out):
        dup = next(v for v in out if out.count(v) > 1)
        raise ParameterError(
            f"{option} for {name}: the value {dup!r} repeats (the same point would be solved "
            "more than once)"
        )
    return out


@lru_cache(maxsize=8)  # a map checks its grid before its fold curves, its sweep again
def check_grid(model, param: str, values: tuple, param2=None, values2=None) -> None:
    """Every point of a sweep's grid validated before any work (`model`: Params or Framework;
    SweepSpec checks the ends): a range that crosses a refused value (a body of zero size, two
    points of one body that meet, ...) is refused naming that point, not met mid-sweep."""
    grid = ([{param: v} for v in values] if param2 is None
            else [{param: u, param2: w} for u, w in product(values, values2)])  # fmt: skip
    for k, point in enumerate(grid):
        try:
            model.replace(**point)
        except ParameterError as err:
            where = ", ".join(f"{n} = {v!r}" for n, v in point.items())
            raise ParameterError(
                f"{err} (at {where}, point {k + 1} of the {len(grid)} of the range: choose a "
                "range or a number of points that avoids it)"
            ) from None


@dataclass(frozen=True)
class SweepSpec:
    """The base parameters, the swept parameter(s) and their values, and the settings."""

    base: dict[str, float]
    param: str
    values: tuple[float, ...]
    param2: str | None = None
    values2: tuple[float, ...] | None = None
    settings: dict = field(default_factory=lambda: Settings().as_dict())
    certify: bool = False  # prove every point (docs/certify.md)
    framework: dict | None = None  # a framework's sweep: the framework (continuation.framework)

    def __post_init__(self) -> None:
        if self.framework is not None:
            self._check_framework()
        for name, option in ((self.param, "param"), (self.param2, "param2")):
            if self.framework is None and name is not None and name not in PARAM_NAMES:
                raise ParameterError(
                    f"{option} = {name!r}: unknown parameter (known: {' '.join(PARAM_NAMES)})"
                )
        object.__setattr__(self, "values", _values(self.param, "values", self.values))
        if self.param2 is not None:
            if self.param2 == self.param:
                raise ParameterError(f"param2 = {self.param2!r}: same as param")
            if self.values2 is None:
                raise ParameterError(f"param2 = {self.param2!r}: needs values2")
            object.__setattr__(self, "values2", _values(self.param2, "values2", self.values2))
        elif self.values2 is not None:
            raise ParameterError("values2 given without param2")
        Settings(**self.settings)  # validated here, before any work
        for values in (self.values_at(0), self.values_at(self.size() - 1)):
            if self.framework is None:
                make_params(None, {**self.base, **values})  # a bad range fails here
            else:
                self.model.replace(**values)

    def _check_framework(self) -> None:
        from .framework import check_param, decode

        fw = decode(self.framework)
        object.__setattr__(self, "_model", fw.replace(**self.base))
        check_param(fw, self.param, "param")
        check_param(fw, self.param2, "param2")
        engine = self.settings.get("engine", "homotopy")
        if engine != "homotopy":
            raise ParameterError(
                f"engine = {engine!r}: a framework is solved by the in-process homotopy engine"
            )

    @property
    def model(self):
        """The framework at the base values (a framework's sweep only)."""
        return self._model

    @classmethod
    def linspace(cls, base: Params, param: str, start: float, stop: float, points: int, **kw):
        """`points` evenly spaced values of `param` from `start` to `stop`."""
        return cls(base.as_dict(), param, linspace(param, start, stop, points), **kw)

    @property
    def columns(self) -> list[str]:
        """The swept parameters' names, in order."""
        return [self.param] + ([self.param2] if self.param2 else [])

    def grid(self) -> list[dict[str, float]]:
        """Every point's swept values, point index = list index (param2 varies fastest)."""
        if self.param2 is None:
            return [{self.param: v} for v in self.values]
        return [{self.param: u, self.param2: w} for u, w in product(self.values, self.values2)]

    def size(self) -> int:
        """The number of grid points."""
        return len(self.values) * (len(self.values2) if self.param2 else 1)

    def values_at(self, index: int) -> dict[str, float]:
        """The swept values of grid point `index`."""
        if self.param2 is None:
            return {self.param: self.values[index]}
        i, j = divmod(index, len(self.values2))
        return {self.param: self.values[i], self.param2: self.values2[j]}

    def neighbours(self, a: int, b: int) -> bool:
        """Whether grid points a and b are next to each other (one step in one parameter)."""
        if self.param2 is None:
            return abs(a - b) == 1
        n2 = len(self.values2)
        (ia, ja), (ib, jb) = divmod(a, n2), divmod(b, n2)
        return abs(ia - ib) + abs(ja - jb) == 1

    def grid_neighbours(self, index: int) -> list[int]:
        """The grid points next to `index` (one step in one parameter)."""
        if self.param2 is None:
            return [i for i in (index - 1, index + 1) if 0 <= i < len(self.values)]
        n2 = len(self.values2)
        i, j = divmod(index, n2)
        near = ((i - 1, j), (i + 1, j), (i, j - 1), (i, j + 1))
        return [a * n2 + b for a, b in near if 0 <= a < len(self.values) and 0 <= b < n2]

    def snake(self) -> list[int]:
        """Every grid index, each one a neighbour of the one before (rows alternate direction)."""
        if self.param2 is None:
            return list(range(len(self.values)))
        n2 = len(self.values2)
        return [
            i * n2 + (j if i % 2 == 0 else n2 - 1 - j)
            for i in range(len(self.values))
            for j in range(n2)
        ]

    def runs(self, todo: list[int], parts: int) -> list[list[int]]:
        """The points of `todo` in snake order, cut into runs of neighbours, then into about
        `parts` pieces of similar length (one piece per task)."""
        pending = set(todo)
        runs: list[list[int]] = []
        for index in self.snake():
            if index not in pending:
                continue
            if runs and self.neighbours(runs[-1][-1], index):
                runs[-1].append(index)
            else:
                runs.append([index])
        size = max(1, -(-len(todo) // max(parts, 1)))
        return [run[k : k + size] for run in runs for k in range(0, len(run), size)]

    def params_at(self, index: int):
        """The full parameter set of grid point `index` (a framework's sweep: the framework)."""
        if self.framework is not None:
            return self.model.replace(**self.values_at(index))
        return Params(**{**self.base, **self.values_at(index)})

    def to_json(self) -> dict:
        """JSON-able form (see from_json)."""
        d = asdict(self)
        d["values"], d["values2"] = list(self.values), self.values2 and list(self.values2)
        return d

    @classmethod
    def from_json(cls, d: dict) -> SweepSpec:
        """Inverse of to_json."""
        d = dict(d)
        d["values"] = tuple(d["values"])
        d["values2"] = None if d.get("values2") is None else tuple(d["values2"])
        return cls(**d)

    def key(self) -> str:
        """Content hash: the same request maps to the same folder (and so resumes)."""
        blob = json.dumps({**self.to_json(), "version": __version__}, sort_keys=True)
        return hashlib.sha256(blob.encode()).hexdigest()[:10]

    def folder_name(self) -> str:
        """A readable, unique folder name."""
        rng = f"{self.param}-{self.values[0]:g}-{self.values[-1]:g}-{len(self.values)}"
        if self.param2:
            rng += f"-{self.param2}-{self.values2[0]:g}-{self.values2[-1]:g}-{len(self.values2)}"
        name = "" if self.framework is None else f"{self.model.name}-"
        return f"sweep-{name}{rng}-{self.key()}"


def linspace(name: str, start: float, stop: float, points: int) -> tuple[float, ...]:
    """`points` evenly spaced values from `start` to `stop`; one value only when they are equal.
    A degenerate request is refused with one line naming the arguments."""
    if isinstance(points, bool) or not isinstance(points, int) or points < 1:
        raise ParameterError(f"points = {points!r} for {name}: must be an integer >= 1")
    if points == 1 and start != stop:
        raise ParameterError(
            f"points = 1 for {name} from start = {start:g} to stop = {stop:g}: a range needs at "
            "least 2 points (for one value, give start == stop)"
        )
    if points > 1 and start == stop:
        raise ParameterError(
            f"start = stop = {start:g} for {name}: an empty range cannot hold {points} distinct "
            "points (points = 1, or widen the range)"
        )
    import numpy as np

    return tuple(float(v) for v in np.linspace(start, stop, points))
