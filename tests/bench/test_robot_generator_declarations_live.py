"""The declarations of generated robots judged live, on the run's log and on its bag (issue 106: "0 false
declarations"; bench/_robot_declarations.py, docs/monitors.md "Generated robots").  Two robots run
through bench/_robot_run.py side by side (real rclpy nodes, the DDS source, 2.5 s of sensing each): seed
855 of 5 nodes, correct, every declaration ``true`` on every path (periods in time and in steps,
``initially``, ``progress``); seed 855 of 6 nodes with its seeded defect, Sensor3 silent once for longer
than its declared period, ``periodic`` ``false`` at that sensor on every path and every other
declaration ``true`` (the control).  Live = log = bag declaration by declaration."""
from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench"))

pytestmark = pytest.mark.live


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> dict[bool, dict[str, Any]]:
    """Both robots run at once, each in its own DDS domain and processes (the module's time is the
    longer run's, not the two's sum), by ``defect``."""
    from concurrent.futures import ThreadPoolExecutor

    from _ros2 import robot_run
    with ThreadPoolExecutor(2) as pool:
        done = {defect: pool.submit(robot_run, tmp_path_factory.mktemp("seeded" if defect else "correct"), 855,
                                    6 if defect else 5, 2.5, defect) for defect in (False, True)}
        return {defect: f.result() for defect, f in done.items()}


def _declared(n: dict[str, Any]) -> list[str]:
    """The declarations of node spec ``n`` as the judge's rows name them."""
    if n["kind"] == "sensor":
        return ["initially 1", f"periodic out.{'cells' if n['sensor_kind'] in ('arr', 'scan') else 'x'}"]
    if n.get("period_steps"):
        return ["periodic out." + ("r" if n["kind"] == "relay" else "high" if n["op"] == "ge" else "low")]
    return ["progress"] if n.get("progress_steps") or n.get("eventually") else []


def _verdicts(res: dict[str, Any]) -> dict[str, dict[tuple[str, str], str]]:
    """Per path, each declaration's verdict by (node, declaration)."""
    return {path: {(node, what): str(row["verdict"]) for (node, what, _), row in d.items()}
            for path, d in res["declarations"].items()}


def test_the_declarations_of_a_correct_robot_hold_on_every_path(runs: dict[bool, dict[str, Any]]) -> None:
    res = runs[False]
    got = _verdicts(res)
    nodes = {n["name"]: n for n in res["spec"]["nodes"]}
    expected = {(name, what) for name, n in nodes.items() for what in _declared(n)}
    assert len(expected) >= 7
    for path in ("live", "log", "bag"):
        assert set(got[path]) == expected, path
        assert set(got[path].values()) == {"true"}, (path, got[path], res["declarations"][path])
    assert res["findings"] == [] and res["errors"] == [], res["findings"] + res["errors"]


def test_a_sensor_silent_past_its_declared_period_is_red_there_only(runs: dict[bool, dict[str, Any]]) -> None:
    res = runs[True]
    victim = next(n for n in res["spec"]["nodes"] if n.get("defect"))
    assert (victim["name"], victim["defect_kind"]) == ("Sensor3", "skip")
    for path, got in _verdicts(res).items():
        assert got[("Sensor3", "periodic out.cells")] == "false", (path, res["declarations"][path])
        others = {k: v for k, v in got.items() if k != ("Sensor3", "periodic out.cells")}
        assert len(others) >= 8 and set(others.values()) == {"true"}, (path, others)
    assert res["findings"] == [] and res["errors"] == [], res["findings"] + res["errors"]
