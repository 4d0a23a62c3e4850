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
        "return document.getElementById('mech').data.filter(t => t.meta && t.meta.sid)"
        ".map(t => [t.meta.sid, t.meta.look, t.line.width])"
    )
    stable = set(rows.solution_id[rows.stable.astype(bool)])
    assert {look for _, look, _ in widths} == {"body", "bar", "spring"}
    bodies = [(sid, w) for sid, look, w in widths if look in ("body", "bar")]
    assert all((w >= 4) == (sid in stable) for sid, w in bodies)  # bodies and bars: wider
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
    folds = "; ".join(f"fold at y = {y:.5g}" for y in mv.snaps.y)  # the snaps' own y
    assert browser.find_element("css selector", "p.note").text == (
        f"state #1 moved along y: -0.8 -> 0.2 -> -0.8, 2 snaps ({folds})."
    )
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


# --- what the pages show a person ----------------------------------------------------------------

LOADED = ROOT / "tests" / "fixtures" / "zeeman_load.toml"  # Zeeman's wheel, a load on its rim
FX = 0.1  # the load's x component in the sweep below; its y component is swept
FYS = (-0.3, 0.0, 0.3)


@pytest.fixture(scope="module")
def loaded_sweep(tmp_path_factory):
    """A sweep of the rim's load (fx, fy) = (0.1, -0.3 .. 0.3): its table and its page."""
    out = tmp_path_factory.mktemp("loaded")
    fw = cb.Framework.from_toml(LOADED).replace(fx=FX)
    sw = cb.sweep(fw, "fy", np.array(FYS), out=out)
    return sw.table, sw.explore(out / "explore.html")


def _rects_overlap(a: dict, b: dict) -> bool:
    return not (a["right"] <= b["left"] or b["right"] <= a["left"] or a["bottom"] <= b["top"]
                or b["bottom"] <= a["top"])  # fmt: skip


def _rects(browser, selector: str) -> list[dict]:
    return browser.execute_script(
        "return Array.from(document.querySelectorAll(arguments[0])).map(e => {"
        "const r = e.getBoundingClientRect(); return {left: r.left, right: r.right, top: r.top,"
        "bottom: r.bottom, text: e.textContent}}).filter(r => r.right > r.left)",
        selector,
    )


@pytest.mark.parametrize("which", ["map", "sweep"])
def test_no_panel_title_lies_under_plotlys_toolbar(which, paper_map, loaded_sweep, browser):
    """With the pointer over each panel (its toolbar showing), no title (the drawing's, a
    figure's, a colour bar's) shares a pixel with a toolbar; the drawing's title says where."""
    from selenium.webdriver.common.action_chains import ActionChains

    page = paper_map[1] if which == "map" else loaded_sweep[1]
    _open(browser, page, f"titles-{which}.png")
    titles = _rects(browser, "#mech-title, .gtitle, .cbtitle, .g-gtitle")
    assert any(t["text"].startswith("L01 = " if which == "map" else "fy = ") for t in titles)
    for panel in ("main", "mech"):
        ActionChains(browser).move_to_element(browser.find_element("id", panel)).perform()
        bars = _rects(browser, f"#{panel} .modebar")
        assert bars, "no toolbar found"
        assert not [(t, b) for t in titles for b in bars if _rects_overlap(t, b)]
    browser.save_screenshot(str(ARTEFACTS / f"titles-{which}-hovered.png"))


def _lab(rgb) -> np.ndarray:
    """CIELAB (D65) of an sRGB colour 0-255: the usual formulas, written here."""
    c = np.asarray(rgb, float) / 255
    c = np.where(c > 0.04045, ((c + 0.055) / 1.055) ** 2.4, c / 12.92)
    xyz = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722],
                    [0.0193, 0.1192, 0.9505]]) @ c / [0.95047, 1.0, 1.08883]  # fmt: skip
    f = np.where(xyz > 0.008856, np.cbrt(xyz), 7.787 * xyz + 16 / 116)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


def test_each_stable_count_has_a_colour_of_its_own(paper_map, browser):
    """The map as shown: the pixels at the grid points of each stable count (read from the
    2-D sweep) share one colour, every two counts' colours differ by a CIELAB distance > 15,
    and the colour bar has one label a count. The palette's twelve classes differ alike."""
    import io

    from PIL import Image

    from cotm_bertini.plot.explore_pages import count_colour

    dm, page, table = paper_map
    _open(browser, page, "counts.png")
    stable = table[table.physical.astype(bool) & table.stable.astype(bool)]
    counts = np.bincount(stable.point, minlength=81)
    shot = Image.open(io.BytesIO(browser.get_screenshot_as_png())).convert("RGB")
    left, top = browser.execute_script(
        "const r = document.getElementById('main').getBoundingClientRect(); return [r.left, r.top]"
    )
    scale = browser.execute_script("return window.devicePixelRatio")
    seen: dict[int, list] = {}
    for k in range(81):
        i, j = divmod(k, 9)
        px, py = browser.execute_script(f"return window.explorer.pixel({i}, {j})")
        seen.setdefault(int(counts[k]), []).append(
            shot.getpixel((round((left + px) * scale), round((top + py) * scale)))
        )
    colour = {}
    for n, pixels in seen.items():
        values, freq = np.unique(np.array(pixels), axis=0, return_counts=True)
        colour[n] = values[np.argmax(freq)]
        assert freq.max() >= 0.6 * len(pixels), (n, pixels)  # fold dots cover a few
    assert len(colour) >= 3, colour
    gaps = [np.linalg.norm(_lab(colour[a]) - _lab(colour[b])) for a in colour for b in colour
            if a < b]  # fmt: skip
    assert min(gaps) > 15, (colour, gaps)
    bar = browser.execute_script("return document.getElementById('main').data[0].colorbar.ticktext")
    assert [int(t) for t in bar] == list(range(max(colour) + 1))
    palette = [_lab([int(count_colour(k)[i : i + 2], 16) for i in (1, 3, 5)]) for k in range(12)]
    assert min(np.linalg.norm(a - b) for n, a in enumerate(palette) for b in palette[n + 1 :]) > 15


