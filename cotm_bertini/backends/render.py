"""Render polynomial systems and solver settings as solver input text (Jinja2 templates)."""

from __future__ import annotations

from collections.abc import Callable
from functools import lru_cache

import numpy as np

from ..fs import cache_root
from ..literals import bertini_number
from ..model.polynomial import ParametricSystem, PolySystem, Subfunctions
from ..resources import template_texts
from ..settings import Settings


@lru_cache(maxsize=1)
def _environment():
    import jinja2

    folder = cache_root() / "jinja"
    folder.mkdir(parents=True, exist_ok=True)
    return jinja2.Environment(
        loader=jinja2.DictLoader(template_texts()),
        # Compiled templates are kept (keyed by their source): ~10 ms a process saved.
        bytecode_cache=jinja2.FileSystemBytecodeCache(str(folder)),
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )


def phc_number(c: float) -> str:
    """A real literal that round-trips in PHCpack's E notation (17 significant digits)."""
    return f"{float(c):.16E}"


def complex_number(z: complex) -> str:
    """A Bertini literal for a (possibly complex) number: (re+im*I)."""
    z = complex(z)
    if z.imag == 0:
        return f"({bertini_number(z.real)})"
    sign = "+" if z.imag >= 0 else "-"
    return f"({bertini_number(z.real)}{sign}{bertini_number(abs(z.imag))}*I)"


def _monomial(names: tuple[str, ...], exps: np.ndarray) -> str:
    return "*".join(n if e == 1 else f"{n}^{int(e)}" for n, e in zip(names, exps, strict=True) if e)


def polynomial_text(
    names: tuple[str, ...],
    exps: np.ndarray,
    coeffs: np.ndarray,
    number: Callable[[float], str] = bertini_number,
) -> str:
    """One polynomial as text, terms in a fixed graded order; complex coefficients as (a+b*I)."""
    if np.iscomplexobj(coeffs) and np.any(np.imag(coeffs) != 0):
        terms = [
            complex_number(c) + (f"*{_monomial(names, e)}" if e.any() else "")
            for e, c in zip(exps, coeffs, strict=True)
        ]
        return " + ".join(terms) if terms else "0"
    coeffs = np.real(coeffs)
    order = sorted(range(len(coeffs)), key=lambda i: (-int(exps[i].sum()), tuple(-exps[i])))
    parts = []
    for i in order:
        c, mono = float(coeffs[i]), _monomial(names, exps[i])
        mag = number(abs(c))
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


def _functions(system: PolySystem) -> list[dict[str, str]]:
    return [
        {"name": n, "text": polynomial_text(system.variables, e, c)}
        for n, e, c in zip(system.names, system.exponents, system.coefficients, strict=True)
    ]


def subfunction_lines(structured: Subfunctions | None) -> list[str]:
    """The constants' declaration and values, then the subfunctions, as input-file lines (after
    the `function` declaration, before the functions); none without a structure."""
    if not structured:
        return []
    lines = []
    if structured.constants:
        lines.append(f"constant {', '.join(n for n, _ in structured.constants)};")
        lines += [f"{n} = {complex_number(v)};" for n, v in structured.constants]
    return lines + [f"{n} = {t};" for n, t in structured.definitions]


def function_texts(system: PolySystem) -> list[str]:
    """Each function as Bertini text: over the system's subfunctions when it has them (write
    subfunction_lines before them), else its terms."""
    if system.structured:
        return list(system.structured.texts)
    return [f["text"] for f in _functions(system)]


def render_input(
    system: PolySystem, settings: Settings, params: dict[str, float], title: str = ""
) -> str:
    """The Bertini classic input file text for `system` under `settings`."""
    return (
        _environment()
        .get_template("zero_dim.input.j2")
        .render(
            title=title or "CoTM equilibria",
            params=params,
            config=settings.bertini_config(),
            variable_groups=variable_groups(system, settings),
            functions=_functions(system),
        )
    )


def render_system(system: PolySystem, groups: list[list[str]] | None = None) -> str:
    """A bare INPUT section (no CONFIG) for Bertini 2's in-process parser; complex allowed.
    With `groups`, one variable_group each (Bertini then starts multihomogeneously). A system
    with subfunctions (PolySystem.structured) is written with them."""
    return (
        _environment()
        .get_template("system.input.j2")
        .render(
            groups=groups or [list(system.variables)],
            functions=[
                {"name": n, "text": t}
                for n, t in zip(system.names, function_texts(system), strict=True)
            ],
            definitions=subfunction_lines(system.structured),
        )
    )


def parametric_texts(ps: ParametricSystem) -> tuple[str, ...]:
    """Each function as text in the variables and the parameters (the derivation's texts, or,
    for a system with parameters fixed, rendered from its terms)."""
    if ps.texts:
        return ps.texts
    names = tuple(ps.variables) + tuple(ps.parameters)
    return tuple(
        polynomial_text(names, np.hstack([ve, pe]), c)
        for ve, pe, c in zip(ps.var_exps, ps.par_exps, ps.coeffs, strict=True)
    )


def render_parameter_homotopy(
    ps: ParametricSystem,
    start: dict[str, complex],
    target: dict[str, complex],
    detour: dict[str, complex] | None = None,
    texts: tuple[str, ...] | None = None,
    twist: dict[str, complex] | None = None,
) -> str:
    """INPUT section of the homotopy moving the parameters from `start` (t=1) to `target` (t=0),
    on a straight line, or bulging into the complex plane by `detour` * t (1 - t), plus
    `twist` * t^2 (1 - t) for the parameters it names (their paths then loop, not go and come
    back along one segment). Without `texts`, a system with subfunctions (ps.structured) is
    written with them."""
    twist = twist or {}
    parameters = [
        {
            "name": n,
            "start": complex_number(start[n]),
            "target": complex_number(target[n]),
            "detour": complex_number(detour[n]) if detour else "",
            "twist": complex_number(twist[n]) if n in twist else "",
        }
        for n in ps.parameters
    ]
    structured = ps.structured if texts is None else None
    if texts is None:
        texts = structured.texts if structured else parametric_texts(ps)
    functions = [{"name": n, "text": t} for n, t in zip(ps.names, texts, strict=True)]
    return (
        _environment()
        .get_template("parameter_homotopy.input.j2")
        .render(
            variables=ps.variables,
            parameters=parameters,
            functions=functions,
            definitions=subfunction_lines(structured),
        )
    )
