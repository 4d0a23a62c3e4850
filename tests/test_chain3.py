"""examples/chain3.toml (three links pinned in series, four springs, a cable, a weight) against
an independent reference: V(theta1, theta2, theta3) in plain numpy with its exact gradient and
Hessian, every critical point on the 3-torus by Newton from grids of starts. Only the numbers
come from the file (read by tomllib, not by the package), so the two cannot drift apart."""

from __future__ import annotations

import ast
import itertools
import operator
import tomllib
from dataclasses import dataclass

import numpy as np
import pytest
from conftest import ROOT

import cotm_bertini as cb

FILE = ROOT / "examples" / "chain3.toml"
SAME = 1e-7  # rad: two Newton ends closer than this on the torus are one critical point
MATCH_DEG = 1e-6  # the package's angles against the reference's
SWITCH_MARGIN = 0.01  # every critical point's cable this far (length) from its free length
_OPS = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
        ast.Div: operator.truediv, ast.Pow: operator.pow, ast.BitXor: operator.pow}  # fmt: skip


def _number(expr, params: dict[str, float]) -> float:
    """A number of the file: a number, or + - * / ^ of numbers and parameter names."""

    def ev(node) -> float:
        if isinstance(node, ast.Constant):
            return float(node.value)
        if isinstance(node, ast.Name):
            return params[node.id]
        if isinstance(node, ast.UnaryOp):
            return -ev(node.operand) if isinstance(node.op, ast.USub) else ev(node.operand)
        return _OPS[type(node.op)](ev(node.left), ev(node.right))

    return ev(ast.parse(expr, mode="eval").body) if isinstance(expr, str) else float(expr)


@dataclass(frozen=True)
class Chain:
    """The file's mechanism as vectors: a point is c + sum_b R(theta_b) a[b] over the bodies."""

    bodies: tuple[str, ...]
    links: tuple  # (c, a, k, L0, is_cable): the vector from end b to end a of each spring/cable
    loads: tuple  # (F, c, a): the force and the point it acts on

    @property
    def cable(self) -> tuple:
        """The one cable's link."""
        (cable,) = [link for link in self.links if link[4]]
        return cable


def read_chain(**override: float) -> Chain:
    """examples/chain3.toml at its parameter values (or the `override`s), by tomllib."""
    spec = tomllib.loads(FILE.read_text())
    params = {k: float(v) for k, v in spec["parameters"].items()} | override
    bodies = tuple(spec["bodies"])

    def xy(p) -> np.ndarray:
        return np.array([_number(x, params) for x in p])

    where = {f"ground.{n}": (xy(p), np.zeros((len(bodies), 2))) for n, p in spec["ground"].items()}
    pins = list(spec["pins"])
    while pins:  # an open chain: place each body by a pin to a point already placed
        pin = next(p for p in pins if (p["a"] in where) != (p["b"] in where))
        new, old = (pin["a"], pin["b"]) if pin["b"] in where else (pin["b"], pin["a"])
        body, joint = new.split(".")
        for name, p in spec["bodies"][body].items():
            c, a = where[old][0], where[old][1].copy()
            a[bodies.index(body)] = xy(p) - xy(spec["bodies"][body][joint])
            where[f"{body}.{name}"] = (c, a)
        pins.remove(pin)

    def link(e: dict, cable: bool) -> tuple:
        (ca, aa), (cb_, ab) = where[e["a"]], where[e["b"]]
        return ca - cb_, aa - ab, _number(e["k"], params), _number(e["L0"], params), cable

    links = [link(e, False) for e in spec["springs"]] + [link(e, True) for e in spec["cables"]]
    loads = tuple((xy(f["force"]), *where[f["point"]]) for f in spec.get("loads", []))
    return Chain(bodies, tuple(links), loads)


