"""Events of a framework sweep named by what happens (issue 39, item 3): a cable reaching its free
length is a cable_switch located where its length equals L0, not a fold; three branches meeting
is a pitchfork. Each value is checked against an energy written here with plain numpy."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import cotm_bertini as cb
from cotm_bertini.cli.main import main

SWITCH = "tests/fixtures/wheel_cable_switch.toml"
PITCHFORK = "tests/fixtures/wheel_pitchfork.toml"
S, Q, K_SPRING = np.array([2.0, 0.0]), np.array([-1.3, -1.7]), 1.0  # as in SWITCH
LEFT, RIGHT = np.array([-0.5, 3.0]), np.array([0.5, 3.0])  # as in PITCHFORK


def _roots(f, lo: float, hi: float, n: int = 20_000) -> list[float]:
    """Every sign change of f on [lo, hi] (a dense grid), each bisected to 1e-15."""
    x = np.linspace(lo, hi, n)
    y = f(x)
    out = []
    for k in np.flatnonzero(np.sign(y[:-1]) != np.sign(y[1:])):
        a, b = x[k], x[k + 1]
        for _ in range(200):
            m = 0.5 * (a + b)
            a, b = (
                (m, b) if np.sign(f(np.array([m]))[0]) == np.sign(f(np.array([a]))[0]) else (a, m)
            )
        out.append(0.5 * (a + b))
    return out


def _rim(theta, start):
    """The rim point: `start` rotated by theta about the origin, (2, n)."""
    c, s = np.cos(theta), np.sin(theta)
    return np.stack([c * start[0] - s * start[1], s * start[0] + c * start[1]])


def _switch_values() -> list[tuple[float, float]]:
    """(cable length, d2V/dtheta2) at each equilibrium of the wheel with the cable slack (the
    spring alone), by a dense scan of dV/dtheta bisected: where the cable reaches its free
    length there, L0c = that length, the slack branch ends."""

    def v_spring(t):
        r = _rim(t, (1.0, 0.0))
        return 0.5 * K_SPRING * ((r - S[:, None]) ** 2).sum(axis=0)

    def dv(t):  # (rim - s) . d rim / d theta, written out: no finite-difference error
        r = _rim(t, (1.0, 0.0))
        return K_SPRING * ((r - S[:, None]) * np.stack([-r[1], r[0]])).sum(axis=0)

    out = []
    for t in _roots(dv, 0.1, 2 * np.pi + 0.1):
        d2 = (v_spring(np.array([t + 1e-4])) - 2 * v_spring(np.array([t]))
              + v_spring(np.array([t - 1e-4])))[0] / 1e-8  # fmt: skip
        out.append((float(np.linalg.norm(_rim(np.array([t]), (1.0, 0.0))[:, 0] - Q)), d2))
    return out


def test_a_cable_reaching_its_free_length_is_a_cable_switch_not_a_fold(tmp_path):
    """The sweep command's events.csv: where the spring's maximum (cable slack) has the cable
    exactly at its free length, a minimum with the cable taut is born with it (a stable state:
    the Hessian there far from singular): a cable_switch, at that length to 1e-12."""
    code = main(["sweep", "--framework", SWITCH, "--param", "L0c", "--from", "1.5", "--to",
                 "2.0", "--points", "11", "--workers", "1", "--quiet", "--no-plots",
                 "--out", str(tmp_path)])  # fmt: skip
    assert code == 0
    events = pd.read_csv(next(tmp_path.glob("sweep-*")) / "events.csv")
    # The independent reference: the slack equilibria (the spring's max and min), one in range.
    expected = [d for d, d2 in _switch_values() if 1.5 < d < 2.0]
    assert len(expected) == 1 and abs(expected[0] - np.sqrt(2.98)) < 1e-9  # |(-1, 0) - q|
    assert "fold" not in set(events["kind"])
    switch = events[events["kind"] == "cable_switch"]
    assert len(switch) == 1
    row = switch.iloc[0]
    assert abs(row["L0c"] - expected[0]) < 1e-12
    assert row["refined"] and row["bracket"] < 1e-9
    assert abs(row["wheel.angle_deg"] - 180.0) < 1e-6  # the slack maximum: the rim at (-1, 0)
    assert row["hess_min_eig"] > 0.05  # not singular: no fold
    assert "band" in row["description"]
    change = events[events["kind"] == "stability_change"]
    assert len(change) == 1 and abs(change.iloc[0]["L0c"] - expected[0]) < 1e-12
    assert _minima_switch(expected[0] - 0.01) + 1 == _minima_switch(expected[0] + 0.01)


def _minima_switch(L0c: float, n: int = 200_000) -> int:
    """Local minima of the wheel's piecewise energy (spring + tension-only cable) on a grid."""
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    r = _rim(t, (1.0, 0.0))
    d = np.linalg.norm(r - Q[:, None], axis=0)
    v = 0.5 * K_SPRING * ((r - S[:, None]) ** 2).sum(axis=0) + 2.5 * np.maximum(d - L0c, 0) ** 2
    return int(((v < np.roll(v, 1)) & (v < np.roll(v, -1))).sum())


