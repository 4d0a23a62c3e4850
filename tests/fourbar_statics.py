"""A four-bar's statics in plain numpy (no package code): the loop's poses in closed form on
both assembly branches (the rocker's and coupler's joint where two circles cross), V along each
branch as a function of the crank angle, and the TOML file of the same mechanism. For a Grashof
crank-rocker (the crank shortest, s + l <= p + q) every crank angle assembles on both branches,
and each branch is a circle in the crank angle."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class FourBar:
    """Ground pivots A (crank) and D (rocker), link lengths, the coupler's point p (in the
    coupler's frame: B at 0, C on its x axis), the rocker's point q (along the rocker), and the
    links: (name, kind 'spring' or 'cable', where 'crank'|'coupler'|'rocker', anchor, k, L0)."""

    A: tuple
    D: tuple
    crank: float
    coupler: float
    rocker: float
    p: tuple
    q: float
    links: tuple

    def points(self, theta: np.ndarray, branch: int) -> dict[str, np.ndarray]:
        """B, C, the coupler's point and the rocker's point (2 x n) at crank angles theta."""
        A, D = np.array(self.A)[:, None], np.array(self.D)[:, None]
        B = A + self.crank * np.stack([np.cos(theta), np.sin(theta)])
        gap = D - B
        dist = np.hypot(*gap)
        along = (self.coupler**2 - self.rocker**2 + dist**2) / (2 * dist)
        across = np.sqrt(np.maximum(self.coupler**2 - along**2, 0.0))
        unit = gap / dist
        normal = np.stack([-unit[1], unit[0]])
        C = B + along * unit + branch * across * normal
        u = (C - B) / self.coupler
        P = B + self.p[0] * u + self.p[1] * np.stack([-u[1], u[0]])
        Q = D + self.q * (C - D) / self.rocker
        return {"crank": B, "coupler": P, "rocker": Q, "C": C}

    def energy(self, theta, branch: int):
        """V on one assembly branch (+1 or -1) at crank angle theta."""
        scalar = np.ndim(theta) == 0
        pts = self.points(np.atleast_1d(np.asarray(theta, float)), branch)
        V = 0.0
        for _, kind, where, anchor, k, L0 in self.links:
            d = np.hypot(*(pts[where] - np.array(anchor)[:, None]))
            stretch = d - L0 if kind == "spring" else np.maximum(d - L0, 0.0)
            V = V + 0.5 * k * stretch**2
        return V[0] if scalar else V

    def branch_of(self, crank_deg: float, coupler_deg: float) -> int:
        """The assembly branch of a pose: the side of the line B -> D the joint C lies on."""
        t, f = np.radians(crank_deg), np.radians(coupler_deg)
        B = np.array(self.A) + self.crank * np.array([np.cos(t), np.sin(t)])
        C = B + self.coupler * np.array([np.cos(f), np.sin(f)])
        gap = np.array(self.D) - B
        return 1 if gap[0] * (C - B)[1] - gap[1] * (C - B)[0] > 0 else -1

    def toml(self, name: str) -> str:
        """The mechanism as a framework file."""
        r = lambda v: repr(float(v))  # noqa: E731
        out = [
            f'name = "{name}"',
            "dim = 2",
            "",
            "[ground]",
            f"A = [{r(self.A[0])}, {r(self.A[1])}]",
            f"D = [{r(self.D[0])}, {r(self.D[1])}]",
        ]
        out += [f"G{i} = [{r(a[0])}, {r(a[1])}]" for i, (*_, a, _k, _L) in enumerate(self.links)]
        out += ["", "[bodies.crank]", "a = [0.0, 0.0]", f"b = [{r(self.crank)}, 0.0]", "",
                "[bodies.coupler]", "b = [0.0, 0.0]", f"c = [{r(self.coupler)}, 0.0]",
                f"p = [{r(self.p[0])}, {r(self.p[1])}]", "", "[bodies.rocker]", "d = [0.0, 0.0]",
                f"c = [{r(self.rocker)}, 0.0]", f"q = [{r(self.q)}, 0.0]"]  # fmt: skip
        for a, b in (("crank.a", "ground.A"), ("coupler.b", "crank.b"), ("rocker.d", "ground.D"),
                     ("rocker.c", "coupler.c")):  # fmt: skip
            out += ["", "[[pins]]", f'a = "{a}"', f'b = "{b}"']
        point = {"crank": "crank.b", "coupler": "coupler.p", "rocker": "rocker.q"}
        for i, (name_, kind, where, _, k, L0) in enumerate(self.links):
            out += ["", f"[[{kind}s]]", f'name = "{name_}"', f'a = "{point[where]}"',
                    f'b = "ground.G{i}"', f"k = {r(k)}", f"L0 = {r(L0)}"]  # fmt: skip
        return "\n".join(out) + "\n"


def random_crank_rocker(rng: np.random.Generator) -> FourBar:
    """A Grashof crank-rocker with random lengths, coupler point, and a spring on the crank, a
    spring or cable on the coupler's point and on the rocker's, anchors anywhere near it."""
    while True:
        crank = rng.uniform(0.3, 0.9)
        coupler, rocker = rng.uniform(1.2, 2.6, 2)
        ground = 2.0
        lengths = sorted([crank, coupler, rocker, ground])
        if lengths[0] == crank and lengths[0] + lengths[3] < lengths[1] + lengths[2] - 0.05:
            break
    kinds = ["spring", rng.choice(["spring", "cable"]), rng.choice(["spring", "cable"])]
    links = tuple(
        (f"l{i}", str(kind), where, tuple(np.round(rng.uniform([-2, -2], [4, 3]), 3)),
         float(np.round(rng.uniform(0.5, 2.0), 3)), float(np.round(rng.uniform(0.2, 1.5), 3)))
        for i, (kind, where) in enumerate(zip(kinds, ("crank", "coupler", "rocker"), strict=True))
    )  # fmt: skip
    return FourBar((0.0, 0.0), (ground, 0.0), round(crank, 3), round(coupler, 3), round(rocker, 3),
                   tuple(np.round(rng.uniform([0.2, -0.8], [1.5, 0.8]), 3)),
                   round(rocker * rng.uniform(0.3, 1.0), 3), links)  # fmt: skip