def _turned(theta: np.ndarray, a: np.ndarray) -> np.ndarray:
    """R(theta_b) a[b] for every start and body: (N, nb, 2)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * a[:, 0] - s * a[:, 1], s * a[:, 0] + c * a[:, 1]], axis=-1)


def energy(chain: Chain, theta: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """V, grad V and its Hessian at angles theta (N, nb): springs k/2 (d - L0)^2, the cable
    k/2 max(d - L0, 0)^2 (its Hessian from the side of the switch the point is on), loads -F.x."""
    n, nb = theta.shape
    V, g, H, eye = np.zeros(n), np.zeros((n, nb)), np.zeros((n, nb, nb)), np.eye(nb)
    for c, a, k, L0, cable in chain.links:
        ra = _turned(theta, a)
        tangent = np.stack([-ra[..., 1], ra[..., 0]], axis=-1)  # d(R a)/d theta
        r = c + ra.sum(axis=1)
        d = np.linalg.norm(r, axis=1)
        on = d > L0 if cable else np.ones(n, dtype=bool)
        force = np.where(on, k * (d - L0), 0.0)  # dV/dd
        rt = np.einsum("ni,nbi->nb", r, tangent)
        outer = rt[:, :, None] * rt[:, None, :] / d[:, None, None] ** 2
        curve = (
            np.einsum("nbi,nci->nbc", tangent, tangent)
            - np.einsum("ni,nbi->nb", r, ra)[:, :, None] * eye
        )
        V += np.where(on, k / 2 * (d - L0) ** 2, 0.0)
        g += (force / d)[:, None] * rt
        H += np.where(on, k, 0.0)[:, None, None] * outer
        H += (force / d)[:, None, None] * (curve - outer)
    for F, c, a in chain.loads:
        ra = _turned(theta, a)
        V -= (c + ra.sum(axis=1)) @ F
        g -= np.stack([-ra[..., 1], ra[..., 0]], axis=-1) @ F
        H += (ra @ F)[:, :, None] * eye
    return V, g, H


@dataclass(frozen=True)
class Critical:
    """Every critical point of V on the torus: angles (rad, in [0, 2 pi)), V, Hessian
    eigenvalues, the cable's length."""

    theta: np.ndarray
    V: np.ndarray
    eig: np.ndarray
    cable_d: np.ndarray

    @property
    def index(self) -> np.ndarray:
        """Negative Hessian eigenvalues of each."""
        return (self.eig < 0).sum(axis=1)


def critical_points(chain: Chain, n: int = 12, shift: float = 0.0) -> Critical:
    """Newton on grad V from an n^nb grid of starts (shifted by `shift` rad), steps capped at
    0.5 rad; the ends where |grad V| < 1e-11, one per point of the torus."""
    grid = np.linspace(0, 2 * np.pi, n, endpoint=False) + shift
    theta = np.array(list(itertools.product(grid, repeat=len(chain.bodies))))
    for _ in range(80):
        _, g, H = energy(chain, theta)
        step = np.einsum("nij,nj->ni", np.linalg.pinv(H), g)
        size = np.abs(step).max(axis=1, keepdims=True)
        theta = theta - step * np.minimum(1.0, 0.5 / np.maximum(size, 1e-300))
    _, g, _ = energy(chain, theta)
    found: list[np.ndarray] = []
    for t in np.mod(theta[np.abs(g).max(axis=1) < 1e-11], 2 * np.pi):
        if all(_torus_gap(t, f).max() > SAME for f in found):
            found.append(t)
    theta = np.array(sorted(found, key=tuple)).reshape(-1, len(chain.bodies))
    V, _, H = energy(chain, theta)
    c, a = chain.cable[:2]
    d = np.linalg.norm(c + _turned(theta, a).sum(axis=1), axis=1)
    return Critical(theta, V, np.linalg.eigvalsh(H), d)


def _torus_gap(a: np.ndarray, b: np.ndarray, period: float = 2 * np.pi) -> np.ndarray:
    d = np.abs(np.mod(a - b, period))
    return np.minimum(d, period - d)


