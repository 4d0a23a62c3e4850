"""Branches and events of an L01 sweep, checked against answers the module does not produce.

A small sweep (L01 = 10.9..11.1, Table 1, L02 = 0) holds one fold: a stable minimum and a saddle
are born there (the real count goes 8 -> 10 near L01 = 11.0128). The checks: branch steps are
small, and each agrees with Newton continuation of the polynomial system between the points;
the fold is confirmed by independent bertini2 ab-initio solves on both sides of it, and to 1e-8
by Newton on the polynomial system; the stability change there by the energy Hessian and the
direct solves (a minimum and a saddle on one side, neither on the other).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cotm_bertini.continuation.events import find_events
from cotm_bertini.continuation.matching import assign_branches
from cotm_bertini.continuation.runner import assemble, prepare, run_points
from cotm_bertini.continuation.spec import SweepSpec
from cotm_bertini.model.compiled import energy_hessian, parametric_system
from cotm_bertini.params import TABLE1, Params
from cotm_bertini.settings import Settings

PARAM = "L01"
START, STOP, POINTS = 10.9, 11.1, 11
NEAR_DEG = 1.0  # solutions this close (each angle) to an event's angles are "near" it


@pytest.fixture(scope="module")
def small(tmp_path_factory) -> tuple[pd.DataFrame, pd.DataFrame]:
    spec = SweepSpec.linspace(Params(**TABLE1), PARAM, START, STOP, POINTS)
    folder = prepare(spec, tmp_path_factory.mktemp("sweep"))
    run_points(spec, folder, workers=1)
    sweep = assign_branches(assemble(spec, folder), PARAM)
    return sweep, find_events(sweep, PARAM, TABLE1, spec.settings)


@pytest.fixture(scope="module")
def fold(small) -> pd.Series:
    events = small[1]
    folds = events[events["kind"] == "fold"]
    assert len(folds) == 1, events[["kind", "branches", PARAM, "description"]]
    return folds.iloc[0]


@pytest.fixture(scope="module")
def solves(fold) -> dict[float, pd.DataFrame]:
    """bertini2 ab-initio (the cli engine) just below and just above the fold."""
    from conftest import solve

    cli = Settings(engine="cli")
    return {d: solve(Params(**{**TABLE1, PARAM: fold[PARAM] + d}), cli) for d in (-1e-4, 1e-4)}


def _system(value: complex):
    ps = parametric_system(Params(**{**TABLE1, PARAM: 1.0}).zfl)
    vals = {**TABLE1, PARAM: value}
    return ps, ps.instantiate([vals[n] for n in ps.parameters])


def _coords(rows: pd.DataFrame, variables) -> np.ndarray:
    return np.stack([rows[f"{v}_re"] + 1j * rows[f"{v}_im"] for v in variables], axis=1)


def _near(table: pd.DataFrame, g1: float, g2: float) -> pd.DataFrame:
    gap = np.abs((table[["gamma1_deg", "gamma2_deg"]].to_numpy() - [g1, g2] + 180) % 360 - 180)
    return table[(gap < NEAR_DEG).all(axis=1)]


def _track(values: list[complex], x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Newton continuation of every row of x through the parameter values; (x, converged)."""
    for value in values:
        _, system = _system(value)
        for _ in range(8):
            step = np.linalg.solve(system.jacobian(x), system.evaluate(x)[..., None])[..., 0]
            x = x - step
    return x, np.abs(system.evaluate(x) / system.scale()).max(axis=1) < 1e-10


def test_branches_are_continuous(small):
    sweep, _ = small
    assert (sweep["branch"] >= 0).all()
    assert not sweep.duplicated(["point", "branch"]).any(), "a branch twice at one point"
    # Deterministic, whatever the row order.
    shuffled = sweep.drop(columns="branch").sample(frac=1.0, random_state=3)
    again = assign_branches(shuffled, PARAM).set_index(["point", "solution_id"])["branch"]
    assert again.equals(sweep.set_index(["point", "solution_id"])["branch"].loc[again.index])
    variables = parametric_system(Params(**{**TABLE1, PARAM: 1.0}).zfl).variables
    points = sorted(sweep["point"].unique())
    # Steps along each branch: at most a few times that branch's typical (median) step
    # (measured: at most 3.2 times, on the two branches that meet at the fold; a swap of two
    # branches makes a step as long as the distance between them).
    for b, rows in sweep.sort_values(PARAM).groupby("branch"):
        assert len(rows) == POINTS, f"branch {b} does not span the sweep"
        steps = np.linalg.norm(np.diff(_coords(rows, variables), axis=0), axis=1)
        typical = np.median(steps)
        assert steps.max() <= 5 * typical + 1e-12, (b, steps)
    # Each step is what Newton continuation between the points gives (a small detour into
    # complex L01 passes beside a fold; there the pair may land on either partner).
    # (Singular rows, the d1 = 0 artefacts, are double roots: Newton does not apply.)
    for ka, kb in zip(points[:-1], points[1:], strict=True):
        A = sweep[sweep["point"] == ka].set_index("branch")
        B = sweep[sweep["point"] == kb].set_index("branch")
        regular = A[~A["singular"]]
        assert len(regular) >= 20
        pa, pb = A[PARAM].iloc[0], B[PARAM].iloc[0]
        t = np.linspace(0, 1, 25)[1:]
        path = list(pa + t * (pb - pa) + 0.5j * (pb - pa) * np.sin(np.pi * t))
        x, ok = _track(path, _coords(regular, variables))
        assert ok.all(), f"Newton continuation failed from {PARAM} = {pa}"
        xb = _coords(B, variables)
        for b, end in zip(regular.index, x, strict=True):
            j = int(np.argmin(np.abs(xb - end).max(axis=1)))
            hit = B.index[j]
            assert np.abs(xb[j] - end).max() < 1e-6
            flips = A.loc[b, "is_real"] != B.loc[b, "is_real"]
            assert hit == b or (flips and A.loc[hit, "is_real"] != B.loc[hit, "is_real"]), (
                f"{PARAM} {pa} -> {pb}: branch {b} continues to branch {hit}"
            )


