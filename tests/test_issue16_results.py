"""Issue 16, readable results: tables indexed by solution_id (3), files that respect the umask
(4), a map folder that holds its sweep (5), a word before a long first solve (6), a cached
answer's times labelled (7), counts that each mean one thing (11), grid values as requested
(13), cusps counted "in the window" (14), a barrier map whose title names its marks (17)."""

from __future__ import annotations

import json
import os
import re
import stat
import subprocess
import sys
import time
from fractions import Fraction
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import run_cli

import cotm_bertini as cb

ROOT = Path(__file__).resolve().parent.parent
ANNOUNCE = "solving the generic solution set"


def cli(*args: str, env: dict | None = None, umask: int | None = None, cwd: Path | None = None):
    """Run `cotm-bertini` as a user would, in a fresh process (optionally under a umask)."""
    return run_cli(*args, env=env, umask=umask, cwd=cwd)


@pytest.fixture(scope="module")
def case3() -> cb.Solutions:
    return cb.solve(cb.Params.case("case3"))


@pytest.fixture(scope="module")
def case3_barriers(case3) -> cb.Barriers:
    return cb.barriers(case3)


# ---- item 3: every table is indexed by solution_id ------------------------------------------


def test_3_solution_tables_are_indexed_by_solution_id(case3):
    """res.table and its views, fresh and from the cache: index == solution_id, so .loc[id]."""
    cached = cb.solve(cb.Params.case("case3"))
    assert cached.cache_hit
    for res in (case3, cached):
        for view in ("table", "real", "physical", "stable", "nonsingular"):
            frame = getattr(res, view)
            assert len(frame) > 0, view
            assert list(frame.index) == list(frame["solution_id"]), view
        for sid in res.stable["solution_id"]:
            assert res.stable.loc[sid, "solution_id"] == sid
            assert res.table.loc[sid, "stable"]
    # the certificate lines up row by row whatever the index
    cert = cb.certify(cb.solve(cb.Params.case("case1")))
    assert cert.status == "proved"


def test_3_barrier_tables_name_rows_as_the_solutions_do(case3, case3_barriers):
    """Barriers.table and .pairs are indexed by saddle_id; their minima are labels of res.stable."""
    b = case3_barriers
    assert len(b.pairs) > 0
    for frame in (b.table, b.pairs):
        assert list(frame.index) == list(frame["saddle_id"])
    for sid, row in b.pairs.iterrows():
        assert case3.table.loc[sid, "kind"] == "saddle"
        for m in (row.min_a, row.min_b):
            assert case3.stable.loc[int(m), "kind"] == "min"


# ---- item 4: files and folders with the user's umask -----------------------------------------


def _modes(root: Path) -> dict[str, int]:
    out = {}
    for path in [root, *root.rglob("*")]:
        if not path.is_symlink():
            out[str(path.relative_to(root.parent))] = stat.S_IMODE(path.stat().st_mode)
    return out


def test_4_run_folders_respect_the_umask(tmp_path):
    """Under umask 002 every file a solve (fresh, then from the cache) and a barriers run write
    is 0664 and every folder 0775: shareable with a group, like any ordinary tool's output."""
    env = {"COTM_CACHE": str(tmp_path / "cache")}
    runs = tmp_path / "runs"
    for args in (("solve", "case1"), ("solve", "case1"), ("barriers", "case1")):
        r = cli(*args, "--out", str(runs / args[0]), env=env, umask=0o002)
        assert r.returncode == 0, r.stderr
    modes = _modes(runs)
    assert len([m for m in modes if m.endswith(".csv")]) >= 3
    wrong = {p: oct(m) for p, m in modes.items()
             if m != (0o775 if (tmp_path / p).is_dir() else 0o664)}  # fmt: skip
    assert not wrong


# ---- items 5, 13, 14: the map -----------------------------------------------------------------

WINDOW = {"L01": ("2.1", "2.8"), "L02": ("5.6", "6.3")}  # a cusp at (2.75, 6.20) is inside


