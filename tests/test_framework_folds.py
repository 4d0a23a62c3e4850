"""Fold curves, cusps and cable switches of frameworks (issue 19), against independent routes:
dense scans of plain-numpy energies (tests/framework_physics.py) and the paper's closed form."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from framework_physics import scan_critical_points, zeeman_energy

import cotm_bertini as cb
from cotm_bertini.catastrophe.framework_folds import SPACING, framework_fold_curves
from cotm_bertini.errors import ParameterError

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
ZEEMAN_WINDOW = ((-0.6, 0.8), (-0.8, 0.2))


def _scanned_folds_along_x(x: float) -> list[float]:
    """The y where the number of minima of the independent V changes along the line x, bisected
    on dense scans."""
    ys = np.linspace(*ZEEMAN_WINDOW[1], 401)
    counts = np.array([_minima((x, y)) for y in ys])
    out = []
    for k in np.flatnonzero(np.diff(counts)):
        a, b = ys[k], ys[k + 1]
        for _ in range(34):
            m = (a + b) / 2
            a, b = (m, b) if _minima((x, m), 100_000) == counts[k] else (a, m)
        out.append((a + b) / 2)
    return out


def test_determinant_by_minors_is_sympys():
    """The fold condition's determinant (expansion by minors over the polynomial ring, which
    takes float coefficients as they come) equals sympy's Berkowitz determinant, up to 7 x 7,
    with zero entries and float coefficients."""
    import sympy as sp
    from sympy.polys.matrices import DomainMatrix

    from cotm_bertini.model.framework.folds import _det_by_minors

    rng = np.random.default_rng(11)
    x, y, z = sp.symbols("x y z")
    pool = [0, 1, x, y - 2, z * x + 3, sp.Float(0.25) * y * z, sp.Float(-1.5)]
    point = {x: 0.3, y: -0.7, z: 1.1}
    for n in (1, 2, 3, 5, 7):
        M = sp.Matrix(n, n, lambda i, j: pool[rng.integers(len(pool))])
        dm = DomainMatrix.from_Matrix(M)
        ours = dm.domain.to_sympy(_det_by_minors(dm))
        theirs = M.det(method="berkowitz")
        assert abs(complex(ours.subs(point)) - complex(theirs.subs(point))) < 1e-9, n


def test_fold_condition_vanishes_at_the_scanned_folds_only():
    """The fold system's extra equation (the bordered Hessian's determinant cleared of 1/d),
    evaluated at the double roots of the independent V' along x = 0.1 and at its ordinary
    critical points: zero at the first, not at the second. Cheap: no Bertini solve."""
    from cotm_bertini.model.framework.folds import curve_system
    from cotm_bertini.model.framework.units import units

    fw = cb.Framework.from_toml(EXAMPLES / "zeeman.toml").replace(x=0.1, y=-0.3)
    cs = curve_system(fw, (), "x", "y")
    L, K = units(fw)

    def fold_value(theta: float, u) -> tuple[float, float]:
        rim = np.array([1.0 + 0.5 * np.cos(theta), 0.5 * np.sin(theta)])
        X = {"c_wheel": np.cos(theta), "s_wheel": np.sin(theta)}
        for band, anchor in (("band_u", u), ("band_p", (2.0, 0.25))):
            d = np.hypot(*(rim - anchor))
            X[f"d_{band}"], X[f"w_{band}"] = d / L, (1.0 - 0.25 / d) / K
        z = np.array([X[v] for v in cs.variables] + [u[0] / cs.scales[0], u[1] / cs.scales[1]])
        res = cs.trace.evaluate(z)[0].real
        return float(np.abs(res[:-1]).max()), float(abs(res[-1]))

    folds = _scanned_folds_along_x(0.1)
    assert len(folds) == 2
    for y in folds:
        # Just on the side with the extra pair: the closest min-max pair is the merging one.
        crit = scan_critical_points(lambda t, y=y: zeeman_energy(t, (0.1, y + 1e-9), False))
        thetas = np.sort([t for t, _ in crit])
        gaps = np.diff(np.append(thetas, thetas[0] + 2 * np.pi))
        if len(thetas) == 2:
            crit = scan_critical_points(lambda t, y=y: zeeman_energy(t, (0.1, y - 1e-9), False))
            thetas = np.sort([t for t, _ in crit])
            gaps = np.diff(np.append(thetas, thetas[0] + 2 * np.pi))
        k = int(np.argmin(gaps))
        double = thetas[k] + gaps[k] / 2
        others = [t for t in thetas if abs(np.angle(np.exp(1j * (t - double)))) > 1e-3]
        balance, at_fold = fold_value(double, (0.1, y))
        assert balance < 1e-6 and len(others) >= 2
        assert at_fold < 1e-2 * min(fold_value(t, (0.1, y))[1] for t in others)


@pytest.fixture(scope="module")
def zeeman():
    fw = cb.Framework.from_toml(EXAMPLES / "zeeman.toml")
    table, record = framework_fold_curves(fw, "x", ZEEMAN_WINDOW[0], "y", ZEEMAN_WINDOW[1])
    return table, record


def _dV(theta, u, h=1e-5):
    return (zeeman_energy(theta + h, u, False) - zeeman_energy(theta - h, u, False)) / (2 * h)


def _d2V(theta, u, h=1e-4):
    f = zeeman_energy
    return (f(theta + h, u, False) - 2 * f(theta, u, False) + f(theta - h, u, False)) / h**2


def _minima(u, n: int = 20000) -> int:
    """Minima of the independent V(theta) at u: sign changes - to + of V' on a dense grid."""
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    g = _dV(t, u)
    return int(((g < 0) & (np.roll(g, -1) >= 0)).sum())


