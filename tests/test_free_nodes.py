"""Nodes held by springs and cables alone (boxsearch/free_nodes.py): their equilibria on the real
route, inside the proved bound, against a statics written here in numpy (no package code):
Newton on grad V from many random poses within twice the bound, each critical point with its
index; on random mechanisms nobody chose (anchors, stiffnesses, free lengths, loads anywhere;
one or two nodes; springs and cables), in the plane and in space."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import cotm_bertini as cb


def _random(rng: np.random.Generator, dim: int, nodes: int) -> tuple[str, dict]:
    """A random mechanism's file and its statics: every node linked to two or three ground
    points, consecutive nodes by a spring, a load on each."""
    axes = "xyz"[:dim]
    ground, links, loads = {}, [], []
    for i in range(nodes):
        for j in range(int(rng.integers(2, 4))):
            g = f"g{i}{j}"
            ground[g] = rng.uniform(-2, 2, dim).round(3)
            kind = "spring" if j == 0 else str(rng.choice(["spring", "cable"]))
            k, L0 = round(float(rng.uniform(0.5, 2)), 3), round(float(rng.uniform(0.2, 1.5)), 3)
            links.append((f"l{i}{j}", kind, f"N{i}", f"ground.{g}", k, L0))
        if i:
            L0 = round(float(rng.uniform(0.2, 1.0)), 3)
            links.append((f"n{i}", "spring", f"N{i - 1}", f"N{i}", 1.0, L0))
        loads.append((f"f{i}", f"N{i}", rng.uniform(-0.5, 0.5, dim).round(3)))
    text = [f'name = "free{dim}{nodes}"', f"dim = {dim}",
            "nodes = [" + ", ".join(f'"N{i}"' for i in range(nodes)) + "]", "[ground]"]  # fmt: skip
    text += [f"{g} = [{', '.join(repr(float(v)) for v in p)}]" for g, p in ground.items()]
    for name, kind, a, b, k, L0 in links:
        text += [f"[[{kind}s]]", f'name = "{name}"', f'a = "{a}"', f'b = "{b}"', f"k = {k}",
                 f"L0 = {L0}"]  # fmt: skip
    for name, point, f in loads:
        text += ["[[loads]]", f'name = "{name}"', f'point = "{point}"',
                 "force = [" + ", ".join(repr(float(v)) for v in f) + "]"]  # fmt: skip
    statics = {"dim": dim, "nodes": nodes, "ground": ground, "links": links,
               "loads": {p: f for _, p, f in loads}, "axes": axes}  # fmt: skip
    return "\n".join(text) + "\n", statics


def _where(st: dict, X: np.ndarray, p: str) -> np.ndarray:
    d = st["dim"]
    if p.startswith("ground."):
        return np.broadcast_to(st["ground"][p[7:]], X.shape[:1] + (d,))
    i = int(p[1:])
    return X[:, i * d : (i + 1) * d]


def _energy(st: dict, X: np.ndarray) -> np.ndarray:
    """V at poses X (R, nodes x dim)."""
    V = np.zeros(len(X))
    for _, kind, a, b, k, L0 in st["links"]:
        d = np.linalg.norm(_where(st, X, a) - _where(st, X, b), axis=1)
        s = d - L0 if kind == "spring" else np.maximum(d - L0, 0.0)
        V += 0.5 * k * s * s
    for p, f in st["loads"].items():
        V -= _where(st, X, p) @ f
    return V


def _derivatives(st: dict, X: np.ndarray, h: float = 1e-5) -> tuple[np.ndarray, np.ndarray]:
    """grad V (central differences of the energy) and its Hessian (of the gradient)."""

    def grad(Y):
        n = Y.shape[1]
        E = np.eye(n) * h
        return np.stack([(_energy(st, Y + E[j]) - _energy(st, Y - E[j])) / (2 * h)
                         for j in range(n)], axis=1)  # fmt: skip

    n = X.shape[1]
    E = np.eye(n) * h
    H = np.stack([(grad(X + E[j]) - grad(X - E[j])) / (2 * h) for j in range(n)], axis=2)
    return grad(X), 0.5 * (H + H.transpose(0, 2, 1))


def _critical_points(st: dict, bound: float, starts: int = 1500, seed: int = 0) -> list:
    """Newton on the statics from random poses: (pose, index) of each critical point found,
    where V is smooth (every link longer than 1e-6)."""
    rng = np.random.default_rng(seed)
    n = st["dim"] * st["nodes"]
    X = rng.uniform(-2 * bound, 2 * bound, (starts, n))
    for _ in range(60):
        g, H = _derivatives(st, X)
        with np.errstate(all="ignore"):
            try:
                dx = np.linalg.solve(H, g[..., None])[..., 0]
            except np.linalg.LinAlgError:
                dx = np.einsum("nij,nj->ni", np.linalg.pinv(H), g)
        dx = dx * np.minimum(1.0, 0.5 / np.maximum(np.abs(dx).max(axis=1), 1e-300))[:, None]
        X = np.where(np.isfinite(dx), X - dx, X)
    g, H = _derivatives(st, X, 1e-4)
    ok = np.abs(g).max(axis=1) < 1e-7
    found: list = []
    for x, hh in zip(X[ok], H[ok], strict=True):
        if all(np.abs(x - y).max() > 1e-5 for y, _ in found):
            found.append((x, int((np.linalg.eigvalsh(hh) < 0).sum())))
    return found


def _rows(res, st: dict) -> list:
    cols = [f"N{i}.{a}" for i in range(st["nodes"]) for a in st["axes"]]
    return [(r[cols].to_numpy(float), int(r["index"])) for _, r in res.physical.iterrows()]


@pytest.mark.parametrize("dim, nodes, seed", [(2, 1, 0), (2, 1, 1), (2, 2, 2), (2, 2, 3),
                                              (3, 1, 4), (3, 1, 5)])  # fmt: skip
def test_free_nodes_equilibria_are_the_statics(dim, nodes, seed, tmp_path):
    """Every critical point Newton finds on the statics is a row, with its index; every row is
    a critical point of the statics; the search proved its box and the Morse sum (chi 1 on
    the product of balls) holds."""
    text, st = _random(np.random.default_rng(seed), dim, nodes)
    path = tmp_path / "free.toml"
    path.write_text(text)
    res = cb.solve(cb.Framework.from_toml(path), cache=False)
    assert res.status == "ok", res.warnings
    assert "real_search" in res.record["details"]
    rows = _rows(res, st)
    for x, index in rows:
        g, H = _derivatives(st, x[None])
        assert np.abs(g).max() < 1e-6 and int((np.linalg.eigvalsh(H[0]) < 0).sum()) == index
    bound = max(float(np.abs(np.vstack([x for x, _ in rows] or [np.zeros(dim)])).max()), 3.0)
    for x, index in _critical_points(st, bound):
        match = [i for y, i in rows if np.abs(x - y).max() < 1e-5]
        assert match == [index], (x, index, rows)
    assert res.morse["applicable"] is False or res.morse["ok"], res.morse


@pytest.mark.slow
def test_a_pair_of_free_nodes_in_space_is_its_statics():
    """tests/fixtures/free_pair.toml (R^3 x R^3, a spring between the nodes, two cables): its two
    equilibria and one cone point, proved; the Morse sum 1."""
    res = cb.solve(cb.Framework.from_toml(ROOT / "tests" / "fixtures" / "free_pair.toml"),
                   cache=False)  # fmt: skip
    assert res.status == "ok" and res.morse["ok"] and len(res.physical) == 2


def test_a_node_that_could_float_is_refused_on_the_real_route(tmp_path):
    """A node on cables alone with no load floats over a region of equilibria (all slack), which
    the search would run down to its smallest boxes: the real route refuses it in one line."""
    path = tmp_path / "float.toml"
    path.write_text('name = "float"\ndim = 2\nnodes = ["N"]\n[ground]\na = [0.0, 0.0]\n'
                    'b = [1.0, 0.0]\n[[cables]]\nname = "ca"\na = "N"\nb = "ground.a"\nk = 1.0\n'
                    'L0 = 1.0\n[[cables]]\nname = "cb"\na = "N"\nb = "ground.b"\nk = 1.0\n'
                    "L0 = 1.0\n")  # fmt: skip
    with pytest.raises(cb.ParameterError, match="node N has no load and 2 link.*float"):
        cb.solve(cb.Framework.from_toml(path), route="real")


def test_a_node_in_the_plane_on_both_routes_agrees(tmp_path):
    """A node on a spring of zero free length and two cables in series (tests/test_prune.py's
    mechanism, with a load): the real route's rows are the complex route's, to 1e-9."""
    from test_prune import SERIES

    path = tmp_path / "series.toml"
    path.write_text(SERIES + '\n[[loads]]\nname = "w"\npoint = "N"\nforce = [0.4, -0.3]\n')
    fw = cb.Framework.from_toml(path)
    real, cplx = cb.solve(fw, cache=False), cb.solve(fw, cache=False, route="complex")
    assert "real_search" in real.record["details"] and real.status == cplx.status == "ok"
    cols = ["N.x", "N.y"]
    a = real.physical.sort_values(cols)[cols].to_numpy(float)
    b = cplx.physical.sort_values(cols)[cols].to_numpy(float)
    assert a.shape == b.shape and np.allclose(a, b, atol=1e-9)
    assert list(real.physical["kind"]) == list(cplx.physical["kind"])
