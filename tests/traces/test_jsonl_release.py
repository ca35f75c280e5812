"""A log block's decoded rows freed once judged (traces/jsonl_blocks.py, ``LogBlock.release``).

The batch path releases each block of a ROSMonitoring log once it has
judged it (backends/monitors/batch.py, ``check_batch``).  A released block
keeps its length, topics, times and the events made from it, and a later
``values`` decodes its rows again from its lines: on logs whose reads are
decoded at once (several blocks a read) and line by line (a value that is
an object holding an array), every key's values at every row, evenly
spaced or not, are those read before the release; the control is the
block itself, whose rows are gone until asked for.  Then the batch path's
verdicts and result on windowed logs are the same with the release as
without it (``release`` a no-op), and as the streaming engine's.
"""
from __future__ import annotations

import json
import random
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from rclverify.backends.monitors.check import check_trace
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.traces import jsonl_blocks, read_trace
from rclverify.traces.jsonl import read_jsonl
from rclverify.traces.jsonl_blocks import JsonlLog, LogBlock
from rclverify.traces.mapping import load_rules

KEYS = ["data", "seq", "clock"]


def _log(path: Path, rnd: random.Random, nested: bool) -> None:
    """Windows, scalars, strings, a ``/clock`` object; with ``nested``, now and then an object holding an
    array (such a read is decoded line by line)."""
    with path.open("w") as out:
        for i in range(400):
            t = round(0.01 * i, 6)
            pick = rnd.random()
            line: dict[str, Any] = {"topic": "limit", "time": t, "data": rnd.choice([1.0, 0.5, 2])}
            if pick < 0.4:
                line = {"topic": "window", "time": t, "data": [rnd.uniform(0, 4) for _ in range(3)]}
            elif pick < 0.5:
                line = {"topic": "/status", "time": t, "data": rnd.choice(["green", "red"]), "seq": i}
            elif pick < 0.55:
                line = {"topic": "clock", "time": t, "clock": {"sec": i, "nanosec": 5}}
            elif nested and pick < 0.58:
                line = {"topic": "odd", "time": t, "data": {"a": [1.0, 2.0]}}
            out.write(json.dumps(line) + "\n")


@pytest.mark.parametrize("nested", [False, True])
def test_a_released_block_reads_the_same_values(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, nested: bool) -> None:
    monkeypatch.setattr(jsonl_blocks, "BLOCK_BYTES", 2048)  # many reads, each cut into blocks below
    log = tmp_path / "run.jsonl"
    _log(log, random.Random(f"release-{nested}"), nested)
    blocks = JsonlLog(log).blocks(KEYS, 7)
    assert blocks is not None
    seen = 0
    rnd = random.Random(3)
    for block in blocks:
        if not isinstance(block, LogBlock):
            continue
        seen += 1
        n = len(block)
        uneven = np.array(sorted(rnd.sample(range(n), max(1, n // 2))))
        picks = [np.arange(n), np.arange(0, n, 2), uneven, np.array([n - 1])]
        before = [[(k, repr(block.values(rows, k))) for k in KEYS] for rows in picks]
        made = block[n - 1]
        topics, times = list(block.topics), block.times.copy()
        block.release()
        assert block.structs is None and len(block) == n  # the control: the rows are gone, the length stays
        assert block[n - 1] is made and block.topics == topics and (block.times == times).all()
        after = [[(k, repr(block.values(rows, k))) for k in KEYS] for rows in picks]
        assert after == before
        assert block.structs is not None and len(block.structs) == n  # decoded again, once
    assert seen > 20


NODES = """\
node G {
  inputs( r : REAL )
  outputs( x : NATURAL --> REAL )
  topics( std_msgs/Float64 limit matches(in.r), std_msgs/Float64MultiArray window matches(out.x) )
  guarantee( forall(k in <0 upto 2> | out.x(k) > in.r) )
}
node U {
  inputs( x : NATURAL --> REAL )
  outputs( y : NATURAL --> REAL )
  topics( std_msgs/Float64MultiArray limit matches(in.x), std_msgs/Float64MultiArray window matches(out.y) )
  guarantee( exists(j in <0 upto 3> | out.y(j) > 4 and forall(i in <0 upto 3> | i < j -> in.x(i) > 1)) )
}
"""


@pytest.mark.parametrize("node", ["G", "U"])
def test_the_batch_paths_verdicts_with_and_without_the_release(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                                node: str) -> None:
    monkeypatch.setattr(jsonl_blocks, "BLOCK_BYTES", 4096)
    checked = check([parse_text(NODES)])
    rules = load_rules({"limit": {"fields": ["data"]}, "window": {"fields": ["data"]}})
    rnd = random.Random(f"windows-{node}")
    log = tmp_path / "run.jsonl"
    width = 4 if node == "U" else 3
    with log.open("w") as out:
        for i in range(1500):
            t = round(0.01 * i, 6)
            q: Any = [rnd.uniform(0.5, 4.5) for _ in range(4)] if node == "U" else rnd.choice([1.0, 0.5, 2.0])
            a = [rnd.uniform(0.0, 8.0) if rnd.random() < 0.95 else rnd.choice([0.5, 2, True]) for _ in range(width)]
            out.write(json.dumps({"topic": "limit", "time": t, "data": q}) + "\n")
            out.write(json.dumps({"topic": "window", "time": t, "data": a}) + "\n")
    released: list[int] = []
    real = LogBlock.release

    def counted(self: LogBlock) -> None:
        released.append(len(self))
        real(self)

    def judged(release: Any) -> tuple[list[Any], Any]:
        monkeypatch.setattr(LogBlock, "release", release)
        seen: list[Any] = []
        got = check_trace(checked, [checked.nodes[node]], read_trace(log, streams=True), rules, 0.005, seen.append,
                          margins=True)
        return seen, got
    with_release = judged(counted)
    without = judged(lambda self: None)
    seen_s: list[Any] = []
    streamed = check_trace(checked, [checked.nodes[node]], read_jsonl(log), rules, 0.005, seen_s.append,
                           batch=False, margins=True)
    assert len(released) > 10 and sum(released) > 2000  # every block released once judged
    assert with_release == without == (seen_s, streamed)
    assert any(v.verdict == "violated" for v in seen_s) and any(v.margin for v in seen_s)