def _pitchfork_energy(theta: np.ndarray, L0: float) -> np.ndarray:
    """V of the wheel between two equal springs (k = 1), the rim (0, 1) turned by theta."""
    r = _rim(theta, (0.0, 1.0))
    return sum(0.5 * (np.linalg.norm(r - g[:, None], axis=0) - L0) ** 2 for g in (LEFT, RIGHT))


def _pitchfork_value() -> float:
    """Where d2V/dtheta2 of the symmetric pose (rim straight up) vanishes, by bisection on L0."""
    h = 1e-4
    zero = np.zeros(1)

    def stiffness(L0s: np.ndarray) -> np.ndarray:
        return np.array([(_pitchfork_energy(zero + h, L) - 2 * _pitchfork_energy(zero, L)
                          + _pitchfork_energy(zero - h, L))[0] / h**2 for L in L0s])  # fmt: skip

    (value,) = _roots(stiffness, 1.9, 2.3, 401)
    return value


@pytest.fixture(scope="module")
def pitchfork_sweep(tmp_path_factory):
    fw = cb.Framework.from_toml(PITCHFORK)
    return cb.sweep(fw, "L0", [2.0, 2.1, 2.2], out=tmp_path_factory.mktemp("pitchfork"))


def test_three_branches_meeting_are_a_pitchfork(pitchfork_sweep):
    """Rim up: a minimum for short springs, a maximum for long ones (they push); where it turns,
    two mirror-image minima branch off it. A pitchfork there, named so, not a fold."""
    events = pitchfork_sweep.events
    value = _pitchfork_value()
    # The closed form: springs to (+-b, c), d0 = |(0, 1) - (b, c)|; V''(0) = 2 [d'^2 +
    # (d0 - L0) d''] with d' = b / d0, d'' = (c - b^2 / d0^2) / d0, zero at this L0.
    b, c = RIGHT
    d0 = np.hypot(b, c - 1.0)
    closed = d0 + b**2 / (d0 * c - b**2 / d0)
    assert abs(value - closed) < 1e-7  # the finite differences' error: O(h^2)
    value = closed
    assert "fold" not in set(events["kind"])
    fork = events[events["kind"] == "pitchfork"]
    assert len(fork) == 1
    row = fork.iloc[0]
    assert abs(row["L0"] - value) < 1e-7
    assert len(row["branches"].split("+")) == 3
    assert "a min and a min branch off" in row["description"]
    assert "a max on their side and a min on the other" in row["description"]
    assert min(row["wheel.angle_deg"], 360 - row["wheel.angle_deg"]) < 1e-4  # rim up
    t = np.linspace(-np.pi, np.pi, 100_001)
    below, above = (_pitchfork_energy(t, value + s) for s in (-1e-3, 1e-3))
    count = lambda v: int(((v < np.roll(v, 1)) & (v < np.roll(v, -1))).sum())  # noqa: E731
    assert (count(below), count(above)) == (1, 2)  # one minimum below, two above