@pytest.mark.parametrize("width", [1400, 1200, 900])
def test_the_table_is_whole_or_scrolls_in_its_box(width, loaded_sweep, browser):
    """At 1400, 1200 and 900 px, the page does not run past the window's right edge, and the
    table of the drawn equilibria (nine columns) is either whole inside its box or its box
    scrolls sideways."""
    _, page = loaded_sweep
    browser.set_window_size(width, 1000)
    try:
        _open(browser, page, f"table-{width}.png")
        got = browser.execute_script(
            "const b = document.getElementById('table-box'), t = document.getElementById('rows');"
            "return {view: document.documentElement.clientWidth,"
            "page: document.documentElement.scrollWidth, box: b.getBoundingClientRect().right,"
            "inner: b.clientWidth, wide: t.scrollWidth, overflow: getComputedStyle(b).overflowX,"
            "cells: t.querySelectorAll('td').length}"
        )
    finally:
        browser.set_window_size(1300, 1000)
    assert got["cells"] > 0
    assert got["page"] <= got["view"] and got["box"] <= got["view"], got
    assert got["wide"] <= got["inner"] or got["overflow"] in ("auto", "scroll"), got


def test_the_drawing_tells_bars_springs_cables_and_loads_apart(loaded_sweep, browser):
    """The loaded wheel at each sweep point: the wheel thick and solid, the spring a zigzag
    between its ends, the cable dashed, a key to them in the legend; the load an arrow whose
    head is at the rim (from the row's wheel angle, by the file's geometry) along (fx, fy)."""
    from selenium.webdriver.common.keys import Keys

    table, page = loaded_sweep
    _open(browser, page, "loaded.png")
    slider = browser.find_element("id", "slider")
    for k, fy in enumerate(FYS):
        if k:
            slider.send_keys(Keys.ARROW_RIGHT)
        rows = _rows_at(table, k)
        data = browser.execute_script("return document.getElementById('mech').data")
        looks = {}
        for t in data:
            if t.get("meta", {}).get("look"):
                looks.setdefault(t["meta"]["look"], []).append(t)
        assert {t["line"]["dash"] for t in looks["cable"]} == {"dash"}
        assert min(t["line"]["width"] for t in looks["body"]) >= 3
        assert max(t["line"]["width"] for t in looks["spring"] + looks["cable"]) <= 2
        assert {t["meta"]["key"] for t in data if "key" in t.get("meta", {})} == {
            "bar", "spring", "cable", "load"}  # fmt: skip
        arrows = browser.execute_script("return document.getElementById('mech').layout"
                                        ".annotations || []")  # fmt: skip
        band_u = [t for t in looks["spring"] if t["meta"]["element"] == "band_u"]
        assert len(arrows) == len(rows) == len(band_u)
        for (_, row), spring in zip(rows.iterrows(), band_u, strict=True):
            theta = np.radians(row["wheel.angle_deg"])
            rim = np.array([1.0 + 0.5 * np.cos(theta), 0.5 * np.sin(theta)])
            xy = np.array([spring["x"], spring["y"]]).T
            ends = np.array([xy[0], xy[-1]])
            assert np.abs(ends - [rim, [0.1, -0.25]]).max() < 1e-5  # ground.u = (x, y)
            axis = (ends[1] - ends[0]) / np.linalg.norm(ends[1] - ends[0])
            off = np.abs((xy - ends[0]) @ [-axis[1], axis[0]])
            assert len(xy) > 10 and off.max() > 0.01  # teeth across the spring
            (arrow,) = [a for a in arrows if np.hypot(a["x"] - rim[0], a["y"] - rim[1]) < 1e-5]
            along = np.array([arrow["x"] - arrow["ax"], arrow["y"] - arrow["ay"]])
            force = np.array([FX, fy])
            assert np.abs(along / np.linalg.norm(along) - force / np.linalg.norm(force)).max(
            ) < 1e-5  # fmt: skip
        assert any(a["text"] == f"hand {np.hypot(FX, fy):.3g}" for a in arrows), [
            a["text"] for a in arrows
        ]
    browser.save_screenshot(str(ARTEFACTS / "loaded-end.png"))
