"""Helpers of the live tests that start processes of their own (a ROS 1
master, nodes, a monitor, each in a session of its own)."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from pathlib import Path
from typing import Any, Callable


def stop(p: subprocess.Popen[bytes], sig: int = signal.SIGTERM, grace: float = 10) -> None:
    """Send ``sig`` to the process group of ``p`` (started with
    ``start_new_session=True``) unless it has ended; SIGKILL after ``grace``
    seconds, then wait up to 5 s more."""
    if p.poll() is None:
        os.killpg(p.pid, sig)
        try:
            p.wait(grace)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait(5)


def wait_for(path: Path, text: str, timeout: float) -> None:
    """Wait until the file ``path`` holds ``text``; ``AssertionError`` with
    the file's last 2000 characters after ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if path.exists() and text in path.read_text(errors="replace"):
            return
        time.sleep(0.05)
    raise AssertionError(f"{path.name} never said {text!r}: {path.read_text(errors='replace')[-2000:]}")


def wait_logged(path: Path, done: Callable[[list[dict[str, Any]]], bool], timeout: float) -> None:
    """Wait until ``done`` holds of the complete JSON lines of the log ``path``
    (a live monitor's ``--log``, written as it runs): a condition on what the
    monitor heard, where a sleep would assume an idle machine.
    ``AssertionError`` with the log's last 2000 characters after ``timeout``
    seconds."""
    deadline = time.monotonic() + timeout
    text = ""
    while time.monotonic() < deadline:
        text = path.read_text(errors="replace") if path.exists() else ""
        if done([json.loads(x) for x in text[:text.rfind("\n") + 1].splitlines() if x.strip()]):
            return
        time.sleep(0.1)
    raise AssertionError(f"{path.name} never held what was waited for: {text[-2000:]}")


def calls_judged(log: list[dict[str, Any]], least: dict[str, int]) -> bool:
    """The monitor's ``log`` (its JSON lines) holds at least ``least[node]``
    call verdicts (deadline lines not counted) of each node ``node``."""
    calls = [x["verdict"]["node"] for x in log if x.get("topic") == "rclverify/verdict" and "kind" not in x
             and x["verdict"].get("call")]
    return all(calls.count(node) >= n for node, n in least.items())
