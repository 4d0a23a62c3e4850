"""What a user reads on the console and in the static pictures, checked against independent
routes: `solve`'s physical rows against a dense scan of Zeeman's energy written in plain numpy
(tests/framework_physics.py), the pictures' load arrows against the file's own numbers."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd
from conftest import run_cli
from framework_physics import scan_critical_points, zeeman_energy

ROOT = Path(__file__).resolve().parent.parent
U = (0.1, -0.25)  # Zeeman's moving anchor: two stable states with tension-only bands


def _printed_rows(stdout: str) -> list[list[str]]:
    """The cells of every line between `solve`'s table header and its `other rows` line."""
    lines = stdout.splitlines()
    head = next(k for k, line in enumerate(lines) if line.split()[:1] == ["solution_id"])
    end = next(k for k, line in enumerate(lines) if "other rows" in line)
    return [lines[head].split()] + [line.split() for line in lines[head + 1 : end]]


def test_solve_prints_the_physical_rows_and_counts_the_others(tmp_path):
    """`solve --framework zeeman_cables.toml`: the printed rows are exactly the equilibria of an
    independent dense scan of V(theta) (angles to the 4 printed decimals, stable = a minimum),
    and one line counts the other rows of solutions.csv, by reason, where they are."""
    # The complex route: its table holds complex and inconsistent rows to count (the real
    # route's holds only the equilibria).
    done = run_cli("solve", "--framework", str(ROOT / "examples" / "zeeman_cables.toml"),
                   "--set", f"x={U[0]}", "--set", f"y={U[1]}", "--no-plots",
                   "--out", str(tmp_path), "--route", "complex")  # fmt: skip
    assert done.returncode == 0, done.stderr
    names, *cells = _printed_rows(done.stdout)
    assert all(len(c) == len(names) for c in cells), cells  # no row without a kind
    shown = pd.DataFrame(cells, columns=names)
    want = scan_critical_points(lambda t: zeeman_energy(t, U, cables=True))
    assert len(shown) == len(want) == 4
    got = sorted(zip(shown["wheel.angle_deg"].astype(float), shown.stable == "True", strict=True))
    ref = sorted((round(np.degrees(t), 4) % 360, kind == "min") for t, kind in want)
    assert [s for _, s in got] == [s for _, s in ref]
    assert np.abs(np.array([a for a, _ in got]) - [a for a, _ in ref]).max() < 2e-4
    table = pd.read_csv(tmp_path / "latest" / "solutions.csv")
    others = table[~table.physical]
    line = next(x for x in done.stdout.splitlines() if "other rows" in x)
    assert line.startswith(f"{len(others)} other rows in the run folder's solutions.csv")
    counted = dict((w, int(n)) for n, w in re.findall(r"(\d+) (\w+)", line.split(":", 1)[1]))
    assert counted == others.reason.str.split(":").str[0].value_counts().to_dict()
    assert "cable_pushes" in counted and "complex" in counted
    assert str(tmp_path / "latest") in done.stdout or str(tmp_path) in done.stdout


def test_the_papers_report_lists_its_physical_rows_and_counts_the_rest():
    """Case 3 by bertini2's ab-initio route: the report shows 14 rows and counts the other 62
    as Bertini 1.6 classifies them on the same formulation (tests/fixtures/bertini-1.6, and
    docs/paper.md): 12 negative d, 4 + 10 with a spring of zero length, 36 other complex."""
    from conftest import solved

    from cotm_bertini.io.runfolder import solve_record

    point, _ = solved("case3")
    text = solve_record(point, {}, "case3", None)["summary"]
    names, *cells = _printed_rows(text)
    assert names == ["solution_id", "gamma1_deg", "gamma2_deg", "d1", "d2", "stable", "kind"]
    assert len(cells) == 14 and all(len(c) == len(names) for c in cells)
    assert all(float(c[3]) > 0 and float(c[4]) > 0 for c in cells)
    line = text.splitlines()[-1]
    assert line == (
        "62 other rows in the run folder's solutions.csv (not physical: 36 complex, "
        "14 zero_length_spring, 12 negative_d; its column reason says why)"
    )


def test_the_pictures_draw_each_load_as_an_arrow_at_its_point():
    """configurations.png of Zeeman's wheel with a load (fx, fy) = (0.05, -0.1) on its rim:
    in every panel an arrow whose head is at the rim (from the row's wheel angle and the
    file's geometry) and which points along the force, labelled by its name and size."""
    import cotm_bertini as cb
    from cotm_bertini.plot.framework import framework_figure

    fw = cb.Framework.from_toml(ROOT / "tests" / "fixtures" / "zeeman_load.toml")
    fw = fw.replace(fx=0.05, fy=-0.1)
    table = cb.solve(fw).table
    phys = table[table.physical.astype(bool)]
    fig = framework_figure(fw, table)
    panels = [ax for ax in fig.axes if ax.get_title()]
    assert len(panels) == len(phys) >= 2
    force = np.array([0.05, -0.1])
    for ax, (_, row) in zip(panels, phys.iterrows(), strict=True):
        (arrow,) = [t for t in ax.texts if t.get_gid() == "load-hand"]
        theta = np.radians(row["wheel.angle_deg"])
        rim = np.array([1.0 + 0.5 * np.cos(theta), 0.5 * np.sin(theta)])
        head, tail = np.array(arrow.xy), np.array(arrow.xyann)
        assert np.abs(head - rim).max() < 1e-9
        along = (head - tail) / np.linalg.norm(head - tail)
        assert np.abs(along - force / np.linalg.norm(force)).max() < 1e-9
        assert arrow.get_text() == f"hand {np.hypot(*force):.3g}"
