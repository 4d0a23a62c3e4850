"""Certificates that agree with themselves (issue 27, items 7 and 8): a spatial row far from
singular is proved, a row that is not is named with the step that failed in the sentence,
run.json and the exit code alike; the spring-length bound and the statement's claim agree, and
the bound holds against the lengths computed without package code."""

from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pytest
from conftest import ROOT, run_cli
from framework_physics import PRISM_BASE, hessian_eigenvalues, prism_nodes, scan_critical_points

import cotm_bertini as cb

# A node on a rod of length 1 about the origin (its poses: the unit sphere), pulled by a spring
# with a free length towards p and by one of zero free length towards q. The ground points lie
# in the plane z = 0; V = F(x) + G(y) on the sphere with G' != 0, so every equilibrium has z = 0
# exactly (grad V = lambda N with lambda != 0): flat poses of a spatial framework.
SPHERE = """
name = "sphere_two_springs"
dim = 3
nodes = ["N"]

[parameters]
L0 = 0.5

[ground]
o = [0.0, 0.0, 0.0]
p = [2.0, 0.0, 0.0]
q = [0.0, 1.5, 0.0]

[[bars]]
name = "rod"
a = "ground.o"
b = "N"
length = 1.0

[[springs]]
name = "s"
a = "N"
b = "ground.p"
k = 1.0
L0 = "L0"

[[springs]]
name = "t"
a = "N"
b = "ground.q"
k = 0.7
L0 = 0.0
"""


def _sphere_energy(a, b, L0=0.5):
    """V of SPHERE at N = (cos a cos b, sin a cos b, sin b), written without package code."""
    a, b = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float))
    n = np.stack([np.cos(a) * np.cos(b), np.sin(a) * np.cos(b), np.sin(b)])
    ds = np.sqrt((n[0] - 2.0) ** 2 + n[1] ** 2 + n[2] ** 2)
    dt2 = n[0] ** 2 + (n[1] - 1.5) ** 2 + n[2] ** 2
    return 0.5 * (ds - L0) ** 2 + 0.35 * dt2


def _sphere_equilibria() -> list[tuple[float, str]]:
    """(angle a in the plane z = 0, kind) of every equilibrium of SPHERE with a positive spring
    length: a dense scan along the circle, the kind from the 2 x 2 Hessian in (a, b)."""
    out = []
    for a, _ in scan_critical_points(lambda t: _sphere_energy(t, 0.0)):
        eig = hessian_eigenvalues(_sphere_energy, (a, 0.0))
        out.append((a, "min" if eig.min() > 0 else "max" if eig.max() < 0 else "saddle"))
    return out


@pytest.fixture(scope="module")
def sphere(tmp_path_factory):
    path = tmp_path_factory.mktemp("sphere") / "sphere.toml"
    path.write_text(SPHERE)
    return path


def test_a_flat_spatial_maximum_is_proved(sphere):
    """Every equilibrium lies in z = 0: with the table's z set to that exact 0 (the solver
    reports 1e-200 or so), each coordinate ball is centred at 0. The maximum (and the minimum)
    must still be proved, with the kinds of the independent energy."""
    res = cb.solve(cb.Framework.from_toml(sphere))
    table = res.table
    assert (table["N.z"].abs() < 1e-9).all()
    table.loc[:, "N.z"] = 0.0  # the exact value (module comment), in the table cb.certify reads
    cert = cb.certify(res)
    assert cert.status == "rows proved", cert.statement
    assert not cert.not_proved
    phys = res.physical
    angles = np.arctan2(phys["N.y"], phys["N.x"]) % (2 * np.pi)
    expected = {}
    for a, kind in _sphere_equilibria():
        gap = np.abs((angles - a + np.pi) % (2 * np.pi) - np.pi)
        expected[int(phys["solution_id"].iloc[int(np.argmin(gap))])] = kind
        assert gap.min() < 1e-6
    assert sorted(expected.values()) == ["max", "min"]
    assert cert.kinds == expected
    assert cert.proved_equilibria == 2
    assert cert.statement.startswith("proved: ") and "; 2 physical (consistency" in cert.statement


def _certificate_block(out) -> dict:
    return json.loads(next(out.glob("*/run.json")).read_text())["certificate"]


def test_rows_proved_agree_in_sentence_run_json_and_exit_code(sphere, tmp_path):
    r = run_cli("certify", "--framework", str(sphere), "--out", str(tmp_path), "--no-plots")
    assert r.returncode == 0, r.stderr
    line = next(t for t in r.stdout.splitlines() if t.startswith("certificate: "))
    assert line.startswith("certificate: proved: every certified solution")
    assert "; 2 physical (consistency and stability proved)" in line
    block = _certificate_block(tmp_path)
    assert block["status"] == "rows proved"
    assert block["proved_equilibria"] == 2
    assert sorted(block["kinds"].values()) == ["max", "min"]
    assert block["not_proved"] == {}


