"""What ``mechcosim run`` prints for its headline quantities."""

from __future__ import annotations

from orchestrator.run_text import headline_line


def test_a_count_prints_without_a_unit_and_a_quantity_with_its_own() -> None:
    assert headline_line("impacts", {"value": 181.0, "unit": "1"}).split() == ["impacts", "181"]
    assert headline_line("armed", {"value": 1.0, "unit": "1"}).split() == ["armed", "1"]
    line = headline_line("arming_time", {"value": 0.05182838443522427, "unit": "s"})
    assert line.split() == ["arming_time", "0.05182838444", "s"]
    why = headline_line("not_armed_reason", {"value": "stalled", "unit": ""})
    assert why.split() == ["not_armed_reason", "stalled"]
