"""Random mechanisms of each kind the real route covers, written twice: as a framework file for
the package, and as plain numpy statics here (no package code) whose critical points Newton
finds from thousands of random starts. Nobody chose them to be easy: anchors anywhere, cables
whose free lengths lie inside their range of lengths (so they go slack and taut), loads in every
direction, springs of zero and of non-zero free length.

- `planar_chain`: links pinned in series from the ground (a torus of absolute link angles);
  springs and cables from link points to ground anchors beyond their reach (no spring can
  collapse), a load on every link's end.
- `hanging_nodes`: nodes hanging by bars from the ground or from a node hung before them (a
  product of spheres), cables between nodes and to the ground, a load on every node
  (so no node is free to float where its cables are slack).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import tensegrity_physics as tp


def _num(x: float) -> str:
    return repr(float(x))


def _vec(v) -> str:
    return "[" + ", ".join(_num(c) for c in v) + "]"


# --- planar chains (tori) ---------------------------------------------------------------------


@dataclass(frozen=True)
class Chain:
    """Links pinned in series (link i's origin at link i-1's end; link 1's at the ground's
    origin), each with an end `length` along its own x axis and a point `mid` in its frame;
    elements (kind, name, (link, point), anchor, k, L0) with kind spring / cable / zfl;
    loads (link, force) at each link's end."""

    lengths: tuple
    mids: tuple
    elements: tuple
    loads: tuple

    def points(self, th: np.ndarray) -> dict:
        """(s, 2) positions of every link point ('o', 'e', 'm' per link) for angles th (s, n)."""
        out, base = {}, np.zeros((len(th), 2))
        for i, (L, m) in enumerate(zip(self.lengths, self.mids, strict=True)):
            c, s = np.cos(th[:, i]), np.sin(th[:, i])
            rot = lambda v, c=c, s=s: np.stack([c * v[0] - s * v[1], s * v[0] + c * v[1]], 1)  # noqa: E731
            out[i, "o"], out[i, "e"], out[i, "m"] = base, base + rot((L, 0.0)), base + rot(m)
            base = out[i, "e"]
        return out

    def energy(self, th: np.ndarray) -> np.ndarray:
        """V of every pose: springs, taut cables, zero-free-length springs, minus the loads'
        work."""
        P, V = self.points(th), np.zeros(len(th))
        for kind, _, at, anchor, k, L0 in self.elements:
            d = np.linalg.norm(P[at] - np.asarray(anchor), axis=1)
            stretch = np.maximum(d - L0, 0.0) if kind == "cable" else d - L0
            V += 0.5 * k * stretch**2
        for i, f in self.loads:
            V -= P[i, "e"] @ np.asarray(f)
        return V

    def gradient(self, th: np.ndarray) -> np.ndarray:
        """grad V (s, n) in the absolute link angles: turning link j about its origin o_j moves
        its own point p by J (p - o_j) and every later link's points by J (e_j - o_j), J the
        quarter turn."""
        P, G = self.points(th), np.zeros_like(th)
        forces = []  # (link, point, force (s, 2)): minus the gradient in the point's position
        for kind, _, at, anchor, k, L0 in self.elements:
            r = P[at] - np.asarray(anchor)
            d = np.linalg.norm(r, axis=1)
            with np.errstate(divide="ignore", invalid="ignore"):  # at a cone: Newton stops
                w = k * (1 - L0 / d)
            if kind == "cable":
                w = np.where(d > L0, w, 0.0)
            forces.append((at, -w[:, None] * r))
        forces += [((i, "e"), np.broadcast_to(np.asarray(f, float), th[:, :2].shape))
                   for i, f in self.loads]  # fmt: skip
        for (i, name), F in forces:
            for j in range(i + 1):  # link j turns its own points, and moves its end's followers
                arm = (P[i, name] if j == i else P[j, "e"]) - P[j, "o"]
                G[:, j] -= arm[:, 0] * F[:, 1] - arm[:, 1] * F[:, 0]
        return G

    def hessian(self, th: np.ndarray, h: float = 1e-5) -> np.ndarray:
        """The Hessian by central differences of the exact gradient (for Newton's steps and
        the Morse index only: the roots are those of the exact gradient)."""
        n = th.shape[1]
        cols = [
            (self.gradient(th + h * e) - self.gradient(th - h * e)) / (2 * h) for e in np.eye(n)
        ]
        H = np.stack(cols, axis=2)
        return 0.5 * (H + np.swapaxes(H, 1, 2))

    def toml(self, name: str) -> str:
        """The framework file."""
        lines = [f'name = "{name}"', "dim = 2", "", "[ground]", "o = [0.0, 0.0]"]
        for j, (*_, anchor, _, _) in enumerate(self.elements):
            lines.append(f"g{j} = {_vec(anchor)}")
        for i, (L, m) in enumerate(zip(self.lengths, self.mids, strict=True)):
            lines += ["", f"[bodies.link{i + 1}]", "o = [0.0, 0.0]", f"e = {_vec((L, 0.0))}",
                      f"m = {_vec(m)}"]  # fmt: skip
        for i in range(len(self.lengths)):
            b = "ground.o" if i == 0 else f"link{i}.e"
            lines += ["", "[[pins]]", f'a = "link{i + 1}.o"', f'b = "{b}"']
        for j, (kind, nm, (i, pt), _, k, L0) in enumerate(self.elements):
            table = "cables" if kind == "cable" else "springs"
            lines += ["", f"[[{table}]]", f'name = "{nm}"', f'a = "link{i + 1}.{pt}"',
                      f'b = "ground.g{j}"', f"k = {_num(k)}", f"L0 = {_num(L0)}"]  # fmt: skip
        for i, f in self.loads:
            lines += ["", "[[loads]]", f'name = "w{i + 1}"', f'point = "link{i + 1}.e"',
                      f"force = {_vec(f)}"]  # fmt: skip
        return "\n".join(lines) + "\n"


