"""The live command's process ends once everything it writes is written (docs/monitors.md, "Stopping";
``runtime/stopping.py``, :func:`end_bounded`), whatever a library leaves behind.

Each case runs a small Python program in a process of its own that writes a file, then leaves
something that would hold the interpreter's exit, then calls :func:`end_bounded` as the live command's
process does once its run is over; its control is the same program without the call, which is still
running seconds later (then killed):

* a thread that is not a daemon and never ends (the interpreter joins it without a limit): the process
  ends at once with the run's exit code and names the thread on stderr;
* an object whose deletion at the interpreter's finalization blocks (as a library's object deleted with
  its module may): the process ends within the bound with status 1 and every thread's stack on stderr,
  naming what held it.

And a ROS 1 run (a master on 127.0.0.1, nothing published) stopped by SIGINT and by SIGTERM beside a
CPU burner ends within :data:`STOP_LIMIT_S` of the signal, its log read line by line and its evidence
written; the ROS 2 sources' stops are tests/runtime/test_live_stops.py's."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
from _procs import stop, wait_for

from rclverify.cli.monitor_live import _command_line
from rclverify.runtime.ros1 import LocalMaster, RosUnavailable, import_rospy

REPO = Path(__file__).resolve().parents[2]
#: the longest a stopped live run may take to exit, from the signal (s): measured 0.60-0.72 s for ROS 1
#: beside a CPU burner at a load of 11-13 on two cores (most of it rospy's shutdown, bounded at 0.5 s)
STOP_LIMIT_S = 1.0
#: how long the control is watched before it is called held (s)
HELD_S = 3.0

HOLDING_THREAD = """
import sys, threading
from pathlib import Path
from rclverify.runtime.stopping import end_bounded
threading.Thread(target=threading.Event().wait, name="held-forever").start()  # not a daemon
Path(sys.argv[1]).write_text("written")
if sys.argv[2] == "bounded":
    end_bounded(3)
sys.exit(3)
"""

HOLDING_FINALIZATION = """
import sys, time
from pathlib import Path
from rclverify.runtime.stopping import end_bounded


class Library:
    def __del__(self):  # deleted with its module at the interpreter's finalization, and never done
        while True:
            time.sleep(0.05)


kept = Library()
Path(sys.argv[1]).write_text("written")
if sys.argv[2] == "bounded":
    end_bounded(0, 0.5)
sys.exit(0)
"""


def _program(tmp: Path, source: str, mode: str) -> tuple[subprocess.Popen[bytes], Path, Path]:
    script, done, err = tmp / f"p_{mode}.py", tmp / f"done_{mode}", tmp / f"err_{mode}"
    script.write_text(textwrap.dedent(source))
    env = dict(os.environ, PYTHONPATH=str(REPO / "src"))
    with open(err, "wb") as fh:
        p = subprocess.Popen([sys.executable, str(script), str(done), mode], env=env, stdout=subprocess.DEVNULL,
                             stderr=fh, start_new_session=True)
    return p, done, err


def _ends_within(p: subprocess.Popen[bytes], seconds: float) -> int | None:
    """``p``'s exit status if it ends within ``seconds``, else ``None`` (then it is killed)."""
    try:
        return p.wait(seconds)
    except subprocess.TimeoutExpired:
        stop(p, signal.SIGKILL)
        return None


def test_a_thread_that_is_not_a_daemon_does_not_hold_the_exit(tmp_path: Path) -> None:
    p, done, err = _program(tmp_path, HOLDING_THREAD, "bounded")
    code = _ends_within(p, 20)
    assert code == 3 and done.read_text() == "written", (code, err.read_text())
    assert "held-forever" in err.read_text() and "did not end with the run" in err.read_text()
    control, _, _ = _program(tmp_path, HOLDING_THREAD, "control")  # the interpreter joins the thread for good
    assert _ends_within(control, HELD_S) is None


def test_a_finalization_that_blocks_is_ended_within_the_bound(tmp_path: Path) -> None:
    p, done, err = _program(tmp_path, HOLDING_FINALIZATION, "bounded")
    code = _ends_within(p, 20)
    assert code == 1 and done.read_text() == "written", (code, err.read_text())
    assert "__del__" in err.read_text(), err.read_text()  # the stack names what held the exit
    control, _, _ = _program(tmp_path, HOLDING_FINALIZATION, "control")
    assert _ends_within(control, HELD_S) is None


def test_an_in_process_caller_is_not_the_command_line() -> None:
    assert not _command_line()  # pytest's process goes on: it is never ended by the live command


try:
    import_rospy()
    NO_ROS1 = ""
except RosUnavailable as exc:
    NO_ROS1 = str(exc)

ROS1_CONTRACT = """\
node Level {
  inputs( )
  outputs( v : REAL )
  topics( std_msgs/Float32 level matches(out.v) )
  assume( TRUE )
  guarantee( out.v <= 0.5 )
}
"""


@pytest.mark.skipif(bool(NO_ROS1), reason=f"ROS 1 unavailable: {NO_ROS1}")
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_a_ros1_run_stopped_beside_a_burner_ends_within_a_second(tmp_path: Path, sig: int) -> None:
    ws = tmp_path / "ws"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/c.rcl").write_text(ROS1_CONTRACT)
    (ws / "contracts/plan.yaml").write_text("contracts: [contracts/c.rcl]\n")
    (ws / "mapping.yaml").write_text("topics: {}\n")
    burner = subprocess.Popen([sys.executable, "-c", "while True: pass"], start_new_session=True)
    try:
        with LocalMaster(tmp_path / "ros") as env:
            env = {**env, "PYTHONPATH": str(REPO / "src")}
            out, log, evidence = tmp_path / "monitor.out", tmp_path / "live.jsonl", tmp_path / "live.json"
            with open(out, "wb") as fh:
                monitor = subprocess.Popen(
                    [sys.executable, "-m", "rclverify.cli.commands", "monitor", "-w", str(ws), "--live", "--ros",
                     "1", "--mapping", "mapping.yaml", "--status", "0", "--log", str(log), "--evidence",
                     str(evidence), "--duration", "60"], env=env, cwd=tmp_path, stdout=fh, stderr=subprocess.STDOUT,
                    start_new_session=True)
            try:
                wait_for(out, "monitoring ", 60)
                t0 = time.monotonic()
                os.kill(monitor.pid, sig)
                code = monitor.wait(20)
                took = time.monotonic() - t0
            finally:
                stop(monitor, signal.SIGKILL)
    finally:
        stop(burner, signal.SIGKILL)
    text = out.read_text()
    assert took <= STOP_LIMIT_S and code == 0, (round(took, 3), code, text)
    assert "sha256" in text and "not judged: topic /level (Level): nothing heard" in text, text
    assert all(json.loads(line) for line in log.read_text().splitlines())  # every line reads
    assert json.loads(evidence.read_text())["not_judged"], evidence.read_text()
