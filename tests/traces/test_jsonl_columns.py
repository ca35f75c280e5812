"""A log's reads decoded at once (traces/jsonl_blocks.py, ``_flat``) against the exact reader and the line-by-line paths.

The whole-read path decodes a read's lines with one msgspec
``decode_lines`` call, which by itself is lax (two objects on one line, one
object over two lines).  Its oracle is :func:`rclverify.traces.jsonl.read_jsonl`
(checked against ``json.loads`` in tests/traces/test_traces.py), and the blocks
read with the whole-read path switched off.  Random logs of flat lines
(the common case, so that whole reads are taken) with damaged lines mixed
in, among them lines made to fool a lax reader: two objects on one line
(joined, spaced, comma-separated), an object split over two lines, a line
whose last ``}`` or first ``{`` is inside a string, a pair of those that
keeps the count of objects equal to the count of lines, nested values,
integer / ``NaN`` / huge / boolean times, bad bytes, control characters,
duplicated and unknown keys, blank lines, ``\\r``.  Every log: the same
events, columns equal to those events, the same error after the same
events; then the command's verdicts equal with and without the path.
"""
from __future__ import annotations

import random
from pathlib import Path
from typing import Any

import msgspec
import numpy as np
import pytest

from rclverify.traces import jsonl_blocks
from rclverify.traces.jsonl import read_jsonl
from rclverify.traces.jsonl_blocks import JsonlLog, LogBlock
from test_jsonl_blocks import _command, _outcome, _run_log, _workspace

TOPICS = ["reading", "status", "/reading", "tick", "st\u00e4tus"]


def _flat_line(rnd: random.Random, t: float) -> str:
    """A line the whole-read path takes: a topic, a float time and scalar values only."""
    topic = rnd.choice(TOPICS)
    value = rnd.choice([repr(rnd.uniform(-500, 500)), '"green"', '"red"', "null", "true", "1e-320", "-0.0",
                        str(rnd.randint(-10**25, 10**25)), '"a}\\n{b"', '"\\u00e9\\ud83d\\ude00"'])
    keys = [f'"topic": "{topic}"', f'"time": {t!r}'] + ([f'"data": {value}'] if rnd.random() < 0.9 else [])
    if rnd.random() < 0.1:
        keys.append(f'"seq": {rnd.randint(0, 99)}')
    rnd.shuffle(keys)
    return "{" + ", ".join(keys) + "}"


DAMAGED = [
    '{"topic": "reading", "time": 1.0}{"topic": "status", "time": 1.0}',  # two objects, joined
    '{"topic": "reading", "time": 1.0} {"topic": "status", "time": 1.0}',  # two objects, spaced
    '{"topic": "reading", "time": 1.0},{"topic": "status", "time": 1.0}',  # two objects, a comma
    '{"topic": "reading",\n"time": 1.0}',  # one object over two lines (the second not led by "{")
    '{"topic": "reading", "time": 1.0, "x": "}\n{", "data": 2.0}',  # a string over the line end
    '{"topic": "reading", "time": 2.0, "x": "}\n{"}',
    '{"topic": "reading", "time": 1.0, "data": [1, 2]}', '{"topic": "reading", "time": 1.0, "data": {"y": 1}}',
    '{"topic": "reading", "time": 7, "data": 1.0}', '{"topic": "reading", "time": 9007199254740993}',
    '{"topic": "reading", "time": NaN}', '{"topic": "reading", "time": 1e400}', '{"topic": "reading", "time": true}',
    '{"topic": null, "time": 1.0}', '{"topic": "reading"}', '{"time": 1.0}', '{"topic": "reading", "time": "1.0"}',
    '{"topic": "reading", "time": 1.0, "data": 1, "data": [1]}', '{"topic": "reading", "time": 1.0, "time": 2.0}',
    '{"topic": "reading", "time": 1.0, "header": {"stamp": {"sec": 1, "nanosec": 5}}}',
    '{"topic": "reading", "time": 1.0, "x": "a\tb"}', ' {"topic": "reading", "time": 1.0}',
    '{"topic": "reading", "time": 1.0} ', '', '[1, 2]', '{}', '{"topic": "reading", "time": 1.0, "": 1}',
    '{"topic": "reading", "time": 1.0}\r', '{"topic": "reading", "time": 1.0, "data": 1E400}',
]
#: a pair that keeps the count of objects equal to the count of lines: two on one line, one split over two
BALANCED = ['{"topic": "a", "time": 1.0}{"topic": "b", "time": 2.0}', '{"topic": "c", "time": 3.0,', '"data": 4.0}']


def _log(rnd: random.Random) -> bytes:
    lines: list[str] = []
    t = 0.0
    for _ in range(rnd.randint(1, 60)):
        t += rnd.choice([0.01, 0.0, 0.003])
        lines.append(_flat_line(rnd, t))
    for _ in range(rnd.choice([0, 0, 1, 2])):
        at = rnd.randrange(len(lines) + 1)
        lines[at:at] = BALANCED if rnd.random() < 0.2 else [rnd.choice(DAMAGED)]
    data = ("\n".join(lines) + "\n").encode("utf-8", "surrogatepass")
    if rnd.random() < 0.05:
        at = rnd.randrange(len(data))
        data = data[:at] + rnd.choice([b"\xff", b"\x00", b"\xed\xa0\x80"]) + data[at:]
    return data if rnd.random() < 0.9 else data[:-1]  # sometimes no line end at the log's end


