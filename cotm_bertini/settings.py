"""Solver settings: Bertini configuration, engine choice, time limit."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

# Bertini CONFIG keys we render, and their names in the input file.
_CONFIG_KEYS = {
    "mptype": "MPType",
    "precision": "Precision",
    "final_tol": "FinalTol",
    "tracktol_before_eg": "TrackTolBeforeEG",
    "tracktol_during_eg": "TrackTolDuringEG",
    "security_level": "SecurityLevel",
    "condnum_threshold": "CondNumThreshold",
    "max_norm": "MaxNorm",
}


@dataclass(frozen=True)
class Settings:
    """How to run Bertini. None leaves a setting at Bertini's default."""

    seed: int = 1
    mptype: int = 2
    precision: int | None = None
    final_tol: float | None = None
    tracktol_before_eg: float | None = None
    tracktol_during_eg: float | None = None
    security_level: int | None = None
    condnum_threshold: float | None = None
    max_norm: float | None = None
    variable_groups: str = "total_degree"  # or "multihomogeneous"
    engine: str = "homotopy"  # or "cli": a total-degree solve by the bertini2 / Bertini 1 binary
    timeout: float = 600.0
    threads: int | None = None  # None: Bertini 2 uses every core
    bertini: str | None = None  # path of a Bertini 1.x binary; None: bundled bertini2
    extra_config: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if self.mptype not in (0, 1, 2):
            raise ValueError(f"mptype = {self.mptype!r}: expected 0, 1 or 2")
        if not 0 <= self.seed < 2**31:
            raise ValueError(f"seed = {self.seed!r}: expected an integer in [0, 2^31)")
        if self.timeout <= 0:
            raise ValueError(f"timeout = {self.timeout!r}: must be > 0 seconds")
        if self.engine not in ("homotopy", "cli"):
            raise ValueError(f"engine = {self.engine!r}: expected 'homotopy' or 'cli'")
        if self.bertini is not None and self.engine != "cli":
            object.__setattr__(self, "engine", "cli")  # a user's binary means the CLI route
        if self.variable_groups not in ("total_degree", "multihomogeneous"):
            raise ValueError(
                f"variable_groups = {self.variable_groups!r}: "
                "expected 'total_degree' or 'multihomogeneous'"
            )

    def bertini_config(self) -> dict[str, str]:
        """The CONFIG section as Bertini key -> value text."""
        cfg = {"MPType": str(self.mptype), "RandomSeed": str(self.seed)}
        for attr, key in _CONFIG_KEYS.items():
            value = getattr(self, attr)
            if value is not None and attr != "mptype":
                cfg[key] = repr(value) if isinstance(value, float) else str(value)
        cfg.update(self.extra_config)
        return cfg

    def retry(self) -> Settings:
        """Settings for a second attempt: another seed, tighter path tracking."""
        from dataclasses import replace

        before = min(self.tracktol_before_eg or 1e-5, 1e-5)
        during = min(self.tracktol_during_eg or 1e-6, 1e-6)
        return replace(
            self,
            seed=(self.seed + 7919) % 2**31,
            tracktol_before_eg=float(f"{before / 100:.3g}"),
            tracktol_during_eg=float(f"{during / 100:.3g}"),
        )

    def as_dict(self) -> dict:
        """All settings, for run.json."""
        return asdict(self)
