"""cotm-bertini: every equilibrium of a compliant tensegrity mechanism, with Bertini.

    import cotm_bertini as cb
    res = cb.solve(cb.Params.case("case3"))      # -> cb.Solutions
    res.physical, res.stable, res.counts, res.save("runs/mine")
    sw = cb.sweep(cb.Params(), "L01", [0.0, 6.0, 12.0])   # -> cb.Sweep

Names load on first use, so `import cotm_bertini` stays cheap (no numpy, pandas or Bertini).
"""

from __future__ import annotations

from importlib import import_module

from ._version import __version__

_EXPORTS = {
    "Params": "cotm_bertini.params",
    "Framework": "cotm_bertini.model.framework.spec",
    "Settings": "cotm_bertini.settings",
    "Tolerances": "cotm_bertini.settings",
    "Solutions": "cotm_bertini.api.solutions",
    "solve": "cotm_bertini.api.solutions",
    "Sweep": "cotm_bertini.api.sweeps",
    "sweep": "cotm_bertini.api.sweeps",
    "resume_sweep": "cotm_bertini.api.sweeps",
    "certify": "cotm_bertini.api.certificates",
    "cost": "cotm_bertini.api.costs",
    "Cost": "cotm_bertini.api.costs",
    "barriers": "cotm_bertini.api.barriers",
    "Barriers": "cotm_bertini.api.barriers",
    "design": "cotm_bertini.analysis.design.free_lengths",
    "fold_curves": "cotm_bertini.catastrophe.paper_folds",
    "design_map": "cotm_bertini.api.maps",
    "DesignMap": "cotm_bertini.api.maps",
    "Design": "cotm_bertini.analysis.design.free_lengths",
    "move": "cotm_bertini.api.motion",
    "Move": "cotm_bertini.api.motion",
    "plan": "cotm_bertini.api.motion",
    "Plan": "cotm_bertini.api.motion",
    "CertificateError": "cotm_bertini.errors",
    "CotmError": "cotm_bertini.errors",
    "ParameterError": "cotm_bertini.errors",
    "SolverError": "cotm_bertini.errors",
}

__all__ = ["__version__", *_EXPORTS]


def __getattr__(name: str):
    if name in _EXPORTS:
        value = getattr(import_module(_EXPORTS[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'cotm_bertini' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
