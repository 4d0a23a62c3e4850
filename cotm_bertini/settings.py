"""Settings: how to solve (engine, Bertini configuration, seed, time limit) and how to classify.

Two engines solve a parameter set. `homotopy` (the default) tracks a cached generic solution set
to the target in-process with the `bertini` module; `cli` runs a total-degree solve with the
`bertini2` command or a user's Bertini 1.x binary. The tracking settings (mptype, tolerances,
security level, condition-number threshold, maximum norm, time limit, threads) reach both; the
options that only a Bertini input file can express are refused under `homotopy`.
"""

from __future__ import annotations

import os
from dataclasses import asdict, dataclass, field, fields, replace

from .errors import ParameterError
from .literals import bertini_number

# Bertini CONFIG keys we render, and their names in the input file.
CONFIG_KEYS = {
    "mptype": "MPType",
    "precision": "Precision",
    "final_tol": "FinalTol",
    "tracktol_before_eg": "TrackTolBeforeEG",
    "tracktol_during_eg": "TrackTolDuringEG",
    "security_level": "SecurityLevel",
    "condnum_threshold": "CondNumThreshold",
    "max_norm": "MaxNorm",
}

ENGINES = ("homotopy", "cli")
ROUTES = (None, "real", "complex")
ONLY = ("all", "stable")
GENERIC_ROUTES = (None, "monodromy", "total-degree", "both")
DEFAULT_CLI_TIMEOUT = 600.0

# Options a Bertini input file can express but the in-process parameter homotopy cannot.
_CLI_ONLY = {
    "variable_groups": ("total_degree", "a multihomogeneous start system"),
    "extra_config": ({}, "extra CONFIG lines"),
    "bertini": (None, "a Bertini 1.x binary"),
    "precision": (None, "a fixed precision (MPType 1)"),
}


