"""Explorer pages (explore.html): one offline file whose drawings are the run's own tables, checked
against an independent kinematics (tests/physics.py), then in a real browser: Debian's
Chromium driven by selenium, clicking the map and moving the sliders. Screenshots go to
runs/test-artefacts/ (or $COTM_TEST_ARTEFACTS)."""

from __future__ import annotations

import base64
import json
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import run_cli
from physics import points as independent_points

import cotm_bertini as cb
from cotm_bertini.analysis.classify import read_table

ROOT = Path(__file__).resolve().parent.parent
ARTEFACTS = Path(os.environ.get("COTM_TEST_ARTEFACTS", ROOT / "runs" / "test-artefacts"))
pytestmark = pytest.mark.xdist_group("zeeman-map")  # as tests/test_motion.py: one cache


def page_data(path: Path) -> dict:
    """The data the page carries (its JSON block), decoded."""
    text = path.read_text()
    block = re.search(r'<script id="data" type="application/json">(.*?)</script>', text, re.S)
    return json.loads(block.group(1).replace("<\\/", "</"))


def floats(b64: str) -> np.ndarray:
    return np.frombuffer(base64.b64decode(b64), dtype="<f4")


def _rows_at(table, point: int):
    phys = table[table.physical.astype(bool)]
    return phys[phys.point == point].sort_values("solution_id")


@pytest.fixture(scope="module")
def paper_map(tmp_path_factory):
    dm = cb.design_map(cb.Params(), (0, 14), (0, 14), 9)
    page = dm.explore(tmp_path_factory.mktemp("explore") / "explore.html")
    return dm, page, read_table(Path(dm.record["sweep_folder"]) / "sweep.csv")


def test_the_map_page_is_one_offline_file_of_the_maps_own_equilibria(paper_map):
    """No external script, style or image; every grid point carries exactly its physical rows
    of the 2-D sweep (ids, kinds), and their drawn points are the independent kinematics'."""
    dm, page, table = paper_map
    text = page.read_text()
    assert not re.search(r"<(script|link|img|iframe)[^>]*\s(src|href)\s*=", text)
    data = page_data(page)
    moving = data["moving"]
    assert sorted(moving) == [3, 4, 5] and set(data["fixed"]) == {"0", "1", "2"}  # P1-P3 still
    coords = np.zeros((len(data["sid"]), 6, 2))
    coords[:, moving] = floats(data["coords"]).reshape(-1, len(moving), 2)
    for p, xy in data["fixed"].items():
        coords[:, int(p)] = xy
    assert len(data["xs"]) == len(data["ys"]) == 9
    for k in range(81):
        rows = _rows_at(table, k)
        start, count = data["start"][k], data["count"][k]
        assert count == len(rows)
        sids = data["sid"][start : start + count]
        assert sorted(sids) == rows.solution_id.tolist()
        kinds = {"min": 0, "saddle": 1, "max": 2}
        by_id = dict(zip(rows.solution_id, rows.kind, strict=True))
        assert [kinds.get(by_id[s], 3) for s in sids] == data["kind"][start : start + count]
        for n, sid in enumerate(sids):
            row = rows[rows.solution_id == sid].iloc[0]
            p = cb.Params(L01=row.L01, L02=row.L02)
            ref = independent_points(p, np.radians(row.gamma1_deg), np.radians(row.gamma2_deg))
            want = np.array([[0.0, 0.0], *[ref[i] for i in range(2, 7)]])
            assert np.abs(coords[start + n] - want).max() < 1e-5 * p.L3


# --- in a real browser ---------------------------------------------------------------------------


@pytest.fixture(scope="module")
def browser():
    """Headless Debian Chromium through its ChromeDriver (selenium), console logs kept."""
    chromium, driver = shutil.which("chromium"), shutil.which("chromedriver")
    if not (chromium and driver):
        pytest.skip("no chromium and chromedriver on PATH: `make browser` (part of `make test`) "
                    "installs Debian's")  # fmt: skip
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = chromium
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
                "--no-first-run", "--disable-background-networking", "--disable-sync",
                "--disable-component-update", "--window-size=1300,1000"):  # fmt: skip
        opts.add_argument(arg)
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    d = webdriver.Chrome(service=Service(driver), options=opts)
    yield d
    d.quit()