@pytest.fixture(scope="module")
def small_map(tmp_path_factory):
    """`cotm-bertini map` on a 3 x 3 grid of a window holding one cusp."""
    out = tmp_path_factory.mktemp("map")
    (a, b), (c, d) = WINDOW["L01"], WINDOW["L02"]
    r = cli("map", "--from", a, "--to", b, "--from2", c, "--to2", d, "--points", "3",
            "--workers", "1", "--no-plots", "--quiet", "--out", str(out))  # fmt: skip
    assert r.returncode == 0, r.stderr
    folder = out / "latest"
    return r, folder.resolve()


def test_5_map_folder_holds_its_sweep(small_map):
    """The saved map holds the 2-D sweep it reports (files, not links into the cache), and its
    regions.csv counts are exactly those of that sweep."""
    r, folder = small_map
    rec = json.loads((folder / "run.json").read_text())
    sweep = (folder / rec["sweep_folder"]).resolve()
    assert sweep.parent == folder and (sweep / "sweep.csv").is_file()
    assert not any(p.is_symlink() for p in [sweep, *sweep.rglob("*")])
    assert str(sweep) in r.stdout
    table = pd.read_csv(sweep / "sweep.csv")
    counts = table.groupby(["L01", "L02"])[["physical", "stable"]].sum().reset_index()
    regions = pd.read_csv(folder / "regions.csv")
    merged = regions.merge(counts, on=["L01", "L02"], suffixes=("", "_sweep"))
    assert len(merged) == len(regions) == 9
    assert (merged.physical == merged.physical_sweep).all()
    assert (merged.stable == merged.stable_sweep).all()


def _exact(lo: str, hi: str, points: int) -> list[str]:
    a, b = Fraction(lo), Fraction(hi)
    return [repr(float(a + (b - a) * k / (points - 1))) for k in range(points)]


def test_13_regions_grid_is_written_as_requested(small_map):
    """regions.csv holds the grid values as asked (2.45, 5.95), not linspace's 5.949999..."""
    _, folder = small_map
    lines = (folder / "regions.csv").read_text().splitlines()
    cells = [line.split(",")[:2] for line in lines[1:]]
    for k, name in enumerate(("L01", "L02")):
        want = _exact(*WINDOW[name], 3)
        assert sorted({c[k] for c in cells}, key=float) == want
    naive = [repr(float(v)) for v in np.linspace(*map(float, WINDOW["L02"]), 3)]
    assert naive != _exact(*WINDOW["L02"], 3)  # this window is one where linspace is off


def test_14_map_counts_cusps_in_the_window(small_map):
    """The console line says the counts are in the window, and the cusp count is folds.csv's."""
    r, folder = small_map
    folds = pd.read_csv(folder / "folds.csv")
    cusps = int((folds.kind == "cusp").sum())
    assert cusps >= 1
    line = next(ln for ln in r.stdout.splitlines() if ln.startswith("map:"))
    assert "in the window L01 2.1..2.8 m, L02 5.6..6.3 m" in line
    assert f" {cusps} cusps" in line and f"{len(folds)} fold points" in line
    assert folds.L01.between(2.1, 2.8).all() and folds.L02.between(5.6, 6.3).all()


def test_14_design_md_counts_cusps_in_all_and_in_the_window():
    """docs/design.md's cusp counts for the paper geometry: in all, and in make map's window."""
    text = " ".join((ROOT / "docs" / "design.md").read_text().split())
    m = re.search(
        r"(\d+) physical cusps in all \((\d+) on tensioned and (\d+) on relaxed fold curves\), "
        r"of which (\d+) are in the window 0 <= L01, L02 <= 14 m",
        text,
    )
    assert m, "the cusp counts sentence is missing from docs/design.md"
    folds = cb.fold_curves(cb.Params.case("case3"))
    cusps = folds[folds.physical & (folds.kind == "cusp")]
    inside = cusps.L01.between(0, 14) & cusps.L02.between(0, 14)
    fam = cusps.family.value_counts()
    assert [int(g) for g in m.groups()] == [
        len(cusps),
        fam.get("tensioned", 0),
        fam.get("relaxed", 0),
        int(inside.sum()),
    ]