def planar_chain(seed: int, links: int = 2, collapse: bool = False) -> Chain:
    """A random chain of `links` links with three to five elements and a load on every end;
    with `collapse`, the springs' anchors lie within their points' reach (the springs may
    shrink to zero length: V has cone sets)."""
    rng = np.random.default_rng(seed)
    lengths = tuple(rng.uniform(0.6, 1.2, links))
    mids = tuple((rng.uniform(0.2, 0.8) * L, rng.uniform(-0.3, 0.3)) for L in lengths)
    reach = np.cumsum(lengths)
    elements = []
    kinds = ["spring", "cable", "zfl"] + list(rng.choice(["spring", "cable", "zfl"], 2))
    for j, kind in enumerate(kinds[: rng.integers(3, 6)]):
        i = int(rng.integers(links)) if j else links - 1
        pt = str(rng.choice(["e", "m"]))
        far = reach[i] + rng.uniform(0.3, 1.5)  # beyond the point's reach: never length 0
        if collapse and kind == "spring":
            far = rng.uniform(0.1, 0.9) * reach[i]
        a = rng.uniform(0, 2 * np.pi)
        anchor = (far * np.cos(a), far * np.sin(a))
        lo, hi = max(far - reach[i], 0.05), far + reach[i]
        L0 = 0.0 if kind == "zfl" else rng.uniform(lo, 0.5 * (lo + hi) if kind == "spring" else hi)
        elements.append((kind, f"{kind}{j}", (i, pt), anchor, rng.uniform(0.5, 1.5), L0))
    loads = tuple((i, tuple(rng.normal(0, 0.3, 2))) for i in range(links))
    return Chain(lengths, mids, tuple(elements), loads)


