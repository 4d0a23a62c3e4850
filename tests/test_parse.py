"""Parsing Bertini 1.6 (labelled) and Bertini 2 (unlabelled) output into one table shape."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from cotm_bertini.analysis.classify import classify
from cotm_bertini.backends.bertini_cli import run_bertini
from cotm_bertini.backends.engine import find_engine
from cotm_bertini.backends.parse import ParseError, read_output, read_solution_list
from cotm_bertini.params import make_params

# Bertini 1.6 stdout summaries (tests/fixtures/bertini-1.6/README.md): finite endpoints,
# distinct solutions, real ones.
EXPECTED = {"case1": (6, 6, 4), "case2": (24, 22, 10), "case3": (84, 76, 30)}


@pytest.mark.parametrize("case", ["case1", "case2", "case3"])
def test_bertini16_fixtures(fixtures_dir, case):
    """Bertini 1.6 main_data: a row per finite endpoint, duplicates expanded, counts as printed."""
    out = read_output(fixtures_dir / case)
    endpoints, distinct, real = EXPECTED[case]
    assert out.layout == "bertini1"
    assert len(out.endpoints) == endpoints == out.finite_solutions_count
    assert len(set(out.endpoints.path_number)) == len(out.endpoints)
    # Every endpoint of finite_solutions is in the table (Bertini 1 prints one of the paths of a
    # multiple root in main_data; the others agree with it to the tracking accuracy).
    finite = read_solution_list(fixtures_dir / case / "finite_solutions")
    pts = out.endpoints.points
    for p in finite:
        assert np.abs(pts - p).max(axis=1).min() < 1e-9
    params = make_params(case)
    table = classify(params, out.endpoints)
    assert len(table) == distinct
    assert int(table["is_real"].sum()) == real
    assert table["multiplicity"].sum() == endpoints


def test_fresh_bertini2_run_has_same_table_shape(fixtures_dir, tmp_path):
    """bertini2 on the fixture's own input parses into the same columns and the same solutions."""
    b1 = read_output(fixtures_dir / "case1")
    run = run_bertini(
        (fixtures_dir / "case1" / "input").read_text(), tmp_path / "b2", find_engine(), timeout=120
    )
    b2 = read_output(run.folder)
    assert b2.layout == "bertini2"
    f1, f2 = b1.endpoints.frame(), b2.endpoints.frame()
    assert list(f2.columns) == list(f1.columns)
    assert dict(f2.dtypes) == dict(f1.dtypes)
    params = make_params("case1")
    t1 = classify(params, b1.endpoints)
    t2 = classify(params, b2.endpoints)
    assert list(t1.columns) == list(t2.columns)
    assert len(t1) == len(t2) == 6
    for a, b in zip(t1.itertuples(), t2.itertuples(), strict=True):
        assert abs(a.gamma1_deg - b.gamma1_deg) < 1e-8 and abs(a.gamma2_deg - b.gamma2_deg) < 1e-8


def test_malformed_files_raise(fixtures_dir, tmp_path):
    """A truncated solution list or an unknown main_data layout is an error, not a short table."""
    folder = tmp_path / "bad"
    shutil.copytree(fixtures_dir / "case1", folder)
    (folder / "finite_solutions").chmod(0o644)
    text = (folder / "finite_solutions").read_text().split("\n")
    (folder / "finite_solutions").write_text("\n".join(text[:8]))
    with pytest.raises(ParseError, match="header says 6"):
        read_output(folder)
    (folder / "main_data").chmod(0o644)
    (folder / "main_data").write_text("garbage\n")
    with pytest.raises(ParseError, match="layout"):
        read_output(folder)


@pytest.mark.parametrize(
    "settings",
    [{"security_level": 1}, {"variable_groups": "multihomogeneous"}],
    ids=["SecurityLevel-1", "multihomogeneous"],
)
def test_bertini2_output_variants_parse_to_the_same_solutions(settings):
    """main_data with endpoints at infinity (SecurityLevel 1) or one homogenizing variable per
    variable group (multihomogeneous start) gives the same case-2 solutions as the default."""
    from conftest import solve

    from cotm_bertini.settings import Settings

    params = make_params("case2")
    ref = solve(params, Settings(engine="cli"))
    other = solve(params, Settings(engine="cli", **settings))
    assert len(other) == len(ref) == 22
    for col in ("is_real", "physical", "stable"):
        assert other[col].sum() == ref[col].sum()
    a = ref.loc[ref["physical"], ["gamma1_deg", "gamma2_deg"]].to_numpy()
    b = other.loc[other["physical"], ["gamma1_deg", "gamma2_deg"]].to_numpy()
    assert np.abs(a - b).max() < 1e-8