def test_fold_confirmed_by_direct_solves(fold, solves):
    p, g1, g2 = fold[PARAM], fold["gamma1_deg"], fold["gamma2_deg"]
    assert fold["refined"] and fold["lo"] < p < fold["hi"]
    assert START < p < STOP
    below, above = solves[-1e-4], solves[1e-4]
    assert len(below) == len(above) == 22
    assert abs(int(above["is_real"].sum()) - int(below["is_real"].sum())) == 2
    real_side, complex_side = (
        (above, below) if "real above" in fold["description"] else (below, above)
    )
    near_real, near_complex = _near(real_side, g1, g2), _near(complex_side, g1, g2)
    assert int(real_side["is_real"].sum()) == int(complex_side["is_real"].sum()) + 2
    assert len(near_real) == 2 and near_real["is_real"].all()
    assert len(near_complex) == 2 and not near_complex["is_real"].any()
    assert abs(near_complex["gamma1_imag_deg"]).max() > 1e-4


def test_fold_satisfies_augmented_system(fold):
    ps, system = _system(fold[PARAM])
    assert tuple(fold["variables"]) == ps.variables
    x, v = np.array(fold["x"]), np.array(fold["null_vector"])
    jac = system.jacobian(x)[0].real
    assert np.abs(system.evaluate(x)[0]).max() < 1e-8
    assert np.abs(jac @ v).max() < 1e-8 and np.linalg.norm(v) > 0.1
    sv = np.linalg.svd(jac, compute_uv=False)
    assert sv[-1] < 1e-10 * sv[0], sv
    # The parameter value to 1e-8: 1e-8 to one side two distinct real roots near x, to the
    # other a complex-conjugate pair, by Newton on the polynomial system.
    kinds = []
    for d in (-1e-8, 1e-8):
        starts = np.array([x + s * e * v for s in (1e-5, 1e-4, 1e-3) for e in (1, -1, 1j, -1j)])
        roots, ok = _track([fold[PARAM] + d] * 8, starts)
        roots = roots[ok & (np.abs(roots - x).max(axis=1) < 1e-2)]
        assert len(roots), d
        imag = np.abs(roots.imag).max()
        spread = np.ptp(roots.real, axis=0).max()
        kinds.append(
            "real" if imag < 1e-12 and spread > 1e-6 else "complex" if imag > 1e-6 else "unclear"
        )
    assert sorted(kinds) == ["complex", "real"], kinds
    assert ("real above" in fold["description"]) == (kinds[1] == "real")


def test_stability_change_at_fold_or_confirmed(small, fold, solves):
    events = small[1]
    changes = events[events["kind"] == "stability_change"]
    assert len(changes) >= 1
    folds = events[events["kind"] == "fold"]
    for _, ev in changes.iterrows():
        p, g1, g2 = ev[PARAM], ev["gamma1_deg"], ev["gamma2_deg"]
        at_fold = folds[(abs(folds[PARAM] - p) < 1e-9) & (folds["branches"] == ev["branches"])]
        if len(at_fold):
            # The energy Hessian is singular at the fold point, and the two equilibria that
            # meet there are a minimum and a saddle (solved directly): one stable one fewer.
            params = Params(**{**TABLE1, PARAM: p})
            eig = np.linalg.eigvalsh(energy_hessian(params, np.radians(g1), np.radians(g2)))[0]
            assert abs(eig).min() < 1e-6 * abs(eig).max(), eig
            stable = {d: int(t["stable"].sum()) for d, t in solves.items()}
            assert abs(stable[1e-4] - stable[-1e-4]) == 1, stable
            pairs = [_near(t, g1, g2) for t in solves.values()]
            pairs = [t for t in pairs if len(t) == 2 and t["physical"].all()]
            assert len(pairs) == 1, pairs
            pair = pairs[0]
            signs = np.sign(pair[["hess_eig1", "hess_eig2"]].to_numpy()).prod(axis=1)
            assert sorted(signs) == [-1, 1], pair
        else:
            from conftest import solve

            signs = []
            for d in (-1e-4, 1e-4):
                table = solve(Params(**{**TABLE1, PARAM: p + d}))
                near = _near(table[table["physical"]], g1, g2)
                assert len(near) >= 1
                signs.append(np.sign(near[["hess_eig1", "hess_eig2"]].to_numpy()[0]))
            assert (signs[0] != signs[1]).any(), signs