# ---- item 6: a word before the first, long generic solve, and a progress bar ----------------


def _in_a_terminal(args: list[str], env: dict) -> str:
    """Run the CLI with stderr on a pseudo-terminal (80 columns); return what it shows there.
    bertini's bar waits 5 s before drawing; here it draws at once, so a short solve shows it."""
    import fcntl
    import pty
    import struct
    import termios

    code = (
        "import sys, bertini._progress as p; p.DELAY_SECONDS = 0.0\n"
        "from cotm_bertini.cli.main import main\n"
        f"sys.exit(main({args!r}))\n"
    )
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 80, 0, 0))
    proc = subprocess.Popen(
        [sys.executable, "-c", code], stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
        stderr=slave, env={**os.environ, **env}, cwd=ROOT,
    )  # fmt: skip
    os.close(slave)
    chunks = []
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # the child closed the terminal
            break
        if not chunk:
            break
        chunks.append(chunk)
    os.close(master)
    assert proc.wait(timeout=600) == 0
    return b"".join(chunks).decode(errors="replace")


def test_6_first_generic_solve_says_what_once_and_shows_progress(tmp_path):
    """A new seed: one line on stderr (what, once, roughly how long), then a progress bar on a
    terminal; the same seed again (solved anew): no such line."""
    env = {"COTM_CACHE": str(tmp_path / "cache")}
    args = ["solve", "case2", "--seed", "4242", "--generic", "total-degree", "--no-plots",
            "--quiet", "--out", str(tmp_path)]  # fmt: skip
    shown = _in_a_terminal(args, env)
    lines = [ln for ln in shown.splitlines() if ANNOUNCE in ln]
    assert len(lines) == 1, shown
    assert re.search(r"seed 4242 \(48 paths, roughly \d+ s; once: kept in .*cache", lines[0])
    after = shown.split(lines[0], 1)[1]
    assert re.search(r"paths: +100%.*48/48", after), after
    again = cli(*args, "--no-cache", env=env)
    assert again.returncode == 0 and ANNOUNCE not in again.stderr
    assert "\r" not in again.stderr  # no bar when stderr is not a terminal


# ---- item 7: a cached answer reports what this command spent ---------------------------------


def test_7_certify_of_a_cached_solve_reports_its_own_time(tmp_path, monkeypatch, capsys):
    """certify of a cached solve: the solve's time is labelled cached, the cache line gives the
    look-up's time (not the proof's), and run.json keeps the two apart."""
    import cotm_bertini.analysis.certify.mechanism as certify_module
    from cotm_bertini.cli.main import main

    assert main(["solve", "case1", "--no-plots", "--quiet", "--out", str(tmp_path)]) == 0
    proof = certify_module.certify_table

    def slow_proof(*a, **k):
        time.sleep(1.0)
        return proof(*a, **k)

    monkeypatch.setattr(certify_module, "certify_table", slow_proof)
    capsys.readouterr()
    assert main(["certify", "case1", "--no-plots", "--out", str(tmp_path)]) == 0
    out, err = capsys.readouterr()
    rec = json.loads((tmp_path / "latest" / "run.json").read_text())
    cached = rec["cache"]
    assert cached["hit"] and "solve" not in rec["timings"] and "cache_lookup" in rec["timings"]
    first = f"(cached: {cached['solve_timings']['solve']:.2f} s when solved on {cached['solved']})"
    assert first in out.splitlines()[0]
    m = re.search(r"cache: answered .* in (\d+) ms; this command took ([\d.]+) s in all", err)
    assert m, err
    assert int(m.group(1)) < 1000 <= float(m.group(2)) * 1000


