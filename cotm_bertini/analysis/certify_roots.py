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

from ..model.compiled import parametric_system, polynomial_system
from ..params import LENGTHS, PARAM_NAMES, Params

RADII = (1e-12, 1e-10, 1e-8, 1e-6)  # tried in turn, relative to 1 + |c|
WORKING_BITS = 128  # the centre is polished by Newton at this precision first


@dataclass(frozen=True)
class BallSystem:
    """A polynomial system with ball coefficients: per function, (coefficient, exponents)."""

    variables: tuple[str, ...]
    terms: tuple[tuple[tuple[object, tuple[int, ...]], ...], ...]
    top: int


def ball_system(params: Params) -> BallSystem:
    """The normalised system of `params` with arb coefficients (parameters divided by L3 and
    max(k) in ball arithmetic, so the rounding of the normalisation is accounted for)."""
    from flint import arb

    ps = parametric_system(params.zfl)
    length, stiff = arb(params.L3), arb(max(params.k1, params.k2))
    values = {n: arb(getattr(params, n)) / (length if n in LENGTHS else stiff) for n in PARAM_NAMES}
    terms = []
    for ve, pe, c in zip(ps.var_exps, ps.par_exps, ps.coeffs, strict=True):
        function = []
        for exps, pexps, coef in zip(ve, pe, c, strict=True):
            ball = arb(float(coef))
            for name, e in zip(ps.parameters, pexps, strict=True):
                ball = ball * values[name] ** int(e) if e else ball
            function.append((ball, tuple(int(v) for v in exps)))
        terms.append(tuple(function))
    top = max(max(e) for f in terms for _, e in f)
    return BallSystem(ps.variables, tuple(terms), top)


def _powers(x: list, top: int) -> list[list]:
    out = []
    for v in x:
        row = [v**0]
        for _ in range(top):
            row.append(row[-1] * v)
        out.append(row)
    return out


def evaluate(system: BallSystem, x: list) -> list:
    """F at a vector of acb balls."""
    pw = _powers(x, system.top)
    out = []
    for function in system.terms:
        total = x[0] * 0
        for coef, exps in function:
            term = coef
            for v, e in enumerate(exps):
                if e:
                    term = term * pw[v][e]
            total = total + term
        out.append(total)
    return out


def jacobian(system: BallSystem, x: list) -> list[list]:
    """The Jacobian at (over) a vector of acb balls."""
    pw = _powers(x, system.top)
    n = len(x)
    out = []
    for function in system.terms:
        row = [x[0] * 0 for _ in range(n)]
        for coef, exps in function:
            for j, ej in enumerate(exps):
                if not ej:
                    continue
                term = coef * ej
                for v, e in enumerate(exps):
                    power = e - 1 if v == j else e
                    if power:
                        term = term * pw[v][power]
                row[j] = row[j] + term
        out.append(row)
    return out


def polish(system: BallSystem, y: np.ndarray, c: np.ndarray, steps: int = 3) -> list:
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


def krawczyk(system: BallSystem, jac_mid: np.ndarray, c: np.ndarray, r: float) -> bool:
    """Whether the box of half-width r around c (complex) holds exactly one solution."""
    from flint import acb, acb_mat, arb

    if not np.isfinite(jac_mid).all() or abs(np.linalg.det(jac_mid)) < 1e-300:
        return False
    y = np.linalg.inv(jac_mid)
    n = len(c)
    centre = polish(system, y, c)
    moved = max(abs(complex(z.mid()) - complex(w)) for z, w in zip(centre, c, strict=True))
    if moved > 1e-6 * (1 + float(np.abs(c).max())):
        return False  # the reported point is not that root to the digits it claims
    real = not np.any(np.imag(c))
    if real:  # keep a real centre real: the box must be its own conjugate
        centre = [acb(z.real.mid()) for z in centre]
    box = [acb(arb(z.real.mid(), r), arb(z.imag.mid(), r)) for z in centre]
    ym = acb_mat([[acb(float(y[i, j].real), float(y[i, j].imag)) for j in range(n)]
                  for i in range(n)])  # fmt: skip
    fc = acb_mat([[f] for f in evaluate(system, centre)])
    jx = acb_mat(jacobian(system, box))
    ident = acb_mat([[1 if i == j else 0 for j in range(n)] for i in range(n)])
    diff = acb_mat([[box[i] - centre[i]] for i in range(n)])
    k = acb_mat([[z] for z in centre]) - ym * fc + (ident - ym * jx) * diff
    return all(box[i].contains_interior(k[i, 0]) for i in range(n))


def certify_rows(params: Params, table) -> tuple[np.ndarray, np.ndarray]:
    """For each row of a solutions table: (proved, box half-width in normalised units or NaN).

    A real row is proved real (a box centred on the real space); a complex one proved non-real.
    Singular rows (double roots) cannot pass: the Jacobian is singular there.
    """
    variables = parametric_system(params.zfl).variables
    numeric = polynomial_system(params.normalized())
    scale = np.array([params.L3 if v.startswith("d") else 1.0 for v in variables])
    re = np.column_stack([np.asarray(table[f"{v}_re"], float) for v in variables])
    im = np.column_stack([np.asarray(table[f"{v}_im"], float) for v in variables])
    points = (re + 1j * im) / scale
    real = np.asarray(table["is_real"], dtype=bool)
    proved = np.zeros(len(points), dtype=bool)
    radius = np.full(len(points), np.nan)
    from flint import ctx

    bits, ctx.prec = ctx.prec, WORKING_BITS
    try:
        system = ball_system(params)
        for i, c in enumerate(points):
            c = c.real + 0j if real[i] else c
            jac = numeric.jacobian(c[None, :])[0]
            for rel in RADII:
                r = rel * (1 + float(np.abs(c).max()))
                if not real[i] and (np.abs(c.imag) <= r).all():
                    continue  # this box would reach the real space: no proof of non-realness
                if krawczyk(system, jac, c, r):
                    proved[i], radius[i] = True, r
                    break
    finally:
        ctx.prec = bits
    return proved, radius
