"""Each reported solution, proved: the Krawczyk test in complex ball arithmetic (python-flint's
acb) on the polynomial system, in units of L3 and max(k) as the solver uses.

For a box X around a reported solution c, Y an approximate inverse of the Jacobian at c,
    K(X) = c - Y F(c) + (I - Y J(X)) (X - c);
K(X) inside the interior of X proves that X holds exactly one solution. The coefficients are
balls computed from the parameters (floats, exact), so the proof is about the system those
parameters define. A box centred on the real space is its own conjugate: a unique solution in it
is real. A box whose imaginary parts exclude 0 in some variable holds no real solution.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...model.compiled import parametric_system, polynomial_system
from ...params import LENGTHS, PARAM_NAMES, Params

RADII = (1e-12, 1e-10, 1e-8, 1e-6)  # tried in turn, relative to 1 + |c|
WORKING_BITS = 128  # the centre is polished by Newton at this precision first


@dataclass(frozen=True)
class BallSystem:
    """A polynomial system with ball coefficients. `terms`: per function, (coefficient,
    ((variable, exponent), ...)) with the zero exponents left out; `derivatives`: per function
    and variable, the terms of the partial derivative in the same form."""

    variables: tuple[str, ...]
    terms: tuple[tuple[tuple[object, tuple[tuple[int, int], ...]], ...], ...]
    derivatives: tuple[tuple[tuple, ...], ...]
    top: int


def ball_system(params: Params) -> BallSystem:
    """The normalised system of `params` with arb coefficients (parameters divided by L3 and
    max(k) in ball arithmetic, so the rounding of the normalisation is accounted for)."""
    from flint import arb

    length, stiff = arb(params.L3), arb(max(params.k1, params.k2))
    values = {n: arb(getattr(params, n)) / (length if n in LENGTHS else stiff) for n in PARAM_NAMES}
    return ball_system_of(parametric_system(params.zfl), values)


def ball_system_of(ps, values: dict) -> BallSystem:
    """A ParametricSystem with its parameters set to balls (`values`: name -> arb): the
    coefficients become balls holding the true ones (the stored coefficients are exact: integers
    and halves from the derivation, or the doubles it folded in)."""
    from flint import arb

    terms = []
    for ve, pe, c in zip(ps.var_exps, ps.par_exps, ps.coeffs, strict=True):
        function = []
        for exps, pexps, coef in zip(ve, pe, c, strict=True):
            ball = arb(float(coef))
            for name, e in zip(ps.parameters, pexps, strict=True):
                ball = ball * values[name] ** int(e) if e else ball
            function.append((ball, tuple((v, int(e)) for v, e in enumerate(exps) if e)))
        terms.append(tuple(function))
    n = len(ps.variables)
    derivatives = tuple(tuple(_derivative(f, j) for j in range(n)) for f in terms)
    top = max((e for f in terms for _, pw in f for _, e in pw), default=1)
    return BallSystem(ps.variables, tuple(terms), derivatives, top)


def _derivative(function: tuple, j: int) -> tuple:
    """The terms of d function / d x_j."""
    out = []
    for coef, powers in function:
        for v, e in powers:
            if v == j:
                rest = tuple((w, f - 1 if w == j else f) for w, f in powers if w != j or f > 1)
                out.append((coef * e, rest))
    return tuple(out)


def _powers(x: list, top: int) -> list[list]:
    out = []
    for v in x:
        row = [v**0, v]
        for _ in range(top - 1):
            row.append(row[-1] * v)
        out.append(row)
    return out


def _sum(terms: tuple, pw: list, zero):
    total = zero
    for coef, powers in terms:
        term = coef
        for v, e in powers:
            term = term * pw[v][e]
        total = total + term
    return total


def evaluate(system: BallSystem, x: list) -> list:
    """F at a vector of acb balls."""
    pw, zero = _powers(x, system.top), x[0] * 0
    return [_sum(function, pw, zero) for function in system.terms]


def jacobian(system: BallSystem, x: list) -> list[list]:
    """The Jacobian at (over) a vector of acb balls."""
    pw, zero = _powers(x, system.top), x[0] * 0
    return [[_sum(d, pw, zero) for d in row] for row in system.derivatives]


def polish(system: BallSystem, y: np.ndarray, c: np.ndarray, steps: int = 1) -> list:
    """The centre refined by Newton steps x - Y F(x) in ball arithmetic (at the working
    precision), as acb midpoints: an ill-conditioned root is located far better than in double
    precision, which the Krawczyk box needs. The steps need not be rigorous: only the test is."""
    from flint import acb, acb_mat

    n = len(c)
    ym = acb_mat([[acb(complex(y[i, j])) for j in range(n)] for i in range(n)])
    x = [acb(complex(z)) for z in c]
    for _ in range(steps):
        step = ym * acb_mat([[f] for f in evaluate(system, x)])
        x = [acb((x[i] - step[i, 0]).mid()) for i in range(n)]
    return x


@dataclass(frozen=True)
class _Centre:
    """A reported point prepared for the Krawczyk test: the polished centre (acb), the
    preconditioner Y (acb_mat) and F at the centre (acb_mat)."""

    centre: list
    ym: object
    fc: object


def prepare(system: BallSystem, y: np.ndarray, c: np.ndarray, near: np.ndarray,
            steps: int) -> object:  # fmt: skip
    """The centre for the tests around the reported point c: `near` (a double-precision Newton
    refinement of c) after `steps` Newton steps in ball arithmetic, with Y the inverse of the
    Jacobian there; None if the root is further than 1e-6 (relative) from c: the reported
    point is not that root to the digits it claims."""
    from flint import acb, acb_mat

    centre = polish(system, y, near, steps) if steps else [acb(complex(z)) for z in near]
    moved = max(abs(complex(z.mid()) - complex(w)) for z, w in zip(centre, c, strict=True))
    if moved > 1e-6 * (1 + float(np.abs(c).max())):
        return None
    if not np.any(np.imag(c)):  # keep a real centre real: the box must be its own conjugate
        centre = [acb(z.real.mid()) for z in centre]
    n = len(c)
    ym = acb_mat([[acb(complex(y[i, j])) for j in range(n)] for i in range(n)])
    return _Centre(centre, ym, acb_mat([[f] for f in evaluate(system, centre)]))


def krawczyk(system: BallSystem, prepared: _Centre, r) -> bool:
    """Whether the box of half-width r (a number, or one per variable) around the prepared
    centre holds exactly one solution: K(X) = c - Y F(c) + (I - Y J(X)) (X - c) inside the
    interior of X."""
    from flint import acb, acb_mat, arb

    centre, n = prepared.centre, len(prepared.centre)
    rs = np.broadcast_to(np.asarray(r, dtype=float), (n,))
    box = [acb(arb(z.real.mid(), float(ri)), arb(z.imag.mid(), float(ri)))
           for z, ri in zip(centre, rs, strict=True)]  # fmt: skip
    jx = acb_mat(jacobian(system, box))
    ident = acb_mat([[1 if i == j else 0 for j in range(n)] for i in range(n)])
    diff = acb_mat([[box[i] - centre[i]] for i in range(n)])
    ym = prepared.ym
    k = acb_mat([[z] for z in centre]) - ym * prepared.fc + (ident - ym * jx) * diff
    return all(box[i].contains_interior(k[i, 0]) for i in range(n))


def _newton(numeric, points: np.ndarray, steps: int = 3) -> np.ndarray:
    """Double-precision Newton steps from every point at once (kept where they do not reduce
    the residual): a good start for the polish."""
    x = points.copy()
    for _ in range(steps):
        f = numeric.evaluate(x)
        jac = numeric.jacobian(x)
        ok = np.isfinite(jac).all(axis=(1, 2)) & (np.abs(np.linalg.det(jac)) > 1e-300)
        if not ok.any():
            break
        new = x.copy()
        new[ok] = x[ok] - np.linalg.solve(jac[ok], f[ok][..., None])[..., 0]
        better = np.abs(numeric.evaluate(new)).max(axis=1) < np.abs(f).max(axis=1)
        x = np.where(better[:, None], new, x)
    return x


def certify_rows(params: Params, table) -> tuple[np.ndarray, np.ndarray]:
    """For each row of a solutions table: (proved, box half-width in normalised units or NaN).

    A real row is proved real (a box centred on the real space); a complex one proved non-real.
    Rows the table marks singular (double roots) are not tried: the Jacobian is singular there.
    """
    variables = parametric_system(params.zfl).variables
    numeric = polynomial_system(params.normalized())
    scale = np.array([params.L3 if v.startswith("d") else 1.0 for v in variables])
    re = np.column_stack([np.asarray(table[f"{v}_re"], float) for v in variables])
    im = np.column_stack([np.asarray(table[f"{v}_im"], float) for v in variables])
    real = np.asarray(table["is_real"], dtype=bool)
    points = np.where(real[:, None], re + 0j, re + 1j * im) / scale
    todo = np.flatnonzero(~np.asarray(table["singular"], dtype=bool))
    proved = np.zeros(len(points), dtype=bool)
    radius = np.full(len(points), np.nan)
    proved[todo], radius[todo], _ = certify_points(
        lambda: ball_system(params), numeric, points[todo], real[todo]
    )
    return proved, radius


def certify_points(make_system, numeric, points: np.ndarray, real: np.ndarray,
                   each: bool = False) -> tuple:  # fmt: skip
    """Krawczyk around each point of a polynomial system (normalised units): (proved, box
    half-width or NaN (the largest, with `each`), the proved boxes as (acb centre list,
    half-widths) or None). `make_system()` builds the BallSystem (at the working precision);
    `numeric`: the same system in double precision (evaluate, jacobian) for the Newton
    refinement of the starts; `each`: radii per variable (`_prove`)."""
    from flint import ctx

    near = _newton(numeric, points) if len(points) else points
    near[real] = near[real].real
    n = points.shape[1] if points.ndim == 2 else 0
    jacs = numeric.jacobian(near) if len(points) else np.zeros((0, n, n))
    invertible = np.isfinite(jacs).all(axis=(1, 2)) & (np.abs(np.linalg.det(jacs)) > 1e-300)
    inverses = np.zeros_like(jacs)
    inverses[invertible] = np.linalg.inv(jacs[invertible])
    proved = np.zeros(len(points), dtype=bool)
    radius = np.full(len(points), np.nan)
    centres: list = [None] * len(points)
    bits, ctx.prec = ctx.prec, WORKING_BITS
    try:
        system = make_system() if len(points) else None
        for row, (start, y, ok) in enumerate(zip(near, inverses, invertible, strict=True)):
            if ok:
                ok, r, centre = _prove(system, points[row], start, y, real[row], each)
                if ok:
                    rs = np.broadcast_to(np.asarray(r, dtype=float), (n,))
                    proved[row], radius[row], centres[row] = True, rs.max(), (centre, rs)
    finally:
        ctx.prec = bits
    return proved, radius, centres


def _prove(system: BallSystem, c: np.ndarray, start: np.ndarray, y: np.ndarray, real: bool,
           each: bool = False) -> tuple[bool, object, list | None]:  # fmt: skip
    """(proved, box half-width, the box's centre) for one row: the double-precision centre
    first, then one Newton step in ball arithmetic with each radius in turn (an
    ill-conditioned root). The radii are relative to 1 + max |c|, or with `each` to 1 + |c_i|
    per variable (a box as wide as each variable's own scale: a force density a thousand times
    the others, at a spring of nearly zero length, needs it) and then down to 1e-15."""
    scale = 1 + (np.abs(c) if each else float(np.abs(c).max()))
    radii_all = RADII if not each else (1e-15, 1e-14, 1e-13, *RADII, 1e-5, 1e-4)
    for steps, radii in ((0, RADII[:1]), (1, radii_all)):
        prepared = prepare(system, y, c, start, steps)
        for r in (rel * scale for rel in (radii if prepared is not None else ())):
            if not real and (np.abs(c.imag) <= r).all():
                continue  # this box would reach the real space: no proof of non-realness
            if krawczyk(system, prepared, r):
                return True, r, prepared.centre
    return False, float("nan"), None
