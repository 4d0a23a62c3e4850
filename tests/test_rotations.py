"""Rigid bodies turning in space on the real route (boxsearch/rotations.py: SO(3) by four
quaternion charts), against a statics written in numpy in tests/so3_statics.py (no package code):
Newton on SO(3) from thousands of random rotations, each critical point with its index; on
random bodies nobody chose (body points, ground points, stiffnesses, free lengths, a cable, a
load anywhere)."""

from __future__ import annotations

import numpy as np
import pytest
import so3_statics
from conftest import ROOT

import cotm_bertini as cb

# examples/ball_joint.toml, its numbers written out again here: the mast's points about the
# pivot at the origin, each spring (kind, body point, ground point, k, L0), no load.
BALL_JOINT = {
    "pivot": np.zeros(3),
    "links": [("spring", [0.5, 0.0, 1.0], [1.1, 0.3, 0.9], 1.0, 0.4),
              ("spring", [-0.5, 0.0, 1.0], [-0.8, 0.7, 0.6], 1.0, 0.5),
              ("spring", [0.0, 0.0, 1.2], [0.4, -1.5, 1.2], 0.8, 0.6)],
    "loads": [],
}  # fmt: skip


def _random(rng: np.random.Generator) -> tuple[str, dict]:
    """A body on a ball joint at a random pivot, three springs (the last a cable or a spring)
    from body points to ground points, a load on a fourth point: its file and its statics."""
    pivot = rng.uniform(-0.5, 0.5, 3).round(3)
    points = {f"p{i}": rng.uniform(-1.0, 1.0, 3).round(3) for i in range(4)}
    ground = {f"g{i}": (pivot + rng.uniform(-2.0, 2.0, 3)).round(3) for i in range(3)}
    kinds = ["spring", "spring", str(rng.choice(["spring", "cable"]))]
    links = [(kinds[i], f"p{i}", f"g{i}", round(float(rng.uniform(0.5, 2.0)), 3),
              round(float(rng.uniform(0.2, 1.2)), 3)) for i in range(3)]  # fmt: skip
    force = rng.uniform(-0.6, 0.6, 3).round(3)
    vec = lambda v: "[" + ", ".join(repr(float(x)) for x in v) + "]"  # noqa: E731
    text = ['name = "random_body"', "dim = 3", "[ground]", f"o = {vec(pivot)}"]
    text += [f"{g} = {vec(p)}" for g, p in ground.items()]
    text += ["[bodies.b]", "o = [0.0, 0.0, 0.0]"] + [f"{n} = {vec(p)}" for n, p in points.items()]
    text += ["[[pins]]", 'a = "b.o"', 'b = "ground.o"']
    for i, (kind, p, g, k, L0) in enumerate(links):
        text += [f"[[{kind}s]]", f'name = "l{i}"', f'a = "b.{p}"', f'b = "ground.{g}"', f"k = {k}",
                 f"L0 = {L0}"]  # fmt: skip
    text += ["[[loads]]", 'name = "f"', 'point = "b.p3"', f"force = {vec(force)}"]
    body = {"pivot": pivot,
            "links": [(kind, points[p], ground[g], k, L0) for kind, p, g, k, L0 in links],
            "loads": [(points["p3"], force)]}  # fmt: skip
    return "\n".join(text) + "\n", body


def _rows(r, body: str = "b") -> tuple[np.ndarray, np.ndarray]:
    """(rotations, Hessian indices) of a solve's physical rows."""
    t = r.table[r.table["physical"].astype(bool)]
    q = np.stack([t[f"{body}.q{a}"].to_numpy(float) for a in "wxyz"], axis=1)
    return so3_statics.rotation(q), t["index"].to_numpy(int)


@pytest.mark.parametrize("seed", [3, 11, pytest.param(17, marks=pytest.mark.slow),
                                  pytest.param(29, marks=pytest.mark.slow)])  # fmt: skip
def test_random_body_on_a_ball_joint(seed: int, tmp_path) -> None:
    """Every critical point Newton on SO(3) finds is a row, with its index; every row is a
    critical point of the numpy statics; each rotation once (q and -q one row); the search
    proved, and the Morse sum on SO(3) is 0."""
    rng = np.random.default_rng(seed)
    text, body = _random(rng)
    path = tmp_path / "body.toml"
    path.write_text(text)
    r = cb.solve(cb.Framework.from_toml(path), settings=cb.Settings(route="real", workers=1))
    assert r.status == "ok", r.warnings
    _agree(r, body, seed)


def test_ball_joint_example() -> None:
    """examples/ball_joint.toml: its 4 equilibria, proved, are the statics'."""
    r = cb.solve(cb.Framework.from_toml(ROOT / "examples" / "ball_joint.toml"),
                 settings=cb.Settings(route="real", workers=1))  # fmt: skip
    assert r.status == "ok", r.warnings
    _agree(r, BALL_JOINT, 0, "mast")
    assert list(r.table["kind"]) == ["min", "saddle", "saddle", "max"]


def _agree(r, body: dict, seed: int, name: str = "b") -> None:
    """The solve's rows against the numpy statics' critical points (and the Morse sum)."""
    rows, index = _rows(r, name)
    found, expected = so3_statics.critical_points(body, 3000, seed)
    assert len(found) >= 4  # the statics' own sanity: a min, a max and saddles at least
    for R, i in zip(found, expected, strict=True):
        gap = np.abs(rows - R).max(axis=(1, 2))
        assert gap.min() < 1e-7, f"the statics' critical point of index {i} is not a row"
        assert index[gap.argmin()] == i
    _, g, _ = so3_statics.derivatives(body, rows)
    assert np.abs(g).max() < 1e-8  # every row is a critical point of the statics
    assert len(rows) == len(found)  # and none twice
    assert r.morse["applicable"] and r.morse["ok"] and r.morse["expected"] == 0


def test_uncovered_spatial_body_is_refused(tmp_path) -> None:
    """A body that no pin holds is not on SO(3): the real route says why in one line."""
    text, _ = _random(np.random.default_rng(5))
    path = tmp_path / "loose.toml"
    path.write_text(text.replace('[[pins]]\na = "b.o"\nb = "ground.o"\n', ""))
    with pytest.raises(ValueError, match="pinned nowhere"):
        cb.solve(cb.Framework.from_toml(path), settings=cb.Settings(route="real"))


def test_a_spring_that_can_collapse_takes_the_complex_route(tmp_path) -> None:
    """A spring of a body in space that can reach zero length (its anchor as far from the pivot
    as its body point): the real route does not enclose its cone, so it is not the default, and
    asking for it is refused in one line naming the spring."""
    from cotm_bertini.routes import choose

    text = (ROOT / "examples" / "ball_joint.toml").read_text()
    # mast.left is at |(0.5, 0, 1)| = sqrt(1.25) from the pivot; so is this anchor
    path = tmp_path / "collapsing.toml"
    path.write_text(text.replace("a = [1.1, 0.3, 0.9]", "a = [0.5, 1.0, 0.0]"))
    fw = cb.Framework.from_toml(path)
    assert choose(fw, cb.Settings()).route == "homotopy"
    with pytest.raises(ValueError, match="spring sa of a body in space can reach zero length"):
        cb.solve(fw, route="real")
