"""Certification (issue 11): each solution proved in ball arithmetic, and the physical set proved
complete; the proof checked against independent answers, and shown able to fail."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import cotm_bertini as cb
from cotm_bertini.analysis.certify.mechanism import certify_table
from cotm_bertini.analysis.critical_points import critical_points
from cotm_bertini.point import solve_point

sys.path.insert(0, str(Path(__file__).resolve().parent / "stress"))
from test_stress import random_params  # noqa: E402

FULL = os.environ.get("COTM_STRESS") == "full"
RANDOM = range(1, 51) if FULL else range(1, 7)


@pytest.mark.parametrize(("case", "n"), [("case1", 4), ("case2", 6), ("case3", 14)])
def test_paper_cases_are_proved(case, n):
    """N = 4 / 6 / 14 equilibria proved, as many as the energy route (Newton on grad V from a
    grid) finds; every stability label proved; every nonsingular solution certified."""
    params = cb.Params.case(case)
    table = solve_point(params).table
    cert = certify_table(params, table)
    assert cert.status == "proved", cert.statement
    assert cert.proved_equilibria == n == len(critical_points(params))
    phys = table[table["physical"]]
    assert {int(s): k for s, k in zip(phys["solution_id"], phys["kind"], strict=True)} == cert.kinds
    nonsingular = ~table["singular"].to_numpy()
    assert cert.certified[nonsingular].all() and not cert.certified[~nonsingular].any()
    assert not cert.undecided_boxes and not cert.contradictions
    # The spring-length bound agrees with the statement's claim (issue 27): no free length in
    # case 1 (no claim, bound 0), none reaching zero length in case 2 (a lower bound, rounded
    # down), boxes set aside in case 3 (an upper bound, rounded up).
    said = re.search(r"longer than ([0-9.e+-]+) m", cert.statement)
    if case == "case1":
        assert "(no spring has a free length)" in cert.statement and cert.shortest_spring == 0
    elif case == "case2":
        assert "in every pose: none reaches zero length" in cert.statement
        assert 0 < float(said.group(1)) <= cert.shortest_spring and not cert.excluded_boxes
    else:
        assert cert.excluded_boxes and 0 < cert.shortest_spring <= float(said.group(1))


@pytest.mark.parametrize("seed", RANDOM)
def test_random_geometries_are_proved(seed):
    """Random geometries (tests/stress's generator): proved, no undecided box, and the proved
    equilibria are those of the energy route whose springs are longer than the bound."""
    params = random_params(seed)
    table = solve_point(params).table
    cert = certify_table(params, table)
    assert cert.status == "proved", cert.statement
    route = critical_points(params)
    assert cert.proved_equilibria <= len(route)
    assert not cert.undecided_boxes


def _tampered(table, drop: bool):
    """The case-2 table with its first physical row dropped, or moved 0.5 deg."""
    first = table.index[np.flatnonzero(table["physical"].to_numpy())[0]]  # its label
    if drop:
        return table.drop(index=first).reset_index(drop=True)
    moved = table.copy()
    g = np.radians(moved.loc[first, ["gamma1_deg", "gamma2_deg"]].to_numpy(float) + 0.5)
    moved.loc[first, ["gamma1_deg", "gamma2_deg"]] = np.degrees(g)
    for name, value in (("c1", np.cos(g[0])), ("s1", np.sin(g[0])), ("c2", np.cos(g[1])),
                        ("s2", np.sin(g[1]))):  # fmt: skip
        moved.loc[first, f"{name}_re"] = value
    return moved


@pytest.mark.parametrize("drop", [True, False], ids=["dropped", "perturbed"])
def test_the_certificate_can_fail(drop):
    """A table missing an equilibrium, or with one moved off its root: a contradiction."""
    params = cb.Params.case("case2")
    table = _tampered(solve_point(params).table, drop)
    cert = certify_table(params, table)
    assert cert.status == "contradiction"
    assert any("not in the table" in text for text in cert.contradictions)
    if not drop:
        assert any("not proved" in text for text in cert.contradictions)
        assert not cert.certified[0]


def test_api_raises_on_a_contradiction_and_saves_the_evidence(tmp_path):
    res = cb.solve(cb.Params.case("case2"))
    cert = cb.certify(res)
    assert cert.status == "proved" and res.table["certified"].sum() == 20
    folder = res.save(tmp_path / "run", plots=False)
    rec = json.loads((folder / "run.json").read_text())
    assert rec["certificate"]["status"] == "proved"
    assert "python-flint" in rec["certificate"]["library"]
    res._table = _tampered(res.table.drop(columns=["certified", "certified_radius"]), True)
    with pytest.raises(cb.CertificateError, match="not in the table") as err:
        cb.certify(res)
    assert err.value.certificate.status == "contradiction"


def test_cli_certify_and_exit_4(tmp_path, monkeypatch):
    r = subprocess.run(
        [sys.executable, "-m", "cotm_bertini.cli", "certify", "case1", "--no-plots", "--out",
         str(tmp_path)], capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert r.returncode == 0, r.stderr
    assert "certificate: proved: exactly 4 equilibria" in r.stdout
    rec = json.loads((tmp_path / "latest" / "run.json").read_text())
    assert rec["certificate"]["proved_equilibria"] == 4

    from cotm_bertini.analysis.certify import mechanism as certify_module
    from cotm_bertini.cli.main import main

    real = certify_module.certify_table
    monkeypatch.setattr(
        certify_module, "certify_table", lambda p, t: real(p, _tampered(t, drop=False))
    )
    assert main(["solve", "case2", "--certify", "--no-plots", "--out", str(tmp_path)]) == 4
    rec = json.loads((tmp_path / "latest" / "run.json").read_text())
    assert rec["status"] == "contradiction" and rec["certificate"]["contradictions"]


def test_sweep_certify_proves_every_point(tmp_path):
    sw = cb.sweep(cb.Params(), "L01", [10.9, 11.05, 11.2], workers=1, out=tmp_path, certify=True)
    per_point = sw.table.groupby("point")["certificate"].first()
    assert (per_point == "proved").all() and sw.status == "ok"
    assert sw.table.loc[~sw.table["singular"], "certified"].all()
