"""Numbers as literals that every Bertini parser reads: one form for every template, route
and CONFIG line."""

from __future__ import annotations

import math


def bertini_number(c: float) -> str:
    """A real literal that round-trips in double precision and that Bertini 1 and 2 both read.

    Bertini 2's parser refuses a mantissa without a decimal point ("1e-05", "5e-324") and an
    exponent with a sign "+" ("1e+16", "1.5e+300"), both of which Python's shortest repr writes;
    so: the shortest repr, ".0" added to a bare mantissa, the exponent as a plain integer."""
    x = float(c)
    if not math.isfinite(x):
        raise ValueError(f"{c!r}: not a finite number, no Bertini literal")
    mantissa, e, exponent = repr(x).partition("e")
    if not e:
        return mantissa
    if "." not in mantissa:
        mantissa += ".0"
    return f"{mantissa}e{int(exponent)}"
