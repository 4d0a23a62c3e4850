"""The paper report, generated from the Bertini 1.6 fixture output (no solver run needed)."""

from __future__ import annotations

from conftest import solved

from cotm_bertini.analysis.classify import classify
from cotm_bertini.backends.parse import read_output
from cotm_bertini.paper.report import Scenario, build_report, match_table
from cotm_bertini.paper.tables import K_RATIO, TABLES
from cotm_bertini.params import make_params


def _fixture_scenario(fixtures_dir) -> Scenario:
    params, tables, paths = {}, {}, {}
    for case in ("case1", "case2", "case3"):
        p = make_params(case)
        out = read_output(fixtures_dir / case)
        params[case] = p
        tables[case] = classify(p, out.endpoints)
        paths[case] = {"case1": 8, "case2": 48, "case3": 192}[case]
    return Scenario("Bertini 1.6 fixtures, Table 1", params, tables, paths)


def test_report_from_fixtures(fixtures_dir):
    """Markdown and CSV: every printed row categorised; counts and labels side by side."""
    text, rows = build_report([_fixture_scenario(fixtures_dir)])
    assert len(rows) == 4 + 14 + 30
    assert set(rows["category"]) <= {
        "physical equilibrium",
        "negative d",
        "d=0 artefact",
        "elimination artefact",
        "unmatched",
    }
    t2 = rows[rows["table"] == "Table 2"]
    assert (t2["category"] == "physical equilibrium").all()
    assert t2["distance"].max() < 1e-3
    # The energy criterion calls solution 1 stable where the paper calls solution 3 stable.
    assert t2.set_index("row")["our_stable"].to_dict() == {1: True, 2: False, 3: False, 4: False}
    t4 = rows[rows["table"] == "Table 4"].set_index("row")
    for r in (14, 15, 26, 28, 29):
        assert t4.loc[r, "category"] == "physical equilibrium" and t4.loc[r, "our_stable"]
    for r in (3, 10, 24, 30):
        assert t4.loc[r, "category"] == "d=0 artefact"
    assert "| Table 4 | 88 (30) |" in text and "76 (30)" in text
    assert "### Table 3 (case2)" in text


def test_table3_elimination_artefacts_with_corrected_ratio():
    """With k2/k1 = 0.98909, Table 3 rows 7, 8, 13, 14 are extra roots of the elimination."""
    result, params = solved("case2", 2.81 * K_RATIO)
    m = match_table(TABLES[1], params, result.table).set_index("row")
    assert [r for r in m.index if m.loc[r, "category"] == "elimination artefact"] == [7, 8, 13, 14]
    assert set(m.loc[[1, 2, 4, 6, 9, 11], "category"]) == {"physical equilibrium"}
    assert set(m.loc[[3, 5, 10, 12], "category"]) == {"negative d"}