# ---- item 11: counts that each mean one thing ------------------------------------------------


def test_11_counts_each_mean_one_thing(case3):
    """Each count is one filter of the table; real and complex rows partition the solutions."""
    c, t = case3.counts, case3.table
    real = t.is_real.astype(bool)
    zero = t.reason == "zero_length_spring"
    assert "zero_length_artefacts" not in c
    assert c["zero_length_real"] == int((zero & real).sum()) > 0
    assert c["zero_length_complex"] == int((zero & ~real).sum()) > 0
    assert c["negative_d"] == int((t.reason == "negative_d").sum())
    assert c["complex"] == int((~real).sum())
    assert c["real"] == c["physical"] + c["negative_d"] + c["zero_length_real"]
    assert c["distinct_solutions"] == c["real"] + c["complex"] == len(t)


def test_11_docs_explain_every_count_and_paper_md_agrees(case3):
    """docs/columns.md explains each count; docs/paper.md quotes case 3's as the solver gives."""
    doc = (ROOT / "docs" / "columns.md").read_text()
    section = doc.split("## counts", 1)[1].split("\n## ", 1)[0]
    documented = re.findall(r"^\| `(\w+)` \|", section, flags=re.M)
    assert documented == list(case3.counts)
    paper = " ".join((ROOT / "docs" / "paper.md").read_text().split())
    for name in ("physical", "negative_d", "zero_length_real", "complex", "zero_length_complex"):
        m = re.search(rf"`{name}` (\d+)", paper)
        assert m and int(m.group(1)) == case3.counts[name], name
    c = case3.counts
    assert (
        f"{c['real']} real ({c['physical']} physical, {c['negative_d']} with a negative d, "
        f"{c['zero_length_real']} with a spring of zero length) and {c['complex']} complex "
        f"({c['zero_length_complex']} of them with a spring of zero length)"
    ) in paper


# ---- item 17: the barrier map says what its marks are ----------------------------------------


def test_17_barrier_map_title_names_the_saddle_marker_and_the_path_lines(case3_barriers):
    """The title names the colour and shape of the saddle and minimum markers and the colour of
    the descent lines, as drawn; the legend lists the paths."""
    from matplotlib.colors import to_rgb

    from cotm_bertini.plot.energy_map import barrier_figure

    b = case3_barriers
    fig = barrier_figure(b.params, b.solutions, b.paths, n=60)
    ax = fig.axes[0]
    title = ax.get_title()
    m = re.search(r"\((\w+) lines\) from each saddle \((\w+) (\w+)s\).*minima \((\w+) (\w+)s\)",
                  title)  # fmt: skip
    assert m, title
    line_colour, saddle_colour, saddle_shape, min_colour, min_shape = m.groups()
    paths = [ln for ln in ax.lines if (ln.get_gid() or "").startswith("descent-")]
    assert paths and all(np.allclose(to_rgb(ln.get_color()), to_rgb(line_colour)) for ln in paths)
    marks = {c.get_gid(): c for c in ax.collections if c.get_gid() in ("saddle", "min")}
    for kind, colour, other in (("saddle", saddle_colour, min_colour),
                                ("min", min_colour, saddle_colour)):  # fmt: skip
        face = marks[kind].get_facecolor()[0][:3]
        assert np.linalg.norm(face - to_rgb(colour)) < np.linalg.norm(face - to_rgb(other))
    corners = {"triangle": 3, "square": 4, "diamond": 4}
    for kind, shape in (("saddle", saddle_shape), ("min", min_shape)):
        vertices = len(np.unique(marks[kind].get_paths()[0].vertices.round(6), axis=0))
        assert vertices == corners[shape] if shape in corners else vertices > 8, (kind, shape)
    labels = [t.get_text() for legend in fig.legends for t in legend.get_texts()]
    assert any("descent path" in t for t in labels) and any("saddle" in t for t in labels)
