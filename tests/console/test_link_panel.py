"""The link panel's figures: every fault the driver counts is on screen."""

from __future__ import annotations

from stairbot.console.widgets.link import health_text


def test_stray_replies_count_as_errors_and_duplicates_are_shown_when_there_are_any() -> None:
    _, quiet = health_text({"frames_per_s": 500.0, "lost": 0.0})
    assert "dup" not in quiet.plain
    _, faults = health_text({"frames_per_s": 500.0, "stray": 2.0, "crc_errors": 1.0,
                             "duplicates": 3.0, "late": 1.0})
    text = faults.plain
    assert "errors 3" in text and "late 1" in text and "dup 3" in text


def test_no_figures_yet_says_so() -> None:
    rates, _ = health_text({})
    assert "no link figures yet" in rates.plain


def test_the_cans_bus_state_error_frames_and_a_flood_are_on_screen() -> None:
    _, quiet = health_text({"frames_per_s": 500.0, "bus_state": 0.0, "flood_id": -1.0})
    assert "bus" not in quiet.plain and "flood" not in quiet.plain
    _, faults = health_text({"frames_per_s": 500.0, "error_frames": 4.0, "bus_state": 1.0,
                             "flood_id": 0.0})
    assert "errors 4" in faults.plain and "bus passive" in faults.plain
    assert "flood 0x000" in faults.plain
    _, off = health_text({"bus_state": 2.0, "flood_id": 0x1FFC0000})
    assert "BUS-OFF" in off.plain and "flood 0x1FFC0000" in off.plain


def test_a_bus_off_and_a_flood_lead_the_fault_line_so_80_columns_never_cut_them() -> None:
    # the link panel at 80x24 shows 39 characters of a line, and cuts the rest
    _, faults = health_text({"frames_per_s": 3.0, "error_frames": 123.0, "lost": 45.0,
                             "late": 67.0, "retries": 890.0, "duplicates": 12.0,
                             "bus_state": 2.0, "flood_id": 0x1FFC0000})
    seen = faults.plain[:39]
    assert "BUS-OFF" in seen and "flood 0x1FFC0000" in seen
    assert "errors 123" in faults.plain and "retries 890" in faults.plain
