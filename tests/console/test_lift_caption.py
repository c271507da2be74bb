"""Issue 35, defect 8: the side view's caption read ``MTB -0 mm`` for a lift
a fraction of a millimetre below segment 2: a sign for nothing."""

from __future__ import annotations

import pytest

from stairbot.console.widgets.picture import lift_mm


@pytest.mark.parametrize("offset_m", [-0.0003, -0.0, 0.0, 0.0004])
def test_a_lift_offset_that_rounds_to_nothing_has_no_minus(offset_m: float) -> None:
    assert lift_mm(offset_m).strip() == "+0"


def test_a_lift_offset_keeps_its_sign_and_width() -> None:
    assert lift_mm(0.19) == "+190"
    assert lift_mm(-0.0006) == "  -1"
    assert lift_mm(-0.012) == " -12"