def test_a_row_not_proved_is_named_alike_everywhere(sphere, tmp_path, monkeypatch):
    """The inertia proof made to fail for the maximum (as a NaN enclosure did, issue 27): the
    sentence names the row and the step, run.json says the same, the exit code is 5."""
    from cotm_bertini.analysis.certify import framework
    from cotm_bertini.cli.main import main

    real = framework.reduced_kind

    def no_maximum(H, G):
        kind = real(H, G)
        return "undecided" if kind == "max" else kind

    monkeypatch.setattr(framework, "reduced_kind", no_maximum)
    code = main(["certify", "--framework", str(sphere), "--out", str(tmp_path), "--no-plots"])
    assert code == 5
    block = _certificate_block(tmp_path)
    assert block["status"] == "undecided"
    ((sid, why),) = block["not_proved"].items()
    assert why.startswith("kind: a pivot of the ball LDL^T")
    assert block["kinds"][sid] == "undecided"
    assert block["proved_equilibria"] == 1
    assert block["statement"].startswith(f"not proved: solution {sid} ({why}); proved: ")
    assert "; 1 physical (consistency and stability proved)" in block["statement"]


def _claimed_bound(statement: str) -> float:
    """The length the statement's spring clause names (what it claims is proved)."""
    found = re.search(r"longer than ([0-9.e+-]+)", statement)
    assert found, statement
    return float(found.group(1))


def test_the_spring_bound_and_the_claim_agree():
    """Zeeman's bands never reach zero length: the certificate says so with a positive bound
    (not 0.0), the record holds the same bound, and every band is longer than it in every pose
    (a dense scan of the rim, without package code)."""
    x, y = 0.1, -0.25
    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman.toml").replace(x=x, y=y)
    cert = cb.certify(cb.solve(fw))
    assert cert.status == "proved", cert.statement
    assert "in every pose: none reaches zero length" in cert.statement
    said = _claimed_bound(cert.statement)
    t = np.linspace(0, 2 * np.pi, 200_001)
    rim = np.stack([1.0 + 0.5 * np.cos(t), 0.5 * np.sin(t)])
    shortest = min(np.hypot(rim[0] - a, rim[1] - b).min() for a, b in ((x, y), (2.0, 0.25)))
    assert 0 < said <= cert.shortest_spring <= shortest
    assert said > 0.5 * shortest  # a bound worth stating, not a token positive number
    assert cert.record()["shortest_spring_bound"] == cert.shortest_spring


def _prism_with_a_free_length_diagonal(L0: float) -> str:
    """examples/prism.toml with the diagonal cable from A a free length L0 (a parameter)."""
    text = (ROOT / "examples" / "prism.toml").read_text()
    text = text.replace("\n[ground]", f"L0da = {L0}\n\n[ground]", 1)
    head, tail = text.split('name = "diag_a"', 1)
    return head + 'name = "diag_a"' + tail.replace('L0 = "L0d"', 'L0 = "L0da"', 1)


def _prism_kind(nodes: np.ndarray, L0: float, kt=1.0, kd=1.5) -> str:
    """The kind of a pose (top nodes A, B, C) of that prism from an energy written here: the
    central-difference Hessian in each node's (polar, azimuth) angles about its base corner."""
    rel = (nodes - PRISM_BASE) / 1.2
    x0 = np.ravel([[np.arccos(v[2]), np.arctan2(v[1], v[0])] for v in rel])

    def energy(x):
        n = prism_nodes(x)
        top = sum(np.sum((n[i] - n[(i + 1) % 3]) ** 2) for i in range(3))
        diag = [np.linalg.norm(n[i] - PRISM_BASE[(i + 1) % 3]) for i in range(3)]
        return kt / 2 * top + kd / 2 * (max(diag[0] - L0, 0.0) ** 2 + diag[1] ** 2 + diag[2] ** 2)

    h, e = 1e-4, np.eye(6) * 1e-4
    H = np.array([[(energy(x0 + e[a] + e[b]) - energy(x0 + e[a] - e[b]) - energy(x0 - e[a] + e[b])
                    + energy(x0 - e[a] - e[b])) / (4 * h * h) for b in range(6)]
                  for a in range(6)])  # fmt: skip
    eig = np.linalg.eigvalsh((H + H.T) / 2)
    assert np.abs(eig).min() > 1e-3  # far from singular: the rows the certificate must prove
    return "min" if eig.min() > 0 else "max" if eig.max() < 0 else "saddle"


@pytest.mark.slow
def test_the_prism_with_a_free_length_diagonal_is_proved(tmp_path):
    """The user's case (issue 27, item 7): every physical row proved, its maximum included,
    and the sentence, run.json and exit code agree (a cold first solve takes 10 to 25 min)."""
    L0 = 0.3
    path = tmp_path / "prism_free_diagonal.toml"
    path.write_text(_prism_with_a_free_length_diagonal(L0))
    out = tmp_path / "runs"
    r = run_cli("certify", "--framework", str(path), "--out", str(out), "--no-plots",
                timeout=3600)  # fmt: skip
    assert r.returncode == 0, r.stdout + r.stderr
    line = next(t for t in r.stdout.splitlines() if t.startswith("certificate: "))
    block = _certificate_block(out)
    assert block["status"] == "rows proved" and block["not_proved"] == {}, line
    table = pd.read_csv(next(out.glob("*/solutions.csv")))
    phys = table[table["physical"].astype(bool)]
    kinds = {
        str(sid): _prism_kind(row[[f"{p}.{a}" for p in "ABC" for a in "xyz"]].to_numpy(float)
                              .reshape(3, 3), L0)
        for sid, (_, row) in zip(phys["solution_id"], phys.iterrows(), strict=True)
    }  # fmt: skip
    assert "max" in kinds.values() and block["kinds"] == kinds
    assert block["proved_equilibria"] == len(kinds)
    assert line.startswith("certificate: proved: every certified solution")
    assert f"; {len(kinds)} physical (consistency and stability proved)" in line