@dataclass(frozen=True)
class Settings:
    """How to solve. None leaves a setting at the engine's default."""

    seed: int = 1
    engine: str | None = None  # None: "cli" when a Bertini binary is given, else "homotopy"
    mptype: int = 2
    precision: int | None = None
    final_tol: float | None = None
    tracktol_before_eg: float | None = None
    tracktol_during_eg: float | None = None
    security_level: int | None = None
    condnum_threshold: float | None = None
    max_norm: float | None = None
    variable_groups: str = "total_degree"  # or "multihomogeneous"
    timeout: float | None = None  # seconds; None: 600 for the cli engine, none in-process
    threads: int | None = None  # None: Bertini uses every core
    bertini: str | None = None  # path of a Bertini 1.x binary; None: the bundled bertini2
    extra_config: dict[str, str] = field(default_factory=dict)
    # A Dask scheduler address: a generic set solved ab initio is split over its workers, or
    # the real route's boxes (where the work is done, not what is found: not part of a
    # result's key).
    scheduler: str | None = None
    # How a generic set is found (backends/generic.py): "monodromy", "total-degree" or "both";
    # None: backends.generic.DEFAULT_ROUTE (monodromy; total-degree with a scheduler).
    generic: str | None = None
    # How a framework is solved (docs/frameworks.md, "The real route"): "real" (branch and bound
    # over the configuration space, real critical points only), "complex" (every complex root of
    # every taut set: generic sets and parameter homotopy); None: the real route where it covers
    # the configuration space, else the complex one.
    route: str | None = None
    # Local processes that share the real route's boxes (1: the search in this process; None:
    # in this process for two seconds, then what it has not decided over one process a core);
    # not part of a result's key. A sweep or map splits its points instead.
    workers: int | None = None
    # What a solve looks for: "all" critical points, or the "stable" equilibria alone (the
    # real route's search drops every box where V can have no local minimum; docs/frameworks.md,
    # "Only the stable equilibria").
    only: str = "all"

    def __new__(cls, *args: object, **values: object) -> Settings:
        """Refuse an unknown setting with ParameterError (not a bare TypeError)."""
        from .params import check_names

        check_names(values, tuple(sorted(cls.__dataclass_fields__)), "setting")
        return super().__new__(cls)

    def __post_init__(self) -> None:
        _check_types(self)
        if self.engine is None:
            binary = self.bertini or os.environ.get("COTM_BERTINI")
            object.__setattr__(self, "engine", "cli" if binary else "homotopy")
        if self.engine not in ENGINES:
            raise ParameterError(f"engine = {self.engine!r}: expected 'homotopy' or 'cli'")
        if self.mptype not in (0, 1, 2):
            raise ParameterError(f"mptype = {self.mptype!r}: expected 0, 1 or 2")
        if not 0 <= self.seed < 2**31:
            raise ParameterError(f"seed = {self.seed!r}: expected an integer in [0, 2^31)")
        if self.timeout is not None and not self.timeout > 0:
            raise ParameterError(f"timeout = {self.timeout!r}: must be > 0 seconds")
        if self.threads is not None and self.threads < 1:
            raise ParameterError(f"threads = {self.threads!r}: must be >= 1")
        if self.workers is not None and self.workers < 1:
            raise ParameterError(f"workers = {self.workers!r}: must be an integer >= 1")
        if self.workers not in (None, 1) and self.scheduler is not None:
            raise ParameterError(
                f"workers = {self.workers!r} with scheduler = {self.scheduler!r}: the boxes go "
                "to the scheduler's workers or to local processes; give one or the other"
            )
        if self.variable_groups not in ("total_degree", "multihomogeneous"):
            raise ParameterError(
                f"variable_groups = {self.variable_groups!r}: "
                "expected 'total_degree' or 'multihomogeneous'"
            )
        for name in ("final_tol", "tracktol_before_eg", "tracktol_during_eg", "max_norm"):
            value = getattr(self, name)
            if value is not None and not value > 0:
                raise ParameterError(f"{name} = {value!r}: must be > 0")
        if self.generic not in GENERIC_ROUTES:
            raise ParameterError(
                f"generic = {self.generic!r}: expected 'monodromy', 'total-degree' or 'both'"
            )
        if self.only not in ONLY:
            raise ParameterError(f"only = {self.only!r}: expected 'all' or 'stable'")
        if self.route not in ROUTES:
            raise ParameterError(f"route = {self.route!r}: expected 'real' or 'complex'")
        if self.route == "real" and self.generic is not None:
            raise ParameterError(
                f"generic = {self.generic!r} with route = 'real': the real route solves no "
                "generic set (route='complex' does)"
            )
        if self.engine == "homotopy":
            self._refuse_cli_only()
            if self.generic == "monodromy" and self.scheduler is not None:
                raise ParameterError(
                    f"generic = 'monodromy' with scheduler = {self.scheduler!r}: the monodromy "
                    "route runs in one process; a scheduler splits the total-degree route"
                )
        elif self.generic is not None:
            raise ParameterError(
                f"generic = {self.generic!r}: the cli engine runs Bertini's own total-degree "
                "solve (a generic set route is for engine='homotopy')"
            )
        elif self.scheduler is not None:
            raise ParameterError(
                f"scheduler = {self.scheduler!r}: splitting paths over Dask workers needs "
                "engine='homotopy' (the cli engine runs one Bertini process)"
            )

    def _refuse_cli_only(self) -> None:
        for name, (default, what) in _CLI_ONLY.items():
            if getattr(self, name) != default:
                raise ParameterError(
                    f"{name} = {getattr(self, name)!r}: {what} needs engine='cli' "
                    "(the homotopy engine tracks a cached generic set in-process)"
                )
        if self.mptype == 1:
            raise ParameterError("mptype = 1: fixed higher precision needs engine='cli'")

    @property
    def cli_timeout(self) -> float:
        """The time limit of a Bertini subprocess."""
        return self.timeout if self.timeout is not None else DEFAULT_CLI_TIMEOUT

    def bertini_config(self) -> dict[str, str]:
        """The CONFIG section as Bertini key -> value text."""
        cfg = {"MPType": str(self.mptype), "RandomSeed": str(self.seed)}
        for attr, key in CONFIG_KEYS.items():
            value = getattr(self, attr)
            if value is not None and attr != "mptype":
                cfg[key] = bertini_number(value) if isinstance(value, float) else str(value)
        cfg.update(self.extra_config)
        return cfg

    def retry(self) -> Settings:
        """Settings for a second attempt: another seed, tighter path tracking."""
        before = min(self.tracktol_before_eg or 1e-5, 1e-5)
        during = min(self.tracktol_during_eg or 1e-6, 1e-6)
        return replace(
            self,
            seed=(self.seed + 7919) % 2**31,
            tracktol_before_eg=float(f"{before / 100:.3g}"),
            tracktol_during_eg=float(f"{during / 100:.3g}"),
        )

    def replace(self, **values) -> Settings:
        """A copy with some settings replaced (validated); an unknown name is refused."""
        known = {f.name for f in fields(self)}
        for name in values:
            if name not in known:
                raise ParameterError(f"{name}: unknown setting (known: {' '.join(sorted(known))})")
        if "bertini" in values and "engine" not in values and self.engine == "homotopy":
            values["engine"] = None  # a binary chooses the engine unless one is named
        return replace(self, **values)

    def as_dict(self) -> dict:
        """All settings, for run.json and cache keys (`scheduler` only when set, so that the
        sweep specs and keys written before it existed still match)."""
        out = asdict(self)
        for name in ("scheduler", "generic", "route", "workers"):  # unset: older keys match
            if out[name] is None:
                del out[name]
        return out

    def result_key(self) -> dict:
        """The settings a result depends on (not the time limit, threads, workers or
        scheduler)."""
        skip = ("timeout", "threads", "scheduler", "generic", "workers")  # the same set
        return {k: v for k, v in self.as_dict().items() if k not in skip}


