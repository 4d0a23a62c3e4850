"""Render a polynomial system and solver settings as a Bertini classic input file (Jinja2)."""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import jinja2
import numpy as np

from .equations import PolySystem
from .settings import Settings

TEMPLATES = Path(__file__).resolve().parent.parent / "templates"


@lru_cache(maxsize=1)
def _environment() -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(TEMPLATES),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )


def _number(c: float) -> str:
    # repr round-trips a double exactly; Bertini reads the e-notation of repr.
    return repr(float(c))


def _monomial(names: tuple[str, ...], exps: np.ndarray) -> str:
    return "*".join(n if e == 1 else f"{n}^{e}" for n, e in zip(names, exps, strict=True) if e)


def polynomial_text(names: tuple[str, ...], exps: np.ndarray, coeffs: np.ndarray) -> str:
    """One polynomial in Bertini syntax, terms in a fixed (graded) order."""
    order = sorted(range(len(coeffs)), key=lambda i: (-int(exps[i].sum()), tuple(-exps[i])))
    parts = []
    for i in order:
        c, mono = float(coeffs[i]), _monomial(names, exps[i])
        mag = _number(abs(c))
        term = mono if (mono and mag == "1.0") else (f"{mag}*{mono}" if mono else mag)
        parts.append(("- " if c < 0 else "+ ") + term)
    if not parts:
        return "0"
    text = " ".join(parts)
    return text[2:] if text.startswith("+ ") else "-" + text[2:]


def variable_groups(system: PolySystem, settings: Settings) -> list[list[str]]:
    """One group of all variables, or {c1,s1},{c2,s2},{d1},{d2} for a multihomogeneous start."""
    if settings.variable_groups == "total_degree":
        return [list(system.variables)]
    groups = [["c1", "s1"], ["c2", "s2"]]
    groups += [[v] for v in system.variables if v.startswith("d")]
    return groups


def render_input(
    system: PolySystem, settings: Settings, params: dict[str, float], title: str = ""
) -> str:
    """The Bertini classic input file text for `system` under `settings`."""
    functions = [
        {"name": n, "text": polynomial_text(system.variables, e, c)}
        for n, e, c in zip(system.names, system.exponents, system.coefficients, strict=True)
    ]
    return (
        _environment()
        .get_template("zero_dim.input.j2")
        .render(
            title=title or "CoTM equilibria",
            params=params,
            config=settings.bertini_config(),
            variable_groups=variable_groups(system, settings),
            functions=functions,
        )
    )
