"""Certificates for frameworks (issue 19): every real row proved, kinds proved, completeness
proved on circles and tori, and the proof's count checked against an independent dense search of
an energy written without package code (framework_physics)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import ROOT, run_cli
from framework_physics import pendulum_energy, scan_critical_points, zeeman_energy

import cotm_bertini as cb
from cotm_bertini.analysis.certify.framework import certify_framework_table

# These share the cold generic sets of the costly examples (fourbar, double pendulum,
# cotm.toml): one xdist worker runs them in turn, so each set is solved once.
pytestmark = pytest.mark.xdist_group("framework_examples")

EXAMPLES = ROOT / "examples"


@pytest.fixture(scope="module")
def pendulum():
    # The same solve as tests/test_frameworks.py: answered from the session's cache there.
    return cb.solve(cb.Framework.from_toml(EXAMPLES / "double_pendulum.toml"))


@pytest.fixture(scope="module")
def zeeman():
    return cb.solve(cb.Framework.from_toml(EXAMPLES / "zeeman.toml").replace(x=0.1, y=-0.25))


@pytest.fixture(scope="module")
def certified(pendulum, zeeman):
    """Each solve certified once (cb.certify attaches the certificate to the solve)."""
    return {"pendulum": cb.certify(pendulum), "zeeman": cb.certify(zeeman)}


def _table_kinds(phys) -> dict[int, str]:
    return {int(s): str(k) for s, k in zip(phys["solution_id"], phys["kind"], strict=True)}


def _real_nonsingular(res) -> np.ndarray:
    t = res.table
    return (t["is_real"].astype(bool) & ~t["singular"].astype(bool)).to_numpy()


@pytest.mark.parametrize("name", ["zeeman", "pendulum"])
def test_circle_and_torus_frameworks_are_proved_complete(name, request, certified):
    res, cert = request.getfixturevalue(name), certified[name]
    assert cert.status == "proved", cert.statement
    assert cert.method == "framework-torus"
    real = _real_nonsingular(res)
    assert cert.certified[real].all() and not cert.certified[~real].any()
    assert (cert.certified_radius[real] < 1e-6).all()
    phys = res.physical
    assert cert.proved_equilibria == len(phys)
    assert cert.kinds == _table_kinds(phys)
    assert not cert.contradictions and not cert.undecided_boxes
    assert res.table["certified"].dtype == bool


def _newton_from_grid(f, n: int = 90, h: float = 1e-5) -> list[tuple[np.ndarray, str]]:
    """Every critical point of f on the torus that Newton on central differences reaches from
    an n x n grid, with its kind from the Hessian's eigenvalues (no package code)."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    x = np.stack([a.ravel() for a in np.meshgrid(t, t, indexing="ij")], axis=1)
    e = np.eye(2) * h
    for _ in range(40):
        g = np.stack([(f(*(x + e[k]).T) - f(*(x - e[k]).T)) / (2 * h) for k in (0, 1)], axis=1)
        H = np.empty((len(x), 2, 2))
        for a in (0, 1):
            for b in (0, 1):
                plus = f(*(x + e[a] + e[b]).T) - f(*(x + e[a] - e[b]).T)
                minus = f(*(x - e[a] + e[b]).T) - f(*(x - e[a] - e[b]).T)
                H[:, a, b] = (plus - minus) / (4 * h * h)
        ok = np.abs(np.linalg.det(H)) > 1e-12
        step = np.zeros_like(x)
        step[ok] = np.linalg.solve(H[ok], g[ok][..., None])[..., 0]
        x = x - np.clip(step, -0.3, 0.3)
    found: list[tuple[np.ndarray, str]] = []
    for p, gp, hp in zip(x, g, H, strict=True):
        if np.linalg.norm(gp) > 1e-8:
            continue
        p = np.mod(p, 2 * np.pi)
        if any(np.abs((p - q + np.pi) % (2 * np.pi) - np.pi).max() < 1e-6 for q, _ in found):
            continue
        eig = np.linalg.eigvalsh((hp + hp.T) / 2)
        found.append((p, "min" if eig.min() > 0 else "max" if eig.max() < 0 else "saddle"))
    return found


