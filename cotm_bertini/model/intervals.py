"""Interval arithmetic over numpy arrays: many boxes at once, rounded outwards.

An `Interval` holds arrays `lo` and `hi` (any broadcastable shapes) with lo <= x <= hi for every
real number x it stands for. Each operation computes its bounds in double precision and moves
them outwards: IEEE addition, multiplication, division and square root are correctly rounded
(error at most half an ulp), so a step of |x| 2^-52 (at least one ulp) each way keeps the true
result inside; sin, cos and non-integer powers (whose libm results are not guaranteed correctly
rounded) are widened further (`_PAD_TRIG`, `_PAD_POW`). An unbounded or undefined result is
[-inf, inf].

It has the methods a framework's generated code calls (+ - * / **, sqrt, sin, cos: the same
source `model.framework.ballcode` evaluates on arb balls), so one call of a generated function
encloses it over a whole batch of boxes: numpy's loops in place of one ball object per box.
"""

from __future__ import annotations

import warnings

import numpy as np

# _down and _up may overflow to -inf / +inf (a valid bound) for a bound within |x| eps of the
# largest double; numpy's warning for that, raised in this module only, says nothing wrong.
warnings.filterwarnings("ignore", "overflow encountered", RuntimeWarning, __name__)

INF = np.inf
_PAD_TRIG = 4e-16  # absolute: libm sin/cos are within one ulp (<= 1.2e-16 on [-1, 1])
_PAD_POW = 8e-16  # relative: libm pow is within a few ulps


_EPS = 2.0**-52  # |x| * _EPS is at least the gap from x to the next double either side
_TINY = 1e-300  # absolute: covers results that underflow (their error is below 1e-323)
_MAX = np.finfo(float).max
_STEP = _MAX * _EPS  # |x| eps for the largest finite x


def _down(x: np.ndarray) -> np.ndarray:
    """A double below every real number that rounds to x: x - |x| eps lies at or beyond the
    next double below, and rounding is monotone (several times cheaper than nextafter). The
    step is capped at _STEP (the largest a finite x takes), so that +inf - step stays +inf (no
    inf - inf), and an overflow to +inf moves back to the largest double (a lower bound is
    never +inf); no error state to set, which costs more than the arithmetic on a batch."""
    return np.minimum(x - (np.minimum(np.abs(x) * _EPS, _STEP) + _TINY), _MAX)


def _up(x: np.ndarray) -> np.ndarray:
    """A double above every real number that rounds to x (see _down)."""
    return np.maximum(x + (np.minimum(np.abs(x) * _EPS, _STEP) + _TINY), -_MAX)