def _read(path: Path, fields: list[str], rows: int) -> tuple[list[Any], list[Any]]:
    """The blocks' events, and each fast block's columns (topics, times, values of ``fields``)."""
    events: list[Any] = []
    columns: list[Any] = []

    def run() -> Any:
        for block in JsonlLog(path).blocks(fields, rows) or ():
            if isinstance(block, LogBlock):
                n = len(block)
                got = [block[i] for i in range(n)]
                assert block.topics == [e.topic for e in got]
                assert [repr(t) for t in block.times.tolist()] == [repr(e.time) for e in got]
                for key in fields:
                    at = np.arange(0, n, 1 + n % 3)
                    want = [repr(got[i].fields.get(key)) for i in at.tolist()]
                    assert [repr(v) for v in block.values(at, key)] == want
                columns.append((block.topics, block.times.tolist(),
                                [block.values(np.arange(n), k) for k in fields]))
                yield from got
            else:
                yield from block
    events.append(_outcome(run()))
    return events, columns


def test_whole_reads_read_as_the_exact_reader(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    rnd = random.Random("jsonl-columns")
    taken = {"flat": 0, "refused": 0}
    real = jsonl_blocks._flat

    def counted(*a: Any) -> Any:
        got = real(*a)
        taken["flat" if got is not None else "refused"] += 1
        return got
    p = tmp_path / "run.jsonl"
    for case in range(400):
        p.write_bytes(_log(rnd))
        fields = rnd.choice([["data"], ["data", "seq"], []])
        rows = rnd.choice([1, 3, 16, 1000])
        monkeypatch.setattr(jsonl_blocks, "BLOCK_BYTES", rnd.choice([64, 300, 1 << 20]))
        monkeypatch.setattr(jsonl_blocks, "_flat", counted)
        want = _outcome(read_jsonl(p))
        (got,), columns = _read(p, fields, rows)
        assert got == want, case
        monkeypatch.setattr(jsonl_blocks, "_flat", lambda *a: None)  # the line-by-line paths only
        (before,), old_columns = _read(p, fields, rows)
        assert before == want, case
        if len(old_columns) == len(columns):  # the same cut into blocks: the same columns
            assert repr(old_columns) == repr(columns), case
    assert taken["flat"] > 300 and taken["refused"] > 100, taken  # both ran


def test_balanced_damage_is_refused(tmp_path: Path) -> None:
    """Two objects on one line and one over two lines: as many objects as lines, still the exact error."""
    p = tmp_path / "run.jsonl"
    p.write_text('{"topic": "r", "time": 0.5, "data": 1.0}\n' + "\n".join(BALANCED) + "\n")
    events, error = _outcome(read_jsonl(p))
    assert len(events) == 1 and error.startswith(f"{p}:2:")
    assert _read(p, ["data"], 100)[0] == [(events, error)]
    assert len(msgspec.json.Decoder().decode_lines(p.read_bytes())) == 4  # what a lax reader reads


def test_a_clean_log_is_read_whole(tmp_path: Path) -> None:
    p = tmp_path / "run.jsonl"
    p.write_text("".join(f'{{"topic": "reading", "time": {i / 100!r}, "data": {i * 1.5!r}}}\n' for i in range(50)))
    blocks = list(JsonlLog(p).blocks(["data"], 16) or ())
    assert [len(b) for b in blocks] == [16, 16, 16, 2] and all(isinstance(b, LogBlock) for b in blocks)
    assert blocks[3][1].where == "run.jsonl:50" and blocks[3][1].fields == {"data": 49 * 1.5}


def test_the_command_judges_the_same_with_and_without_whole_reads(tmp_path: Path,
                                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    root = tmp_path / "ws"
    checked = _workspace(root, 0.02)
    rnd = random.Random("jsonl-columns-command")
    for case in range(6):
        log = tmp_path / f"run{case}.jsonl"
        data = _run_log(rnd, rnd.randint(200, 900))
        if case % 3 == 2:  # a line no reader takes, midway
            lines = data.split(b"\n")
            lines.insert(rnd.randrange(len(lines)), rnd.choice([BALANCED[0].encode(), b'{"topic": "r", "time": 1}{}']))
            data = b"\n".join(lines)
        log.write_bytes(data)
        monkeypatch.setattr(jsonl_blocks, "BLOCK_BYTES", rnd.choice([2000, 1 << 20]))
        whole = [_command(checked, root, log, j) for j in (False, True)]
        monkeypatch.setattr(jsonl_blocks, "_flat", lambda *a: None)
        lines_only = [_command(checked, root, log, j) for j in (False, True)]
        monkeypatch.undo()
        assert whole == lines_only, case
        assert (whole[0][0] == 2) == (case % 3 == 2), whole[0]