def test_pendulum_count_agrees_with_an_independent_dense_search(pendulum, certified):
    cert = certified["pendulum"]
    found = _newton_from_grid(pendulum_energy)
    kinds = sorted(k for _, k in found)
    assert cert.proved_equilibria == len(found), (cert.statement, found)
    assert sorted(cert.kinds.values()) == kinds
    # Poincare-Hopf on the torus (Euler characteristic 0): minima - saddles + maxima = 0.
    assert kinds.count("min") - kinds.count("saddle") + kinds.count("max") == 0
    phys = pendulum.physical
    poses = np.radians(phys[["link1.angle_deg", "link2.angle_deg"]].to_numpy())
    for p, _ in found:
        assert np.abs((poses - p + np.pi) % (2 * np.pi) - np.pi).max(axis=1).min() < 1e-5


def test_zeeman_count_agrees_with_a_dense_scan(certified):
    cert = certified["zeeman"]
    crit = scan_critical_points(lambda t: zeeman_energy(t, (0.1, -0.25), False))
    assert cert.proved_equilibria == len(crit)
    assert sorted(cert.kinds.values()) == sorted(k for _, k in crit)


@pytest.mark.parametrize("name", ["zeeman", "pendulum"])
def test_a_missing_equilibrium_is_found(name, request):
    res = request.getfixturevalue(name)
    fw, table = res.params, res.table.reset_index(drop=True)
    phys = np.flatnonzero(table["physical"].to_numpy(dtype=bool))
    dropped = int(table["solution_id"][phys[-1]])
    cert = certify_framework_table(fw, table.drop(index=phys[-1]).reset_index(drop=True))
    assert cert.status == "contradiction", cert.statement
    assert any("is not in the table" in c for c in cert.contradictions), cert.contradictions
    assert dropped not in cert.kinds


def test_a_perturbed_row_is_not_proved(pendulum):
    table = pendulum.table.reset_index(drop=True).copy()
    row = int(np.flatnonzero(table["physical"].to_numpy(dtype=bool))[0])
    table.loc[row, "link2.angle_deg"] += 1e-3  # a pose 1e-3 deg off the equilibrium
    cert = certify_framework_table(pendulum.params, table)
    assert not cert.certified[row]
    assert cert.status == "contradiction", cert.statement
    sid = int(table["solution_id"][row])
    assert any(f"solution {sid} " in c for c in cert.contradictions), cert.contradictions


def test_fourbar_rows_proved_completeness_not_claimed():
    res = cb.solve(cb.Framework.from_toml(EXAMPLES / "fourbar.toml"))
    cert = cb.certify(res)
    assert cert.status == "rows proved", cert.statement
    assert "completeness not proved: the configuration space is not a circle or torus" in (
        cert.statement
    )
    real = _real_nonsingular(res)
    assert cert.certified[real].all()
    phys = res.physical
    assert cert.kinds == _table_kinds(phys)
    # Without completeness, the equilibria proved are the physical rows proved (root,
    # consistency and kind), and the statement counts the same number.
    assert cert.proved_equilibria == len(phys) > 0 and cert.boxes == 0
    assert f"; {len(phys)} physical (consistency and stability proved)" in cert.statement
    assert not cert.not_proved


def test_certify_framework_cli(tmp_path):
    out = run_cli("certify", "--framework", str(EXAMPLES / "zeeman.toml"), "--out",
                  str(tmp_path), "--no-plots")  # fmt: skip
    assert out.returncode == 0, out.stderr
    assert "certificate: proved: exactly 2 equilibria" in out.stdout
    record = json.loads(next(tmp_path.glob("*/run.json")).read_text())
    assert record["certificate"]["status"] == "proved"
    assert record["certificate"]["proved_equilibria"] == 2
    header = next(tmp_path.glob("*/solutions.csv")).read_text().splitlines()[0].split(",")
    assert "certified" in header and "certified_radius" in header


