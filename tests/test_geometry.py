"""Parameter validation and loading."""

from __future__ import annotations

import math

import pytest

from cotm_bertini.params import TABLE1, ParameterError, make_params, parse_assignment


def test_presets_only_set_free_lengths():
    """A case preset changes L01/L02 and nothing else; ZFL follows from L0 = 0."""
    for case, (l01, l02) in {"case1": (0, 0), "case2": (11.5, 0), "case3": (11.5, 11.5)}.items():
        p = make_params(case)
        assert (p.L01, p.L02) == (l01, l02)
        assert p.zfl == (l01 == 0, l02 == 0)
        assert all(getattr(p, k) == v for k, v in TABLE1.items() if k not in ("L01", "L02"))


@pytest.mark.parametrize(
    ("overrides", "needle"),
    [
        ({"k1": -1}, "k1 = -1.0"),
        ({"k2": 0}, "k2 = 0.0"),
        ({"L3": 0}, "L3 = 0.0"),
        ({"L01": -0.1}, "L01 = -0.1"),
        ({"p2x": math.inf}, "p2x = inf"),
        ({"p3x": 3.1875, "p3y": 0.0}, "point 3 coincides with point 2"),
        ({"p5x": 4.25, "p5y": 0.0}, "point 5 coincides with point 6"),
        ({"nope": 1}, "nope: unknown parameter"),
    ],
)
def test_invalid_values_name_the_field(overrides, needle):
    """Each bad value raises one ParameterError naming the field and the value."""
    with pytest.raises(ParameterError) as info:
        make_params("case1", overrides)
    assert needle in str(info.value)
    assert "\n" not in str(info.value)


def test_parse_assignment():
    """--set NAME=VALUE parsing."""
    assert parse_assignment("L01 = 2.5") == ("L01", 2.5)
    with pytest.raises(ParameterError, match="expected NAME=VALUE"):
        parse_assignment("L01")
