"""A spatial rigid body on a ball joint (issue 39, item 1): each pose is the quaternion q and -q,
reached by paths of their own, and the table must list it once. tests/fixtures/tee_mast.toml (a
T-shaped mast, two crossbar springs of zero free length, a tip spring with a free length, a tip
load) against a reference that shares no code with the package: V(R) on SO(3) written here in
plain numpy from the file (read with tomllib), its critical points found by Newton in the
rotation's tangent space (R <- R exp([w]x)) from random rotations and deduplicated as rotation
matrices, each classified by the eigenvalues of its Hessian in those coordinates."""

from __future__ import annotations

import json
import tomllib
from functools import cache

import numpy as np
import pytest
from conftest import ROOT, run_cli

import cotm_bertini as cb

FIXTURE = ROOT / "tests" / "fixtures" / "tee_mast.toml"
SAME = 1e-6  # two rotations closer than this (max entry) are one
STARTS = 1500


def _rotation(q: np.ndarray) -> np.ndarray:
    """Rotation matrices (n, 3, 3) of quaternions (n, 4) (w, x, y, z), normalised first."""
    w, x, y, z = (q / np.linalg.norm(q, axis=1, keepdims=True)).T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)  # fmt: skip


def _hat(w: np.ndarray) -> np.ndarray:
    """[w]x (n, 3, 3): [w]x v = w x v."""
    z = np.zeros(len(w))
    return np.stack([
        np.stack([z, -w[:, 2], w[:, 1]], -1),
        np.stack([w[:, 2], z, -w[:, 0]], -1),
        np.stack([-w[:, 1], w[:, 0], z], -1),
    ], -2)  # fmt: skip


def _exp(w: np.ndarray) -> np.ndarray:
    """exp([w]x) by Rodrigues' formula (n, 3, 3)."""
    t = np.linalg.norm(w, axis=1)[:, None, None]
    K = _hat(w)
    small = t < 1e-12
    a = np.where(small, 1.0, np.sin(t) / np.where(small, 1.0, t))
    b = np.where(small, 0.5, (1 - np.cos(t)) / np.where(small, 1.0, t) ** 2)
    return np.eye(3) + a * K + b * K @ K


@cache
def _mast(fx: float | None = None) -> dict:
    """The fixture's elements as numbers: springs (body point, ground point, k, L0), the load
    (with `fx`, that parameter set to it)."""
    data = tomllib.loads(FIXTURE.read_text())
    p = {**data["parameters"], **({} if fx is None else {"fx": fx})}

    def num(v):
        return float(p[v]) if isinstance(v, str) else float(v)

    ground = {n: np.array(v, float) for n, v in data["ground"].items()}
    body = {n: np.array(v, float) for n, v in data["bodies"]["mast"].items()}
    springs = [(body[s["a"].split(".")[1]], ground[s["b"].split(".")[1]], num(s["k"]),
                num(s["L0"])) for s in data["springs"]]  # fmt: skip
    (load,) = data["loads"]
    return {"springs": springs, "load": (body[load["point"].split(".")[1]],
                                         np.array([num(f) for f in load["force"]]))}  # fmt: skip


def energy(R: np.ndarray, fx: float | None = None) -> np.ndarray:
    """V(R) = sum k/2 (|R p - a| - L0)^2 - F . R t, per rotation (n, 3, 3)."""
    m = _mast(fx)
    V = np.zeros(len(R))
    for p, a, k, L0 in m["springs"]:
        V += k / 2 * (np.linalg.norm(R @ p - a, axis=1) - L0) ** 2
    t, F = m["load"]
    return V - (R @ t) @ F


def gradient(R: np.ndarray, fx: float | None = None) -> np.ndarray:
    """dV/dw of V(R exp([w]x)) at w = 0 (n, 3): d(R p)/dw = -R [p]x."""
    m = _mast(fx)
    g = np.zeros((len(R), 3))
    for p, a, k, L0 in m["springs"]:
        r = R @ p - a
        d = np.linalg.norm(r, axis=1, keepdims=True)
        g += np.einsum("ni,nij->nj", k * (1 - L0 / d) * r, -R @ _hat(p[None])[0])
    t, F = m["load"]
    return g - np.einsum("i,nij->nj", F, -R @ _hat(t[None])[0])


def hessian(R: np.ndarray, fx: float | None = None, h: float = 1e-5) -> np.ndarray:
    """d^2 V / dw^2 at w = 0 (n, 3, 3), central differences of `gradient`; symmetric at a
    critical point (where the choice of the exponential chart does not matter)."""
    cols = []
    for j in range(3):
        e = np.zeros((len(R), 3))
        e[:, j] = h
        cols.append((gradient(R @ _exp(e), fx) - gradient(R @ _exp(-e), fx)) / (2 * h))
    H = np.stack(cols, axis=-1)
    return (H + np.swapaxes(H, 1, 2)) / 2