def test_a_framework_sweep_certifies_every_point(tmp_path):
    fw = cb.Framework.from_toml(EXAMPLES / "zeeman.toml")
    table = cb.sweep(fw, "x", [0.0, 0.1], certify=True, out=tmp_path, workers=1).table
    assert set(table["certificate"]) == {"proved"}
    real = table["is_real"].astype(bool) & ~table["singular"].astype(bool)
    assert table.loc[real, "certified"].astype(bool).all()
    assert not table.loc[~real, "certified"].astype(bool).any()


@pytest.mark.parametrize("u", [(0.1, -0.25), (1.45, 0.2)])
def test_zeeman_with_cables_is_proved_complete(u):
    # The solves of tests/test_frameworks.py (a slack band at (1.45, 0.2)): V is piecewise.
    fw = cb.Framework.from_toml(EXAMPLES / "zeeman_cables.toml").replace(x=u[0], y=u[1])
    cert = cb.certify(cb.solve(fw))
    assert cert.status == "proved", cert.statement
    crit = scan_critical_points(lambda t: zeeman_energy(t, u, True))
    assert cert.proved_equilibria == len(crit)
    assert sorted(cert.kinds.values()) == sorted(k for _, k in crit)


@pytest.mark.parametrize(
    "case, n", [("case1", 4), pytest.param("case3", 14, marks=pytest.mark.slow)]
)
def test_cotm_toml_is_proved_with_the_papers_count(case, n):
    # The paper's mechanism as a framework (solved in tests/test_frameworks.py too): the paper
    # lists 4 physical equilibria in case 1 and 14 in case 3.
    p = cb.Params.case(case)
    fw = cb.Framework.from_toml(EXAMPLES / "cotm.toml").replace(L01=p.L01, L02=p.L02)
    cert = cb.certify(cb.solve(fw))
    assert cert.status == "proved", cert.statement
    assert cert.proved_equilibria == n


@pytest.mark.slow
def test_prism_rows_proved_completeness_not_claimed():
    res = cb.solve(cb.Framework.from_toml(EXAMPLES / "prism.toml"))
    cert = cb.certify(res)
    assert cert.status == "rows proved", cert.statement
    assert cert.certified[_real_nonsingular(res)].all()
    assert cert.kinds == _table_kinds(res.physical)


def test_a_cached_solve_is_certified_alike(zeeman, certified):
    # Answered from the cache: the table is read back from solutions.csv (an empty taut_set
    # field comes back as NaN), and must be proved the same.
    again = cb.solve(zeeman.params)
    assert again.cache_hit
    cert = cb.certify(again)
    assert cert.status == "proved", cert.statement
    assert (cert.certified == certified["zeeman"].certified).all()
    assert cert.kinds == certified["zeeman"].kinds


@pytest.fixture(scope="module")
def chain4():
    # Issue 46's case: a chain of four links (a 4-torus of poses, 34 equilibria), on the real
    # route; its certificate once took 40 times its solve.
    return cb.solve(cb.Framework.from_toml(ROOT / "tests" / "fixtures" / "chain4.toml"))


def test_a_missing_equilibrium_is_found_on_a_4_torus(chain4):
    # The search in four angles halves two sides a box (not all four) and starts from a coarser
    # grid: a critical point the table lacks must still be found, and every other one proved.
    table = chain4.table.reset_index(drop=True)
    phys = np.flatnonzero(table["physical"].to_numpy(dtype=bool))
    dropped = int(table["solution_id"][phys[len(phys) // 2]])
    cert = certify_framework_table(chain4.params, table.drop(index=phys[len(phys) // 2])
                                   .reset_index(drop=True))  # fmt: skip
    assert cert.status == "contradiction", cert.statement
    missing = [c for c in cert.contradictions if "is not in the table" in c]
    assert len(missing) == 1, cert.contradictions
    assert dropped not in cert.kinds and cert.proved_equilibria == len(phys) - 1


@pytest.mark.slow
def test_a_4_torus_is_proved_with_the_solves_count(chain4):
    cert = cb.certify(chain4)
    assert cert.status == "proved", cert.statement
    assert cert.proved_equilibria == len(chain4.physical) == 34
    assert cert.kinds == _table_kinds(chain4.physical)
    assert not cert.undecided_boxes and cert.excluded_boxes == 0
