"""The live monitor's stop request (runtime/stopping.py; docs/monitors.md, "Stopping"): a signal
whose handler sets it while the main thread is inside its ``wait`` is always heard.

The cause of issue 106's ignored stops, shown on its own: a process whose main thread waits on the
stop request over and over (as the live monitor's loop does, every 0.1 s) while a storm of signals
arrives, each handler setting the request.  With :class:`~rclverify.runtime.stopping.StopFlag` the
process finishes its loop; the control, ``threading.Event`` set from the handler (as the monitor did),
blocks for good on the lock its own ``wait`` holds (or dies of handlers nested inside handlers), so it
never finishes.  Each in a subprocess of its own, bounded by a timeout."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]

SCRIPT = """\
import os, signal, sys, threading, time
from rclverify.runtime.stopping import StopFlag, on_signals
if sys.argv[1] == "flag":
    stop = StopFlag()
    on_signals(stop, [signal.SIGUSR1])
else:
    stop = threading.Event()
    signal.signal(signal.SIGUSR1, lambda *_: stop.set())
me = os.getpid()

def storm():
    end = time.monotonic() + 0.5
    while time.monotonic() < end:
        os.kill(me, signal.SIGUSR1)
        time.sleep(0.002)
threading.Thread(target=storm, daemon=True).start()
waits = 0
end = time.monotonic() + 0.6
while time.monotonic() < end:
    stop.wait(0)
    stop.wait(0.0001)
    waits += 2
print("finished", waits, stop.is_set(), flush=True)
"""


def _run(kind: str, tmp: Path) -> tuple[int | None, str]:
    script = tmp / "storm.py"
    script.write_text(SCRIPT)
    try:
        r = subprocess.run([sys.executable, str(script), kind], capture_output=True, text=True, timeout=4,
                           env={"PYTHONPATH": str(REPO / "src"), "PATH": "/usr/bin:/bin"})
    except subprocess.TimeoutExpired:
        return None, "timed out"
    return r.returncode, r.stdout + r.stderr


def test_a_signal_storm_over_the_waits_is_heard_and_the_loop_ends(tmp_path: Path) -> None:
    code, out = _run("flag", tmp_path)
    assert code == 0 and out.startswith("finished ") and out.split()[2] == "True", out


def test_the_control_an_event_set_by_the_handler_never_finishes(tmp_path: Path) -> None:
    code, out = _run("event", tmp_path)
    assert "finished" not in out, out  # deadlocked on its own lock (timed out) or died of nested handlers