@cache
def critical_points(seed: int = 7, fx: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(rotations (m, 3, 3), Hessian indices (m,)) of every critical point of V that Newton
    reaches from STARTS random rotations (steps capped at 0.5 rad), one per rotation."""
    rng = np.random.default_rng(seed)
    R = _rotation(rng.normal(size=(STARTS, 4)))
    for _ in range(60):
        H, g = hessian(R, fx), gradient(R, fx)
        step = -np.linalg.solve(H + 1e-14 * np.eye(3), g[..., None])[..., 0]
        norm = np.linalg.norm(step, axis=1, keepdims=True)
        R = R @ _exp(step * np.minimum(1.0, 0.5 / np.maximum(norm, 1e-300)))
    done = np.linalg.norm(gradient(R, fx), axis=1) < 1e-10
    found: list[np.ndarray] = []
    for r in R[done]:
        if all(np.abs(r - f).max() > SAME for f in found):
            found.append(r)
    rots = np.array(found)
    eig = np.linalg.eigvalsh(hessian(rots, fx))
    assert (np.abs(eig) > 1e-6).all(), "a degenerate critical point: choose other numbers"
    return rots, (eig < 0).sum(axis=1)


def _row_rotations(table) -> np.ndarray:
    return _rotation(table[["mast.qw", "mast.qx", "mast.qy", "mast.qz"]].to_numpy(float))


def test_the_reference_is_complete():
    """The reference's own check: its Morse sum is chi(SO(3)) = 0 with a minimum, and a second
    seed finds the same critical points."""
    rots, index = critical_points()
    assert (index == 0).sum() >= 1 and ((-1) ** index).sum() == 0
    other, _ = critical_points(seed=11)
    assert len(other) == len(rots)
    assert all(np.abs(rots - r).max(axis=(1, 2)).min() < SAME for r in other)


@pytest.fixture(scope="module")
def solved():
    # The complex route, whose paths reach q and -q apart (the real route's charts hold one of
    # them: tests/test_rotations.py; the sweep and the command line below take it by default).
    return cb.solve(cb.Framework.from_toml(FIXTURE), route="complex")


def test_each_pose_once_and_every_critical_point_found(solved):
    """Physical rows = the reference's critical points, one row each (not one per sign of q),
    kinds and energies alike; no two real rows are one rotation."""
    rots, index = critical_points()
    phys = solved.physical
    assert len(phys) == len(rots) and len(solved.stable) == int((index == 0).sum())
    kinds = np.where(index == 0, "min", np.where(index == 3, "max", "saddle"))
    R = _row_rotations(phys)
    matched = []
    for r, kind, V in zip(R, phys["kind"], phys["energy"], strict=True):
        gap = np.abs(rots - r).max(axis=(1, 2))
        j = int(np.argmin(gap))
        assert gap[j] < 1e-7 and kind == kinds[j]
        assert V == pytest.approx(energy(rots[j : j + 1])[0], abs=1e-9)
        matched.append(j)
    assert sorted(matched) == list(range(len(rots)))
    real = solved.table[solved.table["is_real"].astype(bool)]
    Rr = _row_rotations(real)
    gaps = np.abs(Rr[:, None] - Rr[None]).max(axis=(2, 3)) + np.eye(len(Rr))
    assert gaps.min() > SAME, "two real rows are one rotation (q and -q)"
    assert solved.counts["physical"] == len(rots)


def test_the_certificate_counts_each_pose_once(solved):
    rots, _ = critical_points()
    cert = cb.certify(solved)
    assert cert.status == "rows proved", cert.statement
    assert f"; {len(rots)} physical (consistency and stability proved)" in cert.statement


def test_a_pose_listed_twice_is_a_contradiction(solved):
    """A table listing the minimum again with -q (as before issue 39) is not certified as two
    equilibria: the certificate names the two rows as one pose."""
    import pandas as pd

    from cotm_bertini.analysis.certify.framework import certify_framework_table

    table = solved.table.reset_index(drop=True)
    twin = table[table["kind"] == "min"].copy()
    first = int(twin["solution_id"].iloc[0])
    for c in "wxyz":
        twin[f"mast.q{c}"] = -twin[f"mast.q{c}"]
    twin["solution_id"] = len(table) + 1
    doubled = pd.concat([table, twin], ignore_index=True)
    cert = certify_framework_table(solved.params, doubled)
    assert cert.status == "contradiction", cert.statement
    assert cert.contradictions == [
        f"solutions {first} and {len(table) + 1} are proved at one pose (up to the sign of a "
        "quaternion): one equilibrium listed twice"
    ]


def test_cli_solve_counts_each_pose_once(tmp_path):
    rots, index = critical_points()
    r = run_cli(
        "solve", "--framework", str(FIXTURE), "--out", str(tmp_path), "--no-plots", "--no-cache"
    )
    assert r.returncode == 0, r.stderr
    # the real route (the default for a body on a ball joint) says its rows' count this way
    assert f"{len(rots)} equilibria ({int((index == 0).sum())} stable" in r.stdout
    counts = json.loads(next(tmp_path.glob("*/run.json")).read_text())["counts"]
    assert counts["physical"] == len(rots) and counts["stable"] == int((index == 0).sum())


def test_a_sweep_counts_each_pose_once_and_keeps_its_branches():
    """Every point of a sweep over the load goes through the same classification: its physical
    rows are the reference's critical points at that load, one each; each physical branch
    runs through every point though the shown sign of one saddle's q flips on the way (its qw
    crosses 0 near fx = 0.95: the branches are joined by sign-free coordinates)."""
    values = [0.0, 0.5, 0.9, 1.0, 1.5]
    sw = cb.sweep(cb.Framework.from_toml(FIXTURE), "fx", values)
    table = sw.table
    phys = table[table["physical"].astype(bool)]
    for fx in values:
        rots, index = critical_points(fx=fx)
        here = phys[np.isclose(phys["fx"], fx)]
        assert len(here) == len(rots) and ((-1) ** index).sum() == 0
        R = _row_rotations(here)
        assert all(np.abs(rots - r).max(axis=(1, 2)).min() < 1e-7 for r in R)
    branches = phys.groupby("branch")
    assert len(branches) == len(critical_points()[0])
    assert all(len(b) == len(values) and b["kind"].nunique() == 1 for _, b in branches)
    # A branch's next row is, of the next point's physical rows, the nearest rotation.
    for a, b in zip(values, values[1:], strict=False):
        now, then = (phys[np.isclose(phys["fx"], v)].sort_values("branch") for v in (a, b))
        gap = np.abs(_row_rotations(now)[:, None] - _row_rotations(then)[None]).max(axis=(2, 3))
        assert (gap.argmin(axis=1) == np.arange(len(now))).all()


def test_q_and_minus_q_are_one_pose_for_branch_matching():
    """The sweeps' match coordinates of a row and of the same row with -q are equal."""
    from cotm_bertini.continuation.framework import pose_coordinates

    fw = cb.Framework.from_toml(FIXTURE)
    table = cb.solve(fw).physical
    twin = table.copy()
    for c in "wxyz":
        twin[f"mast.q{c}"] = -twin[f"mast.q{c}"]
    assert np.abs(pose_coordinates(fw, table) - pose_coordinates(fw, twin)).max() < 1e-15