@pytest.mark.slow  # the fold system's witness set: minutes cold (see docs/design.md)
def test_zeeman_fold_points_are_folds_of_the_independent_energy(zeeman):
    table, _ = zeeman
    folds = table[table["kind"] == "fold"]
    assert len(folds) > 100 and folds["physical"].all()
    theta = np.radians(folds["wheel.angle_deg"].to_numpy())
    u = (folds["x"].to_numpy(), folds["y"].to_numpy())
    assert np.abs(_dV(theta, u)).max() < 1e-8
    assert np.abs(_d2V(theta, u)).max() < 1e-5  # V'' scale ~ 0.1-1: a double root of V'


@pytest.mark.slow  # the fold system's witness set: minutes cold (see docs/design.md)
def test_zeeman_is_the_diamond(zeeman):
    table, record = zeeman
    assert record["curves_found"] == 1 and record["counts"]["cusp"] == 4
    ends = [e for ts in record["taut_sets"].values() for r in ts.values() for e in r["ends"]]
    assert ends == [["closed", "closed"]]
    cusps = table[table["kind"] == "cusp"]
    assert (cusps["null_cubic"] < 1e-6).all()
    folds = table[table["kind"] == "fold"]
    cusp_xy = cusps[["x", "y"]].to_numpy()
    far = np.hypot(*(folds[["x", "y"]].to_numpy()[:, None, :] - cusp_xy).transpose(2, 0, 1))
    assert np.median(folds["null_cubic"][far.min(axis=1) > 0.05]) > 1e-3
    # Two cusps on the axis of symmetry (through the pivot c = (1, 0) and p = (2, 0.25)), the
    # other two mirror images of each other in it.
    axis = np.array([1.0, 0.25]) / np.hypot(1.0, 0.25)
    rel = cusp_xy - np.array([1.0, 0.0])
    off = rel @ np.array([-axis[1], axis[0]])
    assert (np.abs(off) < 1e-6).sum() == 2
    pair = rel[np.abs(off) >= 1e-6]
    mirror = 2 * np.outer(pair @ axis, axis) - pair
    assert np.abs(mirror[::-1] - pair).max() < 1e-6