def _check_types(s: Settings) -> None:
    ints = ("seed", "mptype", "precision", "security_level", "threads", "workers")
    floats = ("final_tol", "tracktol_before_eg", "tracktol_during_eg", "condnum_threshold")
    for name in ints:
        value = getattr(s, name)
        if value is not None and (isinstance(value, bool) or not isinstance(value, int)):
            raise ParameterError(f"{name} = {value!r}: must be an integer")
    for name in (*floats, "max_norm", "timeout"):
        value = getattr(s, name)
        if value is not None and (isinstance(value, bool) or not isinstance(value, int | float)):
            raise ParameterError(f"{name} = {value!r}: must be a number")
    if s.scheduler is not None and (not isinstance(s.scheduler, str) or not s.scheduler.strip()):
        raise ParameterError(f"scheduler = {s.scheduler!r}: expected an address, tcp://host:8786")
    if not isinstance(s.extra_config, dict):
        raise ParameterError(f"extra_config = {s.extra_config!r}: must be a dict")


@dataclass(frozen=True)
class Tolerances:
    """Thresholds of the classification; see docs/reference.md."""

    imag: float = 1e-8  # |Im| of every variable below this (relative to 1 + |x|): real
    # Condition number of the Jacobian at the refined point above this: a singular endpoint.
    # Ordinary roots with large |d| reach 1e9 (the variables are not scaled); exactly singular
    # ones (d = 0 artefacts) 1e14 and up.
    singular_condition: float = 1e12
    zero_length: float = 1e-5  # |d| below this times L3 at a singular endpoint: d = 0 artefact
    merge: float = 1e-8  # nonsingular endpoints closer than this (relative) are one solution
    hessian: float = 1e-9  # eigenvalues within this (relative to k L3^2) of 0: degenerate
    newton_steps: int = 3
    # An endpoint this close (units of L3) to a d = 0 artefact is that artefact. Small: a genuine
    # equilibrium can sit 1e-4 from one (a spring compressed to 2e-4 m, seen in a random geometry).
    snap: float = 2e-5