def _open(browser, page: Path, shot: str):
    browser.get(page.resolve().as_uri())
    assert browser.execute_script("return !!window.explorer"), "the page's script did not run"
    errors = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
    assert not errors, errors
    ARTEFACTS.mkdir(parents=True, exist_ok=True)
    browser.save_screenshot(str(ARTEFACTS / shot))


def test_a_click_on_the_map_draws_that_grid_points_equilibria(paper_map, browser):
    """A real mouse click on the grid point with the most equilibria: the drawing holds the
    2-D sweep's physical rows there (ids and kinds), stable ones bold."""
    from selenium.webdriver.common.action_chains import ActionChains

    dm, page, table = paper_map
    _open(browser, page, "map.png")
    counts = [len(_rows_at(table, k)) for k in range(81)]
    k = int(np.argmax(counts))
    i, j = divmod(k, 9)
    main = browser.find_element("id", "main")
    px, py = browser.execute_script(f"return window.explorer.pixel({i}, {j})")
    size = main.size
    ActionChains(browser).move_to_element_with_offset(
        main, int(px - size["width"] / 2), int(py - size["height"] / 2)
    ).click().perform()
    drawn = browser.execute_script("return window.explorer.drawn()")
    rows = _rows_at(table, k)
    assert sorted(d["solution_id"] for d in drawn) == rows.solution_id.tolist()
    by_id = dict(zip(rows.solution_id, rows.kind, strict=True))
    assert all(d["kind"] == by_id[d["solution_id"]] for d in drawn)
    widths = browser.execute_script(
        "return document.getElementById('mech').data.map(t => [t.meta.sid, t.line.width])"
    )
    stable = set(rows.solution_id[rows.stable.astype(bool)])
    assert all((w >= 4) == (sid in stable) for sid, w in widths)
    browser.save_screenshot(str(ARTEFACTS / "map-clicked.png"))


def test_the_sweep_slider_draws_the_angles_of_each_point(browser, tmp_path):
    """The paper's L01 sweep: each arrow key on the slider draws the next point's equilibria,
    whose rod angles (P1 -> P4, read back from the drawing) are the sweep's gamma1."""
    from selenium.webdriver.common.keys import Keys

    sw = cb.sweep(cb.Params(), "L01", np.linspace(0.0, 12.0, 7), out=tmp_path)
    page = sw.explore(tmp_path / "explore.html")
    _open(browser, page, "sweep.png")
    slider = browser.find_element("id", "slider")
    table = sw.table
    for k in range(7):
        if k:
            slider.send_keys(Keys.ARROW_RIGHT)
        drawn = browser.execute_script("return window.explorer.drawn()")
        rows = _rows_at(table, k)
        assert len(drawn) == len(rows)
        got = sorted(np.degrees(np.arctan2(d["points"][3][1], d["points"][3][0])) % 360
                     for d in drawn)  # fmt: skip
        want = sorted(rows.gamma1_deg % 360)
        assert np.abs(np.array(got) - np.array(want)).max() < 1e-3
    browser.save_screenshot(str(ARTEFACTS / "sweep-end.png"))


def test_the_move_slider_draws_the_followed_state(browser, tmp_path):
    """Zeeman's loop: at each step the slider reaches, the drawn rim is the trajectory's."""
    from selenium.webdriver.common.keys import Keys

    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman.toml").replace(x=0.1, y=-0.8)
    mv = cb.move(cb.solve(fw), 1, {"y": [-0.8, 0.2, -0.8]}, steps=10)
    page = mv.explore(tmp_path / "explore.html")
    _open(browser, page, "move.png")
    slider = browser.find_element("id", "slider")
    rim = page_data(page)["skeleton"]["points"].index("wheel.rim")
    for k in range(len(mv.table)):
        if k:
            slider.send_keys(Keys.ARROW_RIGHT)
        (drawn,) = browser.execute_script("return window.explorer.drawn()")
        row = mv.table.iloc[k]
        assert np.abs(np.array(drawn["points"][rim]) - [row["wheel.rim.x"], row["wheel.rim.y"]]
                      ).max() < 1e-5  # fmt: skip


