"""The paper's mechanism (cb.Params) as a framework, so that the general routes solve it too.

examples/cotm.toml is the same description as a file (tests/test_paper_real.py checks that the
two agree). The top body's angle is absolute, like the paper's gamma2: rod.angle_deg is gamma1
and top.angle_deg is gamma2.
"""

from __future__ import annotations

from ...params import Params
from .spec import Framework, from_dict

# Points follow model/kinematics.py: P1 at the origin, P2 = [p2x, 0], P3 = [p3x, p3y] on the
# ground; the rod from P1 to P4 = L3 [cos gamma1, sin gamma1]; the top body's frame at P4, with
# P6 = [p6x, 0] and P5 = [p5x, p5y] in it; spring 1 joins 2-6 and spring 2 joins 3-5.
LAYOUT = {
    "name": "cotm",
    "dim": 2,
    "ground": {"p1": [0.0, 0.0], "p2": ["p2x", 0.0], "p3": ["p3x", "p3y"]},
    "bodies": {
        "rod": {"p1": [0.0, 0.0], "p4": ["L3", 0.0]},
        "top": {"p4": [0.0, 0.0], "p6": ["p6x", 0.0], "p5": ["p5x", "p5y"]},
    },
    "pins": [{"a": "rod.p1", "b": "ground.p1"}, {"a": "top.p4", "b": "rod.p4"}],
    "springs": [
        {"name": "spring1", "a": "ground.p2", "b": "top.p6", "k": "k1", "L0": "L01"},
        {"name": "spring2", "a": "ground.p3", "b": "top.p5", "k": "k2", "L0": "L02"},
    ],
}

# The framework's body angles that are the paper's gamma1 and gamma2, in that order.
ANGLE_COLUMNS = ("rod.angle_deg", "top.angle_deg")


def paper_framework(params: Params) -> Framework:
    """The paper's mechanism with the values of `params` as a cb.Framework (its parameters are
    Params' fields, so a sweep or a `replace` names them alike)."""
    return from_dict({**LAYOUT, "parameters": params.as_dict()}, source="cb.Params")