def test_each_bodys_sign_flips_on_its_own():
    """Two spatial bodies: a root and its three sign copies (-q1, -q2, both; the other unknowns
    unchanged, endpoints refined to 1e-13) are one row with the paths of all four, also where
    qw is 0 but for rounding (a half turn, where a first-component sign rule would split
    them); a root whose second body differs stays a row of its own."""
    from types import SimpleNamespace

    from cotm_bertini.analysis.classify import Merged
    from cotm_bertini.analysis.framework_classify import merge_sign_twins, shown_quaternions
    from cotm_bertini.settings import Tolerances

    rng = np.random.default_rng(3)
    names = ["d_s", *(f"q{c}_one" for c in "wxyz"), "w_s", *(f"q{c}_two" for c in "wxyz")]
    fs = SimpleNamespace(ps=SimpleNamespace(variables=names))
    half_turn = np.array([1e-17, 0.6, -0.48, 0.64])  # qw of a half turn, as rounding leaves it
    q2 = rng.normal(size=4)
    rows, other = [], np.array([1.3, 0.0, 0.0, 0.0, 0.0, 2.1, 0.0, 0.0, 0.0, 0.0])
    for s1, s2 in ((1, 1), (-1, 1), (1, -1), (-1, -1)):
        x = other.copy()
        x[1:5] = s1 * half_turn + np.array([s1 * -2e-17, 0, 0, 0])  # the sign of qw differs
        x[6:10] = s2 * q2 / np.linalg.norm(q2)
        rows.append(x + 1e-13 * rng.normal(size=len(x)))
    apart = rows[0].copy()
    apart[6:10] = rng.normal(size=4) / 2
    x = np.array([*rows, apart], dtype=complex)
    n = len(x)
    merged = Merged(x, np.ones(n, int), [str(i + 1) for i in range(n)], np.ones(n), np.ones(n),
                    np.zeros(n, bool), np.full(n, 1e-26))  # fmt: skip
    out = merge_sign_twins(fs, merged, Tolerances())
    assert out.paths == ["1 2 3 4", "5"] and list(out.multiplicity) == [1, 1]
    assert not out.singular.any()
    shown = shown_quaternions(np.array(rows)[:, 1:5])
    assert np.abs(shown - half_turn).max() < 1e-12  # each copy shown with one sign
