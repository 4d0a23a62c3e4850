"""Figures: files written atomically, one panel per physical row, drawn points = the geometry."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from conftest import solved

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def case1():
    result, params = solved("case1")
    return params, result.table


def _lines(fig) -> dict[str, np.ndarray]:
    """Every line that carries a gid, by gid, as an (n, 2) array of the drawn data."""
    return {ln.get_gid(): ln.get_xydata() for ax in fig.axes for ln in ax.lines if ln.get_gid()}


def _expected_points(params, g1_deg: float, g2_deg: float) -> dict[int, np.ndarray]:
    """Points 1-6 from the README's definition, with complex numbers (independent of plot.py)."""
    z4 = params.L3 * np.exp(1j * np.radians(g1_deg))
    rot = np.exp(1j * np.radians(g2_deg))
    z = {
        1: 0j,
        2: complex(params.p2x, 0.0),
        3: complex(params.p3x, params.p3y),
        4: z4,
        5: z4 + rot * complex(params.p5x, params.p5y),
        6: z4 + rot * complex(params.p6x, 0.0),
    }
    return {i: np.array([v.real, v.imag]) for i, v in z.items()}


def test_plot_run_writes_png_and_svg(case1, tmp_path):
    from cotm_bertini.plot.run import plot_run

    params, sols = case1
    paths = plot_run(params, sols, tmp_path)
    assert sorted(p.name for p in paths) == [
        "configurations.png",
        "configurations.svg",
        "energy_map.png",
        "energy_map.svg",
    ]
    for path in paths:
        assert path.parent == tmp_path
        assert path.stat().st_size > 10_000, path
        head = path.read_bytes()[:200]
        if path.suffix == ".png":
            assert head.startswith(PNG_SIGNATURE), path
        else:
            assert head.lstrip().startswith(b"<?xml") and b"<svg" in path.read_bytes(), path
    # Atomic writes leave no temporary file behind.
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in paths)


def test_one_panel_per_physical_row(case1):
    from cotm_bertini.plot.configurations import configurations_figure

    params, sols = case1
    phys = sols[sols["physical"]]
    assert len(phys) == 4  # Table 2: four real solutions, all physical (ZFL springs)
    fig = configurations_figure(params, sols)
    panels = [ax for ax in fig.axes if ax.has_data()]
    assert len(panels) == len(phys)
    assert [ax.get_gid() for ax in panels] == [f"solution-{i}" for i in phys["solution_id"]]
    # Same limits everywhere; stable panels drawn bold and labelled.
    assert len({(ax.get_xlim(), ax.get_ylim()) for ax in panels}) == 1
    lines = _lines(fig)
    for ax, row in zip(panels, phys.itertuples(), strict=True):
        sid = row.solution_id
        top = next(ln for ln in ax.lines if ln.get_gid() == f"s{sid}-top")
        texts = [t.get_text() for t in ax.texts]
        assert ("stable" in texts) == bool(row.stable)
        assert (top.get_linewidth() > 2) == bool(row.stable)
        assert f"{row.gamma1_deg:.2f}" in ax.get_title() and row.kind in ax.get_title()
    assert {f"s{i}-{part}" for i in phys["solution_id"] for part in ("rod", "spring1")} <= set(
        lines
    )


def test_drawn_points_equal_geometry(case1):
    """Bodies, rod and springs of every panel join the points computed from the angles."""
    from cotm_bertini.plot.configurations import configurations_figure

    params, sols = case1
    lines = _lines(configurations_figure(params, sols))
    for row in sols[sols["physical"]].itertuples():
        sid = row.solution_id
        p = _expected_points(params, row.gamma1_deg, row.gamma2_deg)
        np.testing.assert_allclose(lines[f"s{sid}-bottom"], [p[1], p[2], p[3], p[1]], atol=1e-9)
        np.testing.assert_allclose(lines[f"s{sid}-top"], [p[4], p[5], p[6], p[4]], atol=1e-9)
        np.testing.assert_allclose(lines[f"s{sid}-rod"], [p[1], p[4]], atol=1e-9)
        for name, (a, b) in (("spring1", (2, 6)), ("spring2", (3, 5))):
            zig = lines[f"s{sid}-{name}"]
            assert len(zig) > 10  # drawn as a zigzag
            np.testing.assert_allclose(zig[[0, -1]], [p[a], p[b]], atol=1e-9)
        # The drawn springs have the solver's lengths, the rod has length L3.
        assert np.hypot(*(p[6] - p[2])) == pytest.approx(row.d1, rel=1e-9)
        assert np.hypot(*(p[5] - p[3])) == pytest.approx(row.d2, rel=1e-9)
        assert np.hypot(*p[4]) == pytest.approx(params.L3)


def test_energy_map_marks_equilibria_at_their_critical_points(case1):
    from cotm_bertini.model.compiled import energy
    from cotm_bertini.plot.energy_map import energy_map_figure

    params, sols = case1
    fig = energy_map_figure(params, sols)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "gamma1 (deg)" and ax.get_ylabel() == "gamma2 (deg)"
    assert any(a.get_ylabel() == "V (J)" for a in fig.axes[1:])  # the colour bar
    marks = {c.get_gid(): c.get_offsets() for c in ax.collections if c.get_gid()}
    phys = sols[sols["physical"]]
    for kind in ("min", "saddle", "max"):
        rows = phys[phys["kind"] == kind]
        np.testing.assert_allclose(marks[kind], rows[["gamma1_deg", "gamma2_deg"]].to_numpy())
    # The stable solution of case 1 (75.03, 289.04) is marked as a minimum and is one: V is
    # higher on a ring of radius 2 deg around it.
    (g1, g2) = marks["min"][0]
    assert (round(g1, 2), round(g2, 2)) == (75.03, 289.04)
    t = np.linspace(0, 2 * np.pi, 36, endpoint=False)
    ring = energy(params, np.radians(g1 + 2 * np.cos(t)), np.radians(g2 + 2 * np.sin(t)))
    assert ring.min() > energy(params, np.radians([g1]), np.radians([g2]))[0]


def test_no_physical_solution_gives_a_figure_that_says_so(case1, tmp_path):
    from cotm_bertini.plot.configurations import configurations_figure, plot_configurations

    params, sols = case1
    none = sols.assign(physical=False, stable=False)
    fig = configurations_figure(params, none)
    assert not [ax for ax in fig.axes if ax.has_data()]
    assert any("No physical equilibrium" in t.get_text() for t in fig.texts)
    paths = plot_configurations(params, none.iloc[0:0], tmp_path / "empty")
    assert [p.name for p in paths] == ["empty.png", "empty.svg"]
    assert all(p.stat().st_size > 0 for p in paths)


def test_the_rest_of_the_package_does_not_import_matplotlib():
    code = (
        "import sys, cotm_bertini.point, cotm_bertini.cli.commands, cotm_bertini.api.solutions, "
        "cotm_bertini.api.sweeps, cotm_bertini.continuation.events, cotm_bertini.analysis.verify; "
        "print('matplotlib' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
