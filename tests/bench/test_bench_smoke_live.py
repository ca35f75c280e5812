"""The heavier half of the bench smoke runs (tests/bench/test_bench_smoke.py): the
benches that start live services or run the pipeline several times, in a
file of their own so that the two workers share the smoke runs."""
from __future__ import annotations

from pathlib import Path

import pytest

from test_bench_smoke import BENCHES, HEAVY, bench_cache, run_smoke  # noqa: F401  (bench_cache: a fixture)


def test_every_heavy_bench_exists() -> None:
    assert set(HEAVY) <= set(BENCHES), set(HEAVY) - set(BENCHES)


@pytest.mark.parametrize("bench", [b for b in BENCHES if b in HEAVY and b != "monitor_live_rclpy.py"])
def test_heavy_bench_runs_in_smoke_mode(bench: str, tmp_path: Path, bench_cache: Path) -> None:
    run_smoke(bench, tmp_path, bench_cache)


def test_the_rclpy_bench_runs_in_smoke_mode(tmp_path: Path, bench_cache: Path) -> None:
    """bench/monitor_live_rclpy.py needs ROS 2's Python (a real rclpy publisher): skipped, with the
    reason, without it; with it, the smoke run must hear every message it published."""
    from _ros2 import ros2_python
    ros2_python()
    out = run_smoke("monitor_live_rclpy.py", tmp_path, bench_cache)
    assert "lost 0;" in out and "decode errors 0;" in out and "p99" in out, out