def chain_critical_points(ch: Chain, starts: int = 3000, seed: int = 1) -> list[dict]:
    """Distinct critical points (angles modulo 2 pi, to 1e-7) Newton reaches from random
    starts: dicts (angles, index, energy), each with |grad V| below 1e-10."""
    rng = np.random.default_rng(seed)
    th = rng.uniform(0, 2 * np.pi, (starts, len(ch.lengths)))
    for _ in range(60):
        step = np.linalg.solve(ch.hessian(th), ch.gradient(th)[..., None])[..., 0]
        step *= np.minimum(1.0, 0.5 / np.maximum(np.abs(step).max(axis=1), 1e-300))[:, None]
        th = th - step
    th = np.mod(th, 2 * np.pi)
    good = np.abs(ch.gradient(th)).max(axis=1) < 1e-10
    found: list[dict] = []
    for x in th[good]:
        if any(np.abs((x - p["angles"] + np.pi) % (2 * np.pi) - np.pi).max() < 1e-7 for p in found):
            continue
        ev = np.linalg.eigvalsh(ch.hessian(x[None])[0])
        found.append({"angles": x, "index": int((ev < 0).sum()),
                      "degenerate": bool(np.abs(ev).min() < 1e-7),
                      "energy": float(ch.energy(x[None])[0])})  # fmt: skip
    return found


def chain_cone_points(ch: Chain, starts: int = 3000, seed: int = 1) -> list[dict]:
    """The cone points of each spring with a free length: poses where its length is 0 and
    A = J^T lambda with |lambda| < k L0 (A: grad V with that spring's -k L0 d term taken out,
    i.e. the spring at zero free length; J: d(its vector)/dangle by central differences), by
    Newton on (angles, lambda) from random starts. Dicts (spring, angles, pull, push, index:
    2 plus the negative eigenvalues of the Lagrangian's Hessian along the cone set)."""
    rng = np.random.default_rng(seed)
    n, out = len(ch.lengths), []
    for e, (kind, name, at, anchor, k, L0) in enumerate(ch.elements):
        if kind != "spring" or L0 == 0:
            continue
        zfl = Chain(ch.lengths, ch.mids, ch.elements[:e] + (("zfl", name, at, anchor, k, 0.0),)
                    + ch.elements[e + 1 :], ch.loads)  # fmt: skip
        r = lambda th, at=at, anchor=anchor: ch.points(th)[at] - np.asarray(anchor)  # noqa: E731
        jac = lambda th, r=r: np.stack([(r(th + 1e-6 * v) - r(th - 1e-6 * v)) / 2e-6  # noqa: E731
                                        for v in np.eye(n)], axis=2)  # fmt: skip
        lag = lambda y, zfl=zfl, r=r, jac=jac: np.hstack([  # noqa: E731
            zfl.gradient(y[:, :n]) - np.einsum("bcj,bc->bj", jac(y[:, :n]), y[:, n:]),
            r(y[:, :n])])  # fmt: skip
        y = np.hstack([rng.uniform(0, 2 * np.pi, (starts, n)), rng.normal(0, k * L0, (starts, 2))])
        for _ in range(40):
            with np.errstate(all="ignore"):
                D = np.stack([lag(y + 1e-6 * v) - lag(y - 1e-6 * v) for v in np.eye(n + 2)], 2)
                D /= 2e-6
            F = lag(y)
            bad = ~(np.isfinite(D).all(axis=(1, 2)) & np.isfinite(F).all(axis=1))
            D[bad], F[bad] = np.eye(n + 2), 0.0  # at another spring's cone: that start stops
            step = np.einsum("bij,bj->bi", np.linalg.pinv(D), F)
            y = y - np.nan_to_num(np.clip(step, -0.5, 0.5))
        with np.errstate(all="ignore"):
            good = np.abs(lag(y)).max(axis=1) < 1e-9
        for x in y[good]:
            x = x.copy()
            x[:n] = np.mod(x[:n], 2 * np.pi)
            pull = float(np.hypot(*x[n:]))
            if pull >= k * L0 or any(
                np.abs((x[:n] - p["angles"] + np.pi) % (2 * np.pi) - np.pi).max() < 1e-7
                for p in out if p["spring"] == name):  # fmt: skip
                continue
            J = jac(x[None, :n])[0]
            H = np.stack([(lag(x[None] + 1e-5 * v)[0, :n] - lag(x[None] - 1e-5 * v)[0, :n]) / 2e-5
                          for v in np.eye(n + 2)[:n]], axis=1)  # fmt: skip
            N = np.linalg.svd(J)[2][2:]
            ev = np.linalg.eigvalsh(N @ (0.5 * (H + H.T)) @ N.T) if n > 2 else np.zeros(0)
            out.append({"spring": name, "angles": x[:n], "pull": pull, "push": k * L0,
                        "index": 2 + int((ev < 0).sum())})  # fmt: skip
    return out