def test_a_two_parameter_sweep_page_is_refused_before_any_work(tmp_path):
    """`sweep --param2 ... --html`: one line, exit 2, nothing written (a map's page does it)."""
    done = run_cli("sweep", "--param", "L01", "--from", "0", "--to", "1", "--points", "2",
                   "--param2", "L02", "--from2", "0", "--to2", "1", "--points2", "2", "--html",
                   "--out", str(tmp_path / "w"))  # fmt: skip
    assert done.returncode == 2 and done.stderr.count("\n") == 1 and "--html" in done.stderr
    assert not (tmp_path / "w").exists()


def test_a_plans_page_walks_its_move_over_the_map(browser, tmp_path):
    """A plan between Zeeman's states: its path on the map, and the slider walks the move that
    checks it: each step's drawn rim is the trajectory's, the map's marker at its (x, y)."""
    from selenium.webdriver.common.keys import Keys

    fw = cb.Framework.from_toml(ROOT / "examples" / "zeeman.toml").replace(x=0.1, y=-0.25)
    res = cb.solve(fw)
    a, b = res.stable.solution_id.tolist()
    pl = cb.plan(res, a, b, ("x", (-0.6, 0.8), "y", (-0.8, 0.2)), points=15)
    assert pl.status == "ok"
    page = pl.explore(tmp_path / "explore.html")
    _open(browser, page, "plan.png")
    names = browser.execute_script("return document.getElementById('main').data.map(t => t.name)")
    assert "plan" in names
    slider = browser.find_element("id", "slider")
    rim = page_data(page)["skeleton"]["points"].index("wheel.rim")
    for k in range(1, len(pl.move.table), 7):  # the first key press starts the walk
        while int(slider.get_attribute("value")) < k:
            slider.send_keys(Keys.ARROW_RIGHT)
        (drawn,) = browser.execute_script("return window.explorer.drawn()")
        row = pl.move.table.iloc[k]
        assert np.abs(np.array(drawn["points"][rim]) - [row["wheel.rim.x"], row["wheel.rim.y"]]
                      ).max() < 1e-5  # fmt: skip
        shape = browser.execute_script("return document.getElementById('main').layout.shapes[0]")
        centre = [(shape["x0"] + shape["x1"]) / 2, (shape["y0"] + shape["y1"]) / 2]
        assert np.abs(np.array(centre) - [row.x, row.y]).max() < 1e-9
    browser.save_screenshot(str(ARTEFACTS / "plan-walked.png"))


def test_a_path_drawn_on_the_map_gives_the_command_that_moves_along_it(paper_map, browser):
    """Drawing: three clicks add three waypoints (grid points), a dashed path appears, and the
    page writes the `move` command for it, with the stable ids at its start."""
    from selenium.webdriver.common.action_chains import ActionChains

    dm, page, table = paper_map
    _open(browser, page, "map-draw.png")
    browser.find_element("id", "draw").click()
    main = browser.find_element("id", "main")
    picks = [(2, 2), (6, 2), (6, 5)]
    for i, j in picks:
        px, py = browser.execute_script(f"return window.explorer.pixel({i}, {j})")
        ActionChains(browser).move_to_element_with_offset(
            main, int(px - main.size["width"] / 2), int(py - main.size["height"] / 2)
        ).click().perform()
    xs, ys = page_data(page)["xs"], page_data(page)["ys"]
    assert browser.execute_script("return window.explorer.drawing()") == [
        [xs[i], ys[j]] for i, j in picks
    ]
    names = browser.execute_script("return document.getElementById('main').data.map(t => t.name)")
    assert names.count("drawn path") == 1  # one trace, redrawn at each click
    command = browser.find_element("id", "command").text
    l01 = ",".join(f"{xs[i]:g}" for i, _ in picks)
    assert command.startswith("cotm-bertini move --set L01=") and f"--path L01={l01}" in command
    rows = _rows_at(table, picks[0][0] * 9 + picks[0][1])
    stable = ", ".join(str(s) for s in rows.solution_id[rows.stable.astype(bool)])
    assert f"({stable})" in command
    browser.save_screenshot(str(ARTEFACTS / "map-drawn.png"))
