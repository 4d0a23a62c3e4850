"""What one parameter set's solve returns, whichever route made it."""

from __future__ import annotations

import time
from contextlib import contextmanager
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ..backends.endpoints import Endpoints
from ..params import Params
from ..settings import Settings

STATUS_OK = "ok"

STATUS_INCOMPLETE = "incomplete"

STATUS_CONTRADICTION = "contradiction"  # a proof that contradicts an independent check: a bug


@dataclass
class Timings:
    """Wall-clock seconds per stage."""

    stages: dict[str, float] = field(default_factory=dict)

    @contextmanager
    def stage(self, name: str):
        start = time.perf_counter()
        try:
            yield
        finally:
            self.stages[name] = self.stages.get(name, 0.0) + time.perf_counter() - start


@dataclass(frozen=True)
class PointSolution:
    """The classified solutions of one parameter set and everything that produced them."""

    params: Params
    settings: Settings
    columns: dict[str, np.ndarray]  # the solutions.csv columns, as numpy arrays
    endpoints: Endpoints
    counts: dict
    morse: dict
    status: str  # "ok"; "incomplete" when a completeness check failed; "contradiction"
    warnings: tuple[str, ...]
    engine: dict  # flavour, path, version
    system: dict  # variables, functions, degrees, total degree
    details: dict  # engine specifics: homotopy report and generic set, or the cli attempts
    input_text: str
    timings: dict
    warm: object = None  # homotopy engine: this point as a start for a neighbouring one
    continua: tuple = ()  # a framework's continua of equilibria: continuum_record dicts

    @cached_property
    def table(self):
        """The solutions as a pandas DataFrame (built on first use: pandas loads only then)."""
        import pandas as pd

        return pd.DataFrame(self.columns)