@pytest.mark.slow  # the fold system's witness set: minutes cold (see docs/design.md)
def test_zeeman_folds_along_x_0_1_agree_with_a_dense_scan(zeeman):
    """The y where the number of minima changes along x = 0.1, bisected on a dense scan of the
    independent energy, against the fold curve's crossings of x = 0.1."""
    table, _ = zeeman
    scanned = _scanned_folds_along_x(0.1)
    folds = table[table["kind"] == "fold"].sort_values(["curve_id", "arc"])
    crossings = []
    for _, c in folds.groupby("curve_id"):
        x, y = c["x"].to_numpy(), c["y"].to_numpy()
        for i in np.flatnonzero(np.sign(x[:-1] - 0.1) != np.sign(x[1:] - 0.1)):
            crossings.append(y[i] + (0.1 - x[i]) * (y[i + 1] - y[i]) / (x[i + 1] - x[i]))
    assert len(scanned) == 2 and len(crossings) == 2
    # The polyline's chord: within its spacing squared times the curvature.
    assert np.abs(np.sort(crossings) - np.sort(scanned)).max() < 2e-4


@pytest.mark.slow  # the fold system's witness set: minutes cold (see docs/design.md)
def test_zeeman_stable_count_changes_across_every_arc(zeeman):
    """Across each fold point (away from the cusps) the independent scan's number of minima
    changes by one exactly where changes_stable_count says so."""
    table, _ = zeeman
    cusp_xy = table.loc[table["kind"] == "cusp", ["x", "y"]].to_numpy()
    folds = table[table["kind"] == "fold"].sort_values(["curve_id", "arc"])
    xy = folds[["x", "y"]].to_numpy()
    checked = 0
    for k in range(1, len(xy) - 1, 15):
        if np.hypot(*(cusp_xy - xy[k]).T).min() < 0.05:
            continue
        tangent = xy[k + 1] - xy[k - 1]
        normal = np.array([-tangent[1], tangent[0]]) / np.linalg.norm(tangent)
        step = 2e-3 * normal
        change = abs(_minima(tuple(xy[k] + step)) - _minima(tuple(xy[k] - step)))
        assert change == (1 if folds["changes_stable_count"].iloc[k] else 0)
        checked += 1
    assert checked > 10


@pytest.mark.slow  # the fold system's witness set: minutes cold (see docs/design.md)
def test_polylines_are_ordered_and_dense(zeeman):
    table, _ = zeeman
    diag = np.hypot(*(np.diff(w)[0] for w in ZEEMAN_WINDOW))
    for _, c in table[table["kind"] == "fold"].groupby("curve_id"):
        c = c.sort_values("arc")
        gaps = np.hypot(np.diff(c["x"]), np.diff(c["y"]))
        assert gaps.max() <= SPACING * diag * (1 + 1e-6)
        assert np.allclose(np.diff(c["arc"]), gaps / diag)


def test_bad_axes_are_refused():
    fw = cb.Framework.from_toml(EXAMPLES / "zeeman.toml")
    with pytest.raises(ParameterError, match="^z: unknown parameter"):
        framework_fold_curves(fw, "z", (0, 1), "y", (0, 1))
    with pytest.raises(ParameterError, match="^x: window"):
        framework_fold_curves(fw, "x", (1, 0), "y", (0, 1))
    with pytest.raises(ParameterError, match="^seeds: 'lines' is not a seed route"):
        framework_fold_curves(fw, "x", (0, 1), "y", (0, 1), seeds="lines")
    with pytest.raises(ParameterError, match="^workers = 0: must be an integer >= 1"):
        framework_fold_curves(fw, "x", (0, 1), "y", (0, 1), workers=0)


