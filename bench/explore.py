"""The explorer page of the paper's map: its size and the time headless Chromium takes to open it
(issue targets: a 101 x 101 map, page <= 15 MB, open in <= 3 s), and the map's own time.

Usage: .venv/bin/python bench/explore.py [--points N] [--map FOLDER]
  --map FOLDER: a saved map (runs/map/latest) instead of making one (the 101 x 101 map takes
  minutes; `make explore` writes one with its page). Without it the map is made in an empty
  cache, end to end (fold curves, their generic sets and the 2-D sweep).
Benchmarks, not tests: nothing is asserted; targets are printed beside the measurements.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import tempfile
import time
from pathlib import Path

SIZE_TARGET_MB, OPEN_TARGET_S = 15.0, 3.0


def _map(points: int, folder: str | None):
    if folder is None:  # an empty cache: a cached 2-D sweep would be resumed, not solved
        import os

        os.environ["COTM_CACHE"] = tempfile.mkdtemp(prefix="explore-bench-cache-")
    import cotm_bertini as cb
    from cotm_bertini.api.maps import DesignMap
    from cotm_bertini.params import Params

    if folder is None:
        t0 = time.perf_counter()
        dm = cb.design_map(cb.Params(), (0, 14), (0, 14), points, workers=2)
        return dm, time.perf_counter() - t0
    import pandas as pd

    base = Path(folder).resolve()
    record = json.loads((base / "run.json").read_text())
    record["sweep_folder"] = str(base / record["sweep_folder"])
    params = Params(**record["params"])
    folds, regions = pd.read_csv(base / "folds.csv"), pd.read_csv(base / "regions.csv")
    return DesignMap(params, folds, regions, record), None


def _open_times(page: Path, repeats: int = 3) -> list[float]:
    """Seconds from navigation start until the page's script has drawn (window.explorer)."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = shutil.which("chromium")
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-quic",
                "--no-first-run", "--disable-background-networking", "--disable-sync",
                "--disable-component-update", "--window-size=1300,1000"):  # fmt: skip
        opts.add_argument(arg)
    d = webdriver.Chrome(service=Service(shutil.which("chromedriver")), options=opts)
    try:
        out = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            d.get(page.resolve().as_uri())  # returns once the load event has fired
            d.execute_script("return window.explorer.drawn().length")
            out.append(time.perf_counter() - t0)
        return out
    finally:
        d.quit()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=101)
    ap.add_argument("--map", help="a saved map folder (run.json, folds.csv, regions.csv, sweep/)")
    args = ap.parse_args()
    dm, map_seconds = _map(args.points, args.map)
    page = Path(tempfile.mkdtemp(prefix="explore-bench-")) / "explore.html"
    t0 = time.perf_counter()
    dm.explore(page)
    write = time.perf_counter() - t0
    size = page.stat().st_size / 1e6
    times = _open_times(page)
    n = len(dm.regions)
    print(
        f"paper map {int(n**0.5)} x {int(n**0.5)}"
        + (f": made in {map_seconds:.1f} s (target 60 s for 101 x 101)" if map_seconds else "")
    )
    print(f"page written in {write:.1f} s: {size:.2f} MB (target <= {SIZE_TARGET_MB:g} MB)")
    print(
        f"opened in headless Chromium in {statistics.median(times):.2f} s (median of "
        f"{len(times)}: {', '.join(f'{t:.2f}' for t in times)}; target <= {OPEN_TARGET_S:g} s)"
    )


if __name__ == "__main__":
    main()