def _clean(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """NaN bounds (inf - inf, an undefined operation) become unbounded: no bound is ever NaN,
    which the products rely on."""
    bad = np.isnan(lo)
    if bad.any():
        lo = np.where(bad, -INF, lo)
    bad = np.isnan(hi)
    if bad.any():
        hi = np.where(bad, INF, hi)
    return lo, hi


class Interval:
    """Arrays of closed intervals [lo, hi] (see the module docstring)."""

    __slots__ = ("lo", "hi")
    __array_priority__ = 1000  # numpy scalars and arrays defer to our reflected operators

    def __init__(self, lo, hi=None):
        self.lo = np.asarray(lo, dtype=float)
        self.hi = self.lo if hi is None else np.asarray(hi, dtype=float)

    # --- construction and queries -------------------------------------------------------------
    @staticmethod
    def of(x) -> Interval:
        """An Interval from an Interval or an exact number (array)."""
        return x if isinstance(x, Interval) else Interval(x)

    @property
    def mid(self) -> np.ndarray:
        """The midpoints; NaN for [-inf, inf], which callers read as not finite (a Krawczyk
        step with an unbounded Hessian entry is no step): no RuntimeWarning on the console."""
        with np.errstate(invalid="ignore"):
            return 0.5 * self.lo + 0.5 * self.hi

    @property
    def width(self) -> np.ndarray:
        return self.hi - self.lo

    def contains_zero(self) -> np.ndarray:
        return (self.lo <= 0.0) & (self.hi >= 0.0)

    def finite(self) -> np.ndarray:
        return np.isfinite(self.lo) & np.isfinite(self.hi)

    def __getitem__(self, index) -> Interval:
        return Interval(self.lo[index], self.hi[index])

    def __repr__(self) -> str:
        return f"Interval({self.lo!r}, {self.hi!r})"

    @staticmethod
    def hull(a: Interval, b: Interval) -> Interval:
        return Interval(np.minimum(a.lo, b.lo), np.maximum(a.hi, b.hi))

    @staticmethod
    def where(mask, a: Interval, b: Interval) -> Interval:
        a, b = Interval.of(a), Interval.of(b)
        return Interval(np.where(mask, a.lo, b.lo), np.where(mask, a.hi, b.hi))

    # --- arithmetic ---------------------------------------------------------------------------
    def __neg__(self) -> Interval:
        return Interval(-self.hi, -self.lo)

    def __pos__(self) -> Interval:
        return self

    def __add__(self, other) -> Interval:
        if not isinstance(other, Interval):
            if np.ndim(other) == 0:
                if other == 0:
                    return self
            else:  # numbers per box: each 0 kept exact, as one given alone is
                zero = np.asarray(other, dtype=float) == 0
                out = self + Interval(other)
                return Interval(np.where(zero, self.lo, out.lo), np.where(zero, self.hi, out.hi))
            other = Interval(other)
        # No NaN: a lower bound is never +inf (_down moves an overflow back to the largest
        # double) nor an upper bound -inf, so inf - inf cannot arise.
        return Interval(_down(self.lo + other.lo), _up(self.hi + other.hi))

    __radd__ = __add__

    def __sub__(self, other) -> Interval:
        return self + (-Interval.of(other))

    def __rsub__(self, other) -> Interval:
        return Interval.of(other) + (-self)

    def square(self) -> Interval:
        a, b = self.lo * self.lo, self.hi * self.hi
        low = np.where(self.lo > 0, a, np.where(self.hi < 0, b, 0.0))
        return Interval(*_clean(np.maximum(_down(low), 0.0), _up(np.maximum(a, b))))

    def __mul__(self, other) -> Interval:
        if other is self:
            return self.square()
        if not isinstance(other, Interval):
            c = np.asarray(other, dtype=float)
            if c.ndim == 0 and c == 1.0:
                return self
            lo = np.where(c >= 0, c * self.lo, c * self.hi)
            hi = np.where(c >= 0, c * self.hi, c * self.lo)
            lo, hi = _down(np.where(c == 0, 0.0, lo)), _up(np.where(c == 0, 0.0, hi))
            if c.ndim:  # numbers per box: each 1 kept exact, as one given alone is
                lo, hi = np.where(c == 1.0, self.lo, lo), np.where(c == 1.0, self.hi, hi)
            return Interval(lo, hi)
        with np.errstate(invalid="ignore"):  # 0 * inf: below
            p = [self.lo * other.lo, self.lo * other.hi, self.hi * other.lo, self.hi * other.hi]
        # 0 * inf is nan; as a product of reals (an unbounded end stands for finite numbers) it
        # is 0. fmin and fmax pass a nan over, and the other products of that same 0 end give
        # 0, so only when all four are nan ([0, 0] times [-inf, inf]) is a bound left nan.
        lo = np.fmin(np.fmin(p[0], p[1]), np.fmin(p[2], p[3]))
        hi = np.fmax(np.fmax(p[0], p[1]), np.fmax(p[2], p[3]))
        bad = np.isnan(lo)
        if bad.any():
            lo, hi = np.where(bad, 0.0, lo), np.where(bad, 0.0, hi)
        return Interval(_down(lo), _up(hi))

    __rmul__ = __mul__

    def reciprocal(self) -> Interval:
        """1 / self; unbounded where self holds 0."""
        zero = self.contains_zero()
        with np.errstate(divide="ignore"):
            lo, hi = _down(1.0 / self.hi), _up(1.0 / self.lo)
        return Interval(np.where(zero, -INF, lo), np.where(zero, INF, hi))

    def __truediv__(self, other) -> Interval:
        if not isinstance(other, Interval):
            c = np.asarray(other, dtype=float)
            lo, hi = np.minimum(self.lo / c, self.hi / c), np.maximum(self.lo / c, self.hi / c)
            return Interval(_down(lo), _up(hi))
        return self * other.reciprocal()

    def __rtruediv__(self, other) -> Interval:
        return Interval.of(other) * self.reciprocal()

    def __pow__(self, n) -> Interval:
        if isinstance(n, (int, np.integer)) or (isinstance(n, float) and n.is_integer()):
            n = int(n)
            if n == 0:
                return Interval(np.ones(np.broadcast(self.lo, self.hi).shape))
            out, base, k = None, self, abs(n)
            while k:  # repeated squaring: each step a valid enclosure
                if k & 1:
                    out = base if out is None else out * base
                k >>= 1
                base = base.square() if k else base
            return out if n > 0 else out.reciprocal()
        # A real power is defined for x >= 0 only (here: squared lengths).
        lo, hi = np.maximum(self.lo, 0.0), np.maximum(self.hi, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):  # 0 ** -r: inf, unbounded
            a, b = (lo**n, hi**n) if n > 0 else (hi**n, lo**n)
            return Interval(*_clean(a * (1 - _PAD_POW), b * (1 + _PAD_POW) + 1e-300))

    # --- functions ----------------------------------------------------------------------------
    def sqrt(self) -> Interval:
        lo, hi = np.maximum(self.lo, 0.0), np.maximum(self.hi, 0.0)
        return Interval(np.maximum(_down(np.sqrt(lo)), 0.0), _up(np.sqrt(hi)))

    def cos(self) -> Interval:
        return (self + np.pi / 2).sin()

    def sin(self) -> Interval:
        """sin over each interval: its values at the ends, and +-1 where a crest or trough of
        sin lies inside (tested against pi rounded outwards, so none is missed)."""
        lo, hi = self.lo, self.hi
        a, b = np.sin(lo), np.sin(hi)
        out_lo, out_hi = np.minimum(a, b) - _PAD_TRIG, np.maximum(a, b) + _PAD_TRIG
        # crest at pi/2 + 2 pi k, trough at -pi/2 + 2 pi k: is one in [lo, hi]?
        k_crest = np.ceil((lo - np.pi / 2) / (2 * np.pi) - 1e-12)
        crest = np.pi / 2 + 2 * np.pi * k_crest <= hi * (1 + 1e-15) + 1e-12
        k_trough = np.ceil((lo + np.pi / 2) / (2 * np.pi) - 1e-12)
        trough = -np.pi / 2 + 2 * np.pi * k_trough <= hi * (1 + 1e-15) + 1e-12
        wide = ~(hi - lo < 2 * np.pi) | ~np.isfinite(lo) | ~np.isfinite(hi)
        out_hi = np.where(crest | wide, 1.0, np.minimum(out_hi, 1.0))
        out_lo = np.where(trough | wide, -1.0, np.maximum(out_lo, -1.0))
        return Interval(out_lo, out_hi)

    def sin_cos(self) -> tuple[Interval, Interval]:
        return self.sin(), self.cos()

    def isum(self, axis: int) -> Interval:
        """The sum along an axis, rounded outwards (a floating sum of n terms is within
        (n - 1) eps sum |x_i| of the true one)."""
        n = self.lo.shape[axis]
        pad = n * np.finfo(float).eps
        lo, hi = self.lo.sum(axis=axis), self.hi.sum(axis=axis)
        with np.errstate(invalid="ignore"):
            lo = lo - pad * np.abs(self.lo).sum(axis=axis) - 1e-300
            hi = hi + pad * np.abs(self.hi).sum(axis=axis) + 1e-300
        return Interval(*_clean(lo, hi))


def stack(items: list, axis: int = -1) -> Interval:
    """Intervals (or numbers) of one shape stacked along a new axis."""
    items = [Interval.of(v) for v in items]
    shape = np.broadcast_shapes(*(np.shape(v.lo) for v in items))
    lo = np.stack([v.lo if v.lo.shape == shape else np.broadcast_to(v.lo, shape)
                   for v in items], axis=axis)  # fmt: skip
    hi = np.stack([v.hi if v.hi.shape == shape else np.broadcast_to(v.hi, shape)
                   for v in items], axis=axis)  # fmt: skip
    return Interval(lo, hi)