# --- nodes hanging by bars (products of spheres) ----------------------------------------------


@dataclass(frozen=True)
class Hanging:
    """A tensegrity_physics.Spatial (with its loads), and its file."""

    spatial: tp.Spatial

    def toml(self, name: str) -> str:
        """The framework file."""
        sp = self.spatial
        lines = [f'name = "{name}"', "dim = 3", f"nodes = {_names(sp.free)}", "", "[ground]"]
        lines += [f"{g} = {_vec(p)}" for g, p in sp.anchors.items()]
        ref = lambda p: f"ground.{p}" if p in sp.anchors else p  # noqa: E731
        for j, (a, b, length) in enumerate(sp.bars):
            lines += ["", "[[bars]]", f'name = "bar{j}"', f'a = "{ref(a)}"', f'b = "{ref(b)}"',
                      f"length = {_num(length)}"]  # fmt: skip
        for nm, a, b, k, L0 in sp.cables:
            lines += ["", "[[cables]]", f'name = "{nm}"', f'a = "{ref(a)}"', f'b = "{ref(b)}"',
                      f"k = {_num(k)}", f"L0 = {_num(L0)}"]  # fmt: skip
        for node, f in sp.loads:
            lines += ["", "[[loads]]", f'name = "w{node}"', f'point = "{node}"',
                      f"force = {_vec(f)}"]  # fmt: skip
        return "\n".join(lines) + "\n"


def _names(items) -> str:
    return "[" + ", ".join(f'"{x}"' for x in items) + "]"


def hanging_nodes(seed: int, nodes: int = 2) -> Hanging:
    """Random nodes hanging by bars (the first from the ground, each later one from the ground
    or from the node before it), three to five cables, a load on every node."""
    rng = np.random.default_rng(seed)
    anchors = {}
    for j in range(4):
        a = 2 * np.pi * j / 4 + rng.uniform(-0.4, 0.4)
        anchors[f"g{j}"] = (np.cos(a) * rng.uniform(0.8, 1.2), np.sin(a) * rng.uniform(0.8, 1.2),
                            rng.uniform(-0.2, 0.2))  # fmt: skip
    free = tuple("ABCD"[:nodes])
    bars = []
    for i, v in enumerate(free):
        top = f"g{i}" if i == 0 or rng.random() < 0.6 else free[i - 1]
        bars.append((top, v, rng.uniform(0.8, 1.3)))
    cables, pairs = [], [(v, g) for v in free for g in anchors] + [
        (a, b) for i, a in enumerate(free) for b in free[i + 1 :]]  # fmt: skip
    picks = rng.choice(len(pairs), size=min(len(pairs), 3 + nodes), replace=False)
    for j, p in enumerate(picks):
        a, b = pairs[p]
        cables.append((f"c{j}", a, b, rng.uniform(0.5, 1.5), rng.uniform(0.3, 1.6)))
    loads = tuple((v, tuple(rng.normal(0, 0.25, 3))) for v in free)
    return Hanging(tp.Spatial(anchors, free, tuple(bars), tuple(cables), loads=loads))
