"""The monitor's benchmark reports its figures (no speed assertion: that is relrl bench's)."""

from __future__ import annotations

import pytest

from bench.monitor_cost import bench_monitor

pytestmark = pytest.mark.slow  # every test here takes a second or more


def test_bench_monitor_reports_both_rates() -> None:
    fig = bench_monitor(200, repeats=1, rate=50)
    assert fig["steps_per_second_without"] > 0 and fig["steps_per_second_with"] > 0
    assert fig["ratio_range"][0] <= fig["ratio"] <= fig["ratio_range"][1]
    assert fig["pairs"] == 1
    assert fig["views_published"] >= 1  # the monitor really was fed