def test_zeeman_sweep_seeds_find_the_same_diamond():
    """The seed route from the equilibria along the lines (no fold witness set: branches traced
    from the grid's crossings, folds where they turn back): the same single closed curve with
    four cusps, each point a double root of the independent V, and its crossings of x = 0.1
    where a dense scan puts them."""
    fw = cb.Framework.from_toml(EXAMPLES / "zeeman.toml")
    table, record = framework_fold_curves(
        fw, "x", ZEEMAN_WINDOW[0], "y", ZEEMAN_WINDOW[1], kinds=("fold",), seeds="sweep"
    )
    info = record["taut_sets"]["none"]["fold"]
    assert info["seed_route"] == "sweep" and "generic_set" not in info
    assert info["sweep_points"] == 9 and len(info["lines"]) == 18
    assert sum(ln["real_in_window"] for ln in info["lines"]) >= 4  # the diamond crosses lines
    assert record["curves_found"] == 1 and record["counts"]["cusp"] == 4
    assert info["ends"] == [["closed", "closed"]] and info["unrefined_turns"] == 0
    folds = table[table["kind"] == "fold"].sort_values("arc")
    theta = np.radians(folds["wheel.angle_deg"].to_numpy())
    u = (folds["x"].to_numpy(), folds["y"].to_numpy())
    assert np.abs(_dV(theta, u)).max() < 1e-8 and np.abs(_d2V(theta, u)).max() < 1e-5
    x, y = u
    cut = np.flatnonzero(np.sign(x[:-1] - 0.1) != np.sign(x[1:] - 0.1))
    crossings = y[cut] + (0.1 - x[cut]) * (y[cut + 1] - y[cut]) / (x[cut + 1] - x[cut])
    scanned = _scanned_folds_along_x(0.1)
    assert len(crossings) == 2 and np.abs(np.sort(crossings) - np.sort(scanned)).max() < 2e-4


def test_zeeman_sweep_route_in_two_processes_is_the_same():
    """The sweep route's solves, lines and classification in two worker processes give the
    table of one process, row for row."""
    fw = cb.Framework.from_toml(EXAMPLES / "zeeman.toml")
    args = (fw, "x", ZEEMAN_WINDOW[0], "y", ZEEMAN_WINDOW[1])
    one, rec1 = framework_fold_curves(*args, kinds=("fold",), seeds="sweep")
    two, rec2 = framework_fold_curves(*args, kinds=("fold",), seeds="sweep", workers=2)
    assert rec2["workers"] == 2 and len(one) > 500
    pd.testing.assert_frame_equal(one, two)


def _cable_minima(u, n: int = 20000) -> int:
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    h = 1e-5
    g = (zeeman_energy(t + h, u, True) - zeeman_energy(t - h, u, True)) / (2 * h)
    return int(((g < 0) & (np.roll(g, -1) >= 0)).sum())