def _pairing(found_deg: np.ndarray, ref_deg: np.ndarray) -> list[int]:
    """For each reference row the found row within MATCH_DEG on the torus, one to one."""
    assert found_deg.shape == ref_deg.shape, (found_deg, ref_deg)
    gaps = _torus_gap(ref_deg[:, None, :], found_deg[None, :, :], 360.0).max(axis=2)
    pick = gaps.argmin(axis=1)
    assert (gaps.min(axis=1) < MATCH_DEG).all(), gaps.min(axis=1)
    assert len(set(pick)) == len(pick)
    return [int(i) for i in pick]


@pytest.fixture(scope="module")
def reference() -> Critical:
    """The reference at the file's values."""
    return critical_points(read_chain())


def test_reference_is_complete_and_the_file_says_what_it_has(reference):
    chain = read_chain()
    # Every anchor is beyond its point's reach (|c| > sum |a|): no spring or cable reaches
    # zero length, so V is smooth but for the cable's switch and the Morse count applies.
    for c, a, *_ in chain.links:
        assert np.linalg.norm(c) > np.linalg.norm(a, axis=1).sum() + 0.05
    # Two different grids of starts find the same points.
    other = critical_points(chain, n=13, shift=0.1)
    _pairing(np.degrees(other.theta), np.degrees(reference.theta))
    assert np.abs(reference.eig).min() > 1e-3  # nondegenerate
    assert (np.abs(reference.cable_d - chain.cable[3]) > SWITCH_MARGIN).all()
    # Euler characteristic of the 3-torus: sum of (-1)^index over the critical points is 0.
    assert ((-1) ** reference.index).sum() == 0
    # A slack cable pulls nothing: at each point where it is slack, V without it is critical.
    taut = reference.cable_d > chain.cable[3]
    bare = Chain(chain.bodies, tuple(link for link in chain.links if not link[4]), chain.loads)
    assert np.abs(energy(bare, reference.theta[~taut])[1]).max() < 1e-9
    # The file's header: 22 equilibria, five stable: two with the cable taut, three slack.
    assert len(reference.theta) == 22
    stable = reference.index == 0
    assert ((stable & taut).sum(), (stable & ~taut).sum()) == (2, 3)
    assert taut.any() and (~taut & (reference.index > 0)).any()


def test_reference_derivatives_match_finite_differences():
    chain = read_chain()
    theta = np.random.default_rng(28).uniform(0, 2 * np.pi, (20, 3))
    _, g, H = energy(chain, theta)
    h = 1e-5
    for b in range(3):
        e = np.zeros(3)
        e[b] = h
        (vp, gp, _), (vm, gm, _) = energy(chain, theta + e), energy(chain, theta - e)
        np.testing.assert_allclose(g[:, b], (vp - vm) / (2 * h), atol=1e-7)
        np.testing.assert_allclose(H[:, :, b], (gp - gm) / (2 * h), atol=1e-7)


def test_reference_tells_a_perturbed_weight_apart(reference):
    # The comparison below would fail if the package solved a mechanism off by 1e-5 in one
    # number: the reference moves by far more than MATCH_DEG.
    moved = critical_points(read_chain(weight=0.1 + 1e-5))
    with pytest.raises(AssertionError):
        _pairing(np.degrees(moved.theta), np.degrees(reference.theta))


def _angles(table) -> np.ndarray:
    return table[[f"{b}.angle_deg" for b in read_chain().bodies]].to_numpy(dtype=float)


def test_chain3_equilibria_match_the_reference(reference):
    # The real route (issue 40): a few seconds, where the complex route never finished.
    res = cb.solve(cb.Framework.from_toml(FILE), route="real", cache=False)
    assert res.status == "ok", res.warnings
    phys = res.physical
    pick = _pairing(_angles(phys), np.degrees(reference.theta))
    rows = phys.iloc[pick]
    np.testing.assert_array_equal(rows["index"].to_numpy(dtype=int), reference.index)
    taut = reference.cable_d > read_chain().cable[3]
    np.testing.assert_array_equal(rows["cable.taut"].to_numpy(dtype=bool), taut)
    np.testing.assert_allclose(rows["cable.length"], reference.cable_d, rtol=0, atol=1e-8)
    minima = reference.theta[reference.index == 0]
    _pairing(_angles(res.stable), np.degrees(minima))
