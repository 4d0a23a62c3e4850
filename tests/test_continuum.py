"""A continuum of equilibria is reported as one, not as missing equilibria (issue 39, item 5).

tests/fixtures/xmodule_spring.toml is a cheap X-module without load: with its cable slack every
pose with the spring at its free length has zero energy. The known answers come from the
mechanism's geometry in plain numpy: the curve |tip1 - tip2| = L0s, its ends where the cable
length |tip1 - b| = L0c, its extremes where the bars line up, and an independent energy.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import run_cli

FIXTURE = Path(__file__).parent / "fixtures" / "xmodule_spring.toml"
L, L0S, L0C, KS, KC = 1.3, 0.6, 1.2, 1.0, 2.0  # the fixture's numbers
B = np.array([1.0, 0.0])  # bar2's pin and the cable's ground end


def _tips(t1: np.ndarray, t2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    a, b = np.radians(t1), np.radians(t2)
    return np.stack([L * np.cos(a), L * np.sin(a)], -1), B + np.stack(
        [L * np.cos(b), L * np.sin(b)], -1
    )


def energy(t1, t2) -> np.ndarray:
    """V(theta1, theta2) in degrees: the spring, the tension-only cable, no load."""
    p, q = _tips(np.asarray(t1, float), np.asarray(t2, float))
    spring = np.linalg.norm(p - q, axis=-1)
    cable = np.linalg.norm(p - B, axis=-1)
    return KS / 2 * (spring - L0S) ** 2 + KC / 2 * np.maximum(cable - L0C, 0.0) ** 2


def on_curve(rho: float) -> list[tuple[float, float]]:
    """The poses (theta1 > 0, both theta2) with |tip1 - b| = rho and the spring at L0s."""
    t1 = np.degrees(np.arccos((L * L + 1 - rho * rho) / (2 * L)))
    phi = np.degrees(np.arctan2(*(_tips(t1, 0.0)[0] - B)[::-1]))
    half = np.degrees(np.arccos(np.clip((rho * rho + L * L - L0S**2) / (2 * L * rho), -1, 1)))
    return [(t1, (phi + s * half) % 360) for s in (-1, 1)]


@pytest.fixture(scope="module")
def solved():
    import cotm_bertini as cb

    fw = cb.Framework.from_toml(FIXTURE)
    return fw, cb.solve(fw)  # the real route (issue 40): boxes along the arcs stay undecided


def test_arcs_of_neutral_minima_end_where_the_cable_turns_taut(solved):
    _, res = solved
    assert res.status == "ok" and not res.warnings, res.warnings
    assert res.counts["continua"] == 2
    arcs = res.record["continua"]
    assert [c["shape"] for c in arcs] == ["arc", "arc"]
    assert all(c["dimension"] == 1 and c["kind"] == "neutral minima" for c in arcs)
    ends = on_curve(L0C)  # closed form: the arc of theta1 > 0 ends where the cable = L0c
    upper = next(c for c in arcs if c["extent"]["bar1.angle_deg"][0] < 180)
    got = sorted(([e["bar1.angle_deg"], e["bar2.angle_deg"]] for e in upper["ends"]),
                 key=lambda e: e[1])  # fmt: skip
    np.testing.assert_allclose(got, sorted(ends, key=lambda e: e[1]), atol=1e-7)
    assert all("cable right reaches its free length" in e["by"] for e in upper["ends"])
    # The arc's other extreme in theta1: the bars in line, |tip1 - b| = L - L0s.
    lo = on_curve(L - L0S)[0][0]
    np.testing.assert_allclose(upper["extent"]["bar1.angle_deg"], [lo, ends[0][0]], atol=1e-7)
    lower = next(c for c in arcs if c is not upper)  # the mirror image
    np.testing.assert_allclose(
        lower["extent"]["bar1.angle_deg"], [360 - ends[0][0], 360 - lo], atol=1e-7
    )
    # The independent energy: 0 at the ends and along the arc; beyond an end the cable pulls.
    assert max(abs(c["energy"]) for c in arcs) < 1e-12
    assert energy(*np.array(ends).T).max() < 1e-20
    inside, beyond = on_curve(L0C - 1e-3)[0], on_curve(L0C + 1e-3)[0]
    assert energy(*inside) < 1e-20 < 1e-8 < energy(*beyond)


def test_the_arcs_are_neutral_minima_of_an_independent_energy(solved):
    """Inside the reported extent V = 0, flat along the curve and rising across it (finite
    differences of the independent energy): neutral minima, as reported."""
    _, res = solved
    arc = next(c for c in res.record["continua"] if c["extent"]["bar1.angle_deg"][0] < 180)
    assert arc["kind"] == "neutral minima" and arc["index_across"] == 0
    lo, hi = arc["extent"]["bar1.angle_deg"]
    for t1 in np.linspace(lo, hi, 7)[1:-1]:
        rho = np.linalg.norm(_tips(t1, 0.0)[0] - B)
        for t in map(np.array, on_curve(rho)):
            h = 1e-3  # degrees
            E = [[energy(*(t + h * (ei + ej))) - energy(*(t + h * (ei - ej)))
                  - energy(*(t - h * (ei - ej))) + energy(*(t - h * (ei + ej)))
                  for ej in np.eye(2)] for ei in np.eye(2)]  # fmt: skip
            eig = np.linalg.eigvalsh(np.array(E) / (4 * h * h) * np.degrees(1.0) ** 2)
            assert energy(*t) < 1e-24 and abs(eig[0]) < 1e-4 * eig[1] and eig[1] > 0.05


def test_rows_on_the_arcs_are_not_isolated_equilibria(solved):
    """The Morse sum counts each arc as one minimum; no row on an arc stays `degenerate`."""
    _, res = solved
    t = res.table
    assert not (t["kind"] == "degenerate").any()
    on = t[t["reason"].str.startswith("continuum:")]
    assert len(on) >= 4 and not on["physical"].any()
    assert (energy(on["bar1.angle_deg"], on["bar2.angle_deg"]) < 1e-16).all()
    m = res.morse
    assert m["ok"] and m["continua_term"] == 2 and m["continua_minima"] == 2
    assert res.counts["physical"] == len(res.physical) and m["min"] == 0


def test_a_cable_always_slack_leaves_closed_curves_of_term_zero(solved):
    import cotm_bertini as cb

    fw, _ = solved
    res = cb.solve(fw.replace(L0c=3.0))  # longer than any pose's
    assert res.status == "ok", res.warnings
    loops = res.record["continua"]
    assert [c["shape"] for c in loops] == ["closed curve"] * 2
    assert all(c["morse_term"] == 0 and not c["ends"] for c in loops)
    lo, hi = on_curve(L - L0S)[0][0], on_curve(L + L0S)[0][0]
    upper = next(c for c in loops if c["extent"]["bar1.angle_deg"][0] < 180)
    np.testing.assert_allclose(upper["extent"]["bar1.angle_deg"], [lo, hi], atol=1e-7)


def test_cli_reports_the_continua_and_exits_0(solved, tmp_path):
    r = run_cli("solve", "--framework", str(FIXTURE), "--out", str(tmp_path), "--no-plots")
    assert r.returncode == 0, r.stderr
    assert "equilibria may be missing" not in r.stderr
    assert "2 continua of equilibria apart" in r.stdout
    assert "continuum 1 (taut set none): a 1-dim arc of neutral minima, energy 0.0000" in r.stdout
    assert "where cable right reaches its free length" in r.stdout
    (folder,) = [p for p in tmp_path.iterdir() if p.is_dir() and not p.is_symlink()]
    record = json.loads((folder / "run.json").read_text())
    assert record["counts"]["continua"] == 2 and record["status"] == "ok"
    lines = (folder / "continua.csv").read_text().splitlines()
    assert len(lines) == 3 and lines[0].startswith("continuum,taut_set,dimension,shape")


def test_the_real_route_says_which_boxes_lie_along_the_arcs(solved):
    _, res = solved
    info = res.record["details"]["real_search"]
    assert info["undecided"] == info["undecided_along_continua"] > 0
    assert any("Morse-Bott" in n for n in info["notes"]) and not info["warnings"]


@pytest.mark.slow
def test_the_complex_route_finds_the_same_arcs(solved):
    """The complex route (generic sets, parameter homotopy; ~40 s CPU) against the real one."""
    import cotm_bertini as cb

    fw, real = solved
    cplx = cb.solve(fw, generic="total-degree")
    assert cplx.status == "ok" and cplx.counts["continua"] == real.counts["continua"] == 2
    for a, b in zip(real.record["continua"], cplx.record["continua"], strict=True):
        ea = sorted((e["bar1.angle_deg"], e["bar2.angle_deg"]) for e in a["ends"])
        eb = sorted((e["bar1.angle_deg"], e["bar2.angle_deg"]) for e in b["ends"])
        np.testing.assert_allclose(ea, eb, atol=1e-7)