def test_zeeman_cables_switch_curve_against_a_scan():
    """Points of the cable-switch curves: at their (x, y) a dense scan of the independent cable
    energy has an equilibrium at the row's wheel angle where the band is exactly at its free
    length; the stable count on both sides of the curve agrees with changes_stable_count."""
    fw = cb.Framework.from_toml(EXAMPLES / "zeeman_cables.toml")
    table, record = framework_fold_curves(
        fw, "x", ZEEMAN_WINDOW[0], "y", ZEEMAN_WINDOW[1], kinds=("cable_switch",)
    )
    assert record["kinds"] == ["cable_switch"] and set(table["kind"]) == {"cable_switch"}
    assert len(table) > 100 and table["physical"].all()
    # At the corner (0.8, 0.2) u is 0.217 from the rim's circle, less than the band's free
    # length 0.25: band_u can go slack there though never at the window's centre, so the taut
    # set {band_p} is the window's. Its equations hold neither x nor y: no curve, and said so.
    assert np.hypot(0.8 - 1.0, 0.2) > 0.5 - 0.25 and ZEEMAN_WINDOW == ((-0.6, 0.8), (-0.8, 0.2))
    alone = record["taut_sets"]["band_p"]["switch band_p"]
    assert alone["curves_traced"] == 0 and "neither x nor y" in alone["why"]
    rows = table.sort_values(["curve_id", "arc"]).reset_index(drop=True)
    for k in range(1, len(rows) - 1, max(1, len(rows) // 8)):
        row = rows.iloc[k]
        u = (row["x"], row["y"])
        crit = scan_critical_points(lambda t, u=u: zeeman_energy(t, u, True))
        theta = np.radians(row["wheel.angle_deg"])
        gap = [abs(np.angle(np.exp(1j * (t - theta)))) for t, _ in crit]
        t_scan = crit[int(np.argmin(gap))][0]
        assert min(gap) < 1e-6
        rim = np.array([1.0 + 0.5 * np.cos(t_scan), 0.5 * np.sin(t_scan)])
        assert abs(np.hypot(*(rim - np.array(u))) - 0.25) < 1e-6
        xy = rows[["x", "y"]].to_numpy()
        tangent = xy[k + 1] - xy[k - 1]
        step = 2e-3 * np.array([-tangent[1], tangent[0]]) / np.linalg.norm(tangent)
        change = abs(_cable_minima(tuple(xy[k] + step)) - _cable_minima(tuple(xy[k] - step)))
        assert change == (1 if row["changes_stable_count"] else 0)


def _cotm_springs(g1, g2):
    """The two spring vectors (p6 - p2, p5 - p3) of the paper's mechanism at poses (gamma1,
    gamma2) and their derivatives in gamma1 and gamma2: plain numpy from Table 1's geometry
    (not the framework's derivation)."""
    rod = 9.0 * np.array([np.cos(g1), np.sin(g1)])
    rod_1 = 9.0 * np.array([-np.sin(g1), np.cos(g1)])
    c, s = np.cos(g2), np.sin(g2)
    top6, top6_2 = 4.25 * np.array([c, s]), 4.25 * np.array([-s, c])
    top5 = np.array([-0.299 * c + 3.4872 * s, -0.299 * s - 3.4872 * c])
    top5_2 = np.array([0.299 * s + 3.4872 * c, -0.299 * c + 3.4872 * s])
    r1 = rod + top6 - np.array([3.1875, 0.0])[:, None]
    r2 = rod + top5 - np.array([-2.5745, 4.9309])[:, None]
    return (r1, rod_1, top6_2), (r2, rod_1, top5_2)


def test_cotm_relaxed_folds_against_plain_geometry_and_the_closed_form():
    """cotm.toml's relaxed folds (both springs at their free length, where the fold system is
    singular): each point's free lengths are its spring lengths and the lengths' Jacobian in
    the two angles is singular (plain numpy, central differences), each changes the stable
    count, and they lie on the closed form's relaxed family (catastrophe/paper_folds.py) and
    cover it in the window."""
    from cotm_bertini.backends.pools import worker_pool
    from cotm_bertini.catastrophe import framework_folds as ff
    from cotm_bertini.catastrophe.paper_folds import fold_curves
    from cotm_bertini.model.framework.folds import RELAXED, curve_system

    fw = cb.Framework.from_toml(EXAMPLES / "cotm.toml")
    window = (1e-3, 14.0)
    cs = curve_system(fw.replace(L01=7.0, L02=7.0), (), "L01", "L02", RELAXED)
    axes = ("L01", window), ("L02", window)
    with worker_pool(1) as run:
        work = ff._Work(run, 1, "relaxed folds")
        curves, info = ff._find(fw, cs, axes, cb.Settings(), "auto", work)
        table, _, about = ff._rows(fw, curves, ("L01", "L02"), 0, work)
    assert info["seed_route"] == "witness" and info["lost_paths"] == 0
    assert about["artefacts"] == 0 and len(table) > 500 and table["physical"].all()
    assert table["changes_stable_count"].all() and set(table["kind"]) == {"fold"}
    g1 = np.radians(table["rod.angle_deg"].to_numpy())
    g2 = np.radians(table["top.angle_deg"].to_numpy())
    springs = _cotm_springs(g1, g2)
    L0 = table[["L01", "L02"]].to_numpy()
    lengths = np.stack([np.hypot(*r) for r, _, _ in springs], axis=1)
    assert np.abs(lengths - L0).max() < 1e-9 * 14
    # The gradients of |r|^2 / 2 in (gamma1, gamma2): parallel.
    grads = [np.stack([(r * a).sum(axis=0), (r * b).sum(axis=0)]) for r, a, b in springs]
    det = grads[0][0] * grads[1][1] - grads[0][1] * grads[1][0]
    scale = np.hypot(*grads[0]) * np.hypot(*grads[1])
    assert (np.abs(det) < 1e-6 * scale).all()
    closed = fold_curves(cb.Params.case("case3"))
    closed = closed[(closed["family"] == "relaxed") & closed["physical"]
                    & closed["L01"].between(*window) & closed["L02"].between(*window)]  # fmt: skip
    assert len(closed) > 100
    c = closed[["L01", "L02"]].to_numpy()
    nearest = np.sqrt(((c[:, None, :] - L0[None, :, :]) ** 2).sum(axis=2)).min(axis=1)
    assert nearest.max() <= SPACING * np.hypot(14.0, 14.0)


def test_cotm_toml_folds_lie_on_the_closed_form_curves():
    """The fold curves of examples/cotm.toml by the Bertini route, over the paper's window
    (0, 14]^2, against the built-in closed form (catastrophe/paper_folds.py: the parallel curve
    and the quadratic det H(t)), which shares no code with the framework route: every Bertini fold
    point has its pose on the parallel curve and its free lengths those the closed form gives at
    that pose (1e-6 relative), and every closed-form fold point in the window is within the
    polyline spacing of a Bertini one."""
    from cotm_bertini.analysis.design.free_lengths import generalised_forces, parallel_cross
    from cotm_bertini.catastrophe.paper_folds import fold_curves, tensioned_free_lengths

    p = cb.Params.case("case3")
    fw = cb.Framework.from_toml(EXAMPLES / "cotm.toml")
    window = (1e-9, 14.0)
    table, record = framework_fold_curves(fw, "L01", window, "L02", window, kinds=("fold",))
    for info in (r for ts in record["taut_sets"].values() for r in ts.values()):
        assert info["lost_paths"] == 0 and info.get("unrefined_turns", 0) == 0
    assert record["taut_sets"]["none"]["fold"]["seed_route"] == "sweep"  # 1,408 witness paths
    folds = table[table["physical"].astype(bool) & (table["kind"] == "fold")]
    assert len(folds) > 500
    g1 = np.radians(folds["rod.angle_deg"].to_numpy())
    g2 = np.radians(folds["top.angle_deg"].to_numpy())
    ours = folds[["L01", "L02"]].to_numpy().T
    # On the parallel curve: a_1 x a_2 = 0, relative to |a_1| |a_2|.
    a, d = generalised_forces(p, g1, g2)
    scale = np.hypot(*a[0]) * np.hypot(*a[1])
    assert (np.abs(parallel_cross(p, g1, g2)) <= 1e-6 * scale).all()
    # Free lengths: the tensioned fold's (t = -c1/c2) or the relaxed one's (L0 = d, t = 0).
    tensioned = tensioned_free_lengths(p, g1, g2)
    gap = np.minimum(np.abs(ours - tensioned).max(axis=0), np.abs(ours - d).max(axis=0))
    assert (gap <= 1e-6 * np.abs(ours).max(axis=0)).all()
    # The reverse: every closed-form fold point in the window near a Bertini one.
    closed = fold_curves(p)
    closed = closed[closed["physical"] & (closed["kind"] == "fold")
                    & closed["L01"].between(*window) & closed["L02"].between(*window)]  # fmt: skip
    assert len(closed) > 500
    spacing = SPACING * np.hypot(14.0, 14.0)
    c = closed[["L01", "L02"]].to_numpy()
    nearest = np.sqrt(((c[:, None, :] - ours.T[None, :, :]) ** 2).sum(axis=2)).min(axis=1)
    assert nearest.max() <= spacing, closed.iloc[int(np.argmax(nearest))].to_dict()
