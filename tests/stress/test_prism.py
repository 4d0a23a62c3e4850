"""The spatial example (examples/prism.toml): its first solve tracks thousands of paths, so it
is marked slow: `make stress` runs it, `make test` deselects it; figures in docs/frameworks.md."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from framework_physics import prism_minima  # noqa: E402

import cotm_bertini as cb  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent.parent


@pytest.mark.slow
def test_every_minimum_random_descents_find_is_in_the_table():
    res = cb.solve(cb.Framework.from_toml(ROOT / "examples" / "prism.toml"))
    assert res.status == "ok", res.warnings
    stable = res.stable
    table = np.stack(
        [stable[[f"{n}.{a}" for a in "xyz"]].to_numpy() for n in "ABC"], axis=1
    )  # (rows, node, axis)
    minima = prism_minima()
    assert minima
    for nodes in minima:
        gap = np.abs(table - nodes[None]).max(axis=(1, 2))
        assert gap.min() < 1e-5, (nodes, table)
