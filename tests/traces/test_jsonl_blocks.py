"""The log read in blocks (traces/jsonl_blocks.py) against the exact reader, and the command with and without it.

The block reader's fast path gives the batch path columns (topics, times,
field values) and makes an event only for a row asked for; its oracle is
:func:`rclverify.traces.jsonl.read_jsonl` (itself checked against
``json.loads`` in tests/traces/test_traces.py).  On random logs of good, odd and
hostile lines (keys out of order, duplicated or escaped, extra keys, a
leading ``/``, integer and missing times, integers beyond 64 bits, ``NaN``,
bytes that are not UTF-8, deep nesting, blank lines, every line end), cut
into blocks of 1 line up and read a few bytes at a time up: the same
events, the same columns as those events, the same error after the same
events.  Then ``rclverify monitor`` on random classifier runs prints the
same with the fast path as without it (every block read as events).
"""
from __future__ import annotations

import argparse
import contextlib
import io
import json
import random
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from _classifier import CLASSIFIER
from rclverify.traces import TraceError, read_trace
from rclverify.traces import jsonl_blocks
from rclverify.traces.jsonl import read_jsonl
from rclverify.traces.jsonl_blocks import JsonlLog, LogBlock
from test_traces import LINES

GOOD = [b'{"topic": "reading", "time": 0.5, "data": 1.5}', b'{"topic": "status", "time": 0.5, "data": "green"}',
        b'{"topic": "/reading", "time": 1.25, "data": 119.99999999999999}', b'{"data": 4.0, "time": 3.0, "topic": "reading"}',
        b'{"topic": "status", "time": 2.0, "data": "red", "seq": 7}', b'{"topic": "tick", "time": 9.0}',
        b'{"topic": "reading", "time": 1e-320, "data": -0.0}', b'{"topic":"reading","time":2.0,"data":null}',
        b'  {"topic": "reading", "time": 4.0, "data": [1, {"y": 2.5}]}  ', b'{"topic": "status", "time": 5.0, "data": true}',
        '{"topic": "st\u00e4tus", "time": 6.0, "data": "\u00e9\\ud83d\\ude00"}'.encode(),
        b'{"topic": "\\/reading", "time": 6.5, "data": 2.0}', b'{"topic": "\\u002Freading", "time": 7.0, "data": 3.0}',
        b'{"topic": "window", "time": 7.5, "data": [1.5, 2, -0.0, 123456789012345678901234567890, "x}{", null, true]}',
        b'{"topic": "window", "time": 8.0, "data": [], "seq": [4.0, 1e-320]}']
ODD = [b'{"topic": "reading", "time": 1.0, "data": 1, "data": "x"}', b'{"topic": "a", "topic": "reading", "time": 2.0}',
       b'{"t\\u006fpic": "reading", "time": 2.0, "data": 3.0}', b'{"topic": "reading", "time": 7, "data": 1.0}',
       b'{"topic": "reading", "time": 8.0, "data": 123456789012345678901234567890}', b'{"topic": "reading", "time": 2.5e308}',
       b'{"topic": "reading", "time": 1.0, "time": "x"}', b'{"topic": "reading", "time": "1.0"}', b'{"topic": null, "time": 1.0}',
       b'{"topic": "reading", "time": 1.0, "": 1}', b'{"topic": "reading", "time": 1.0, "data": NaN}',
       b'{"topic": "reading", "time": 1.0, "x": "\xff"}', b'{"topic": "reading", "time": 1.0, "x": "\xed\xa0\x80"}',
       b'{"topic": "reading", "time": 1.0, "data": 2.0}\x00', b'\x0c{"topic": "reading", "time": 1.0}',
       b'{"topic": "reading", "time": 1.0, "x": ' + b'[' * 3000 + b']' * 3000 + b'}', b'{"topic": "reading", "time": -0.0}',
       b'{"topic": "reading", "time": 1.0, "data": 1E400}', b'{"topic": "reading", "time": 1.0, "seq": 2, "seq": null}',
       b'{"topic": "window", "time": 1.0, "data": [[1.0], [2.0]]}', b'{"topic": "window", "time": 1.0, "data": [1.0, 1E400]}',
       b'{"topic": "window", "time": 1.0, "data": [1.0, NaN]}', b'{"topic": "window", "time": 1.0, "data": [1.0,',
       b'2.0]}']
HOSTILE = [line.encode("utf-8", "surrogatepass") for line in LINES]
FIELDS = [["data"], ["data", "seq"], ["time", "data"], [], ["x", "topic"]]


def _outcome(run: Any) -> tuple[list[tuple[Any, ...]], str]:
    """Events as comparable tuples (repr: -0.0, 1 and 1.0, True apart) and the error ('' when none)."""
    got: list[tuple[Any, ...]] = []
    try:
        for ev in run:
            got.append((ev.index, repr(ev.time), ev.topic, repr(list(ev.fields.items())), ev.where, ev.stamp))
        said = ""
    except TraceError as exc:
        said = str(exc)
    except RecursionError as exc:
        said = f"RecursionError: {exc}"
    return got, said


def _blockwise(path: Path, fields: list[str], rows: int, rnd: random.Random, seen: dict[str, int]) -> Any:
    """The blocks' events, each fast block's columns checked against its events on the way."""
    for block in JsonlLog(path).blocks(fields, rows):
        if not isinstance(block, LogBlock):
            seen["exact"] += 1
            yield from block
            continue
        seen["fast"] += 1
        n = len(block)
        assert 1 <= n <= rows
        events = [block[i] for i in range(n)]
        assert block[0:n] == events and block[-1] is events[-1] and all(block[i] is events[i] for i in range(n))
        assert block.topics == [e.topic for e in events]
        # the rows per topic, counted among the read's topics (a block of a read may lack some: not named)
        assert block.topic_counts() == dict(Counter(e.topic for e in events))
        assert [repr(t) for t in block.times.tolist()] == [repr(e.time) for e in events]
        for key in fields + ["data", "seq", "topic", "time", "nope"]:
            for at in (np.arange(n), np.arange(0, n, 2), np.arange(1, n, 3),
                       np.array(sorted(rnd.sample(range(n), rnd.randint(0, n))), dtype=np.int64)):
                want = [repr(events[i].fields.get(key)) if key not in ("topic", "time") else "None"
                        for i in at.tolist()]
                assert [repr(v) for v in block.values(at, key)] == want, (key, at)
        yield from events


def test_blocks_read_as_the_exact_reader(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st
    seen = {"fast": 0, "exact": 0}
    line = st.one_of(st.sampled_from(GOOD), st.sampled_from(GOOD), st.sampled_from(ODD), st.sampled_from(HOSTILE),
                     st.just(b""), st.just(b"   "))
    end = st.sampled_from([b"\n", b"\n", b"\r\n", b"\r"])

    @settings(max_examples=250, deadline=None, database=None, derandomize=True,
              suppress_health_check=list(HealthCheck))
    @given(st.lists(st.tuples(line, end), max_size=14), st.booleans(), st.sampled_from([1, 2, 3, 7, 1000]),
           st.sampled_from([1, 5, 17, 64, 1 << 20]), st.sampled_from(FIELDS), st.integers(0, 99))
    def check(lines: list[tuple[bytes, bytes]], last_end: bool, rows: int, size: int, fields: list[str],
              seed: int) -> None:
        data = b"".join(text + e for text, e in lines)
        if lines and not last_end:
            data = data[:len(data) - len(lines[-1][1])]
        p = tmp_path / "run.jsonl"
        p.write_bytes(data)
        monkeypatch.setattr(jsonl_blocks, "BLOCK_BYTES", size)
        want = _outcome(read_jsonl(p))
        assert _outcome(_blockwise(p, fields, rows, random.Random(seed), seen)) == want
    check()
    assert seen["fast"] > 100 and seen["exact"] > 100  # both paths ran


def test_a_log_with_more_keys_is_read_fast_after_its_first_block(tmp_path: Path) -> None:
    p = tmp_path / "run.jsonl"
    p.write_text("".join(f'{{"topic": "reading", "time": {i / 100!r}, "data": {i * 1.5!r}, "seq": {i}, '
                         f'"frame": "base"}}\n' for i in range(100)))
    kinds = [type(b).__name__ for b in JsonlLog(p).blocks(["data"], 10)]
    assert kinds == ["list"] + ["LogBlock"] * 9
    log = read_trace(p)
    assert isinstance(log, JsonlLog) and list(log) == list(read_jsonl(p))
    assert log.blocks(["data"], 10) is None  # its events were read: no blocks after that


def test_topics_seen_are_read_as_one_object_each_and_a_new_one_still_read(tmp_path: Path,
                                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """After a read decoded at once, its topics are decoded as Literal values (one string object per
    name, so the topic column compares objects); a read bringing a topic not seen before is decoded
    again with the topic a string, and its topic is known from then on: the same events either way."""
    p = tmp_path / "run.jsonl"
    lines = [f'{{"topic": "{t}", "time": {i / 100!r}, "data": {i * 0.5!r}}}\n'
             for i, t in enumerate(["a", "/b"] * 40 + ["a", "/b", "c", "\\/b"] * 20 + ["c", "a"] * 40)]
    p.write_text("".join(lines))
    monkeypatch.setattr(jsonl_blocks, "BLOCK_BYTES", 40 * len(lines[0]))
    blocks = list(JsonlLog(p).blocks(["data"], 1000))
    assert all(isinstance(b, LogBlock) for b in blocks) and len(blocks) >= 5
    events = list(read_jsonl(p))
    assert [t for b in blocks for t in b.topics] == [e.topic for e in events]
    assert [t for b in blocks for t in b.times.tolist()] == [e.time for e in events]
    assert [v for b in blocks for v in b.values(np.arange(len(b)), "data")] == [e.fields["data"] for e in events]
    seen: set[str] = set()
    known = 0
    for b in blocks:  # a read of topics all seen before: one object per topic (as the lines spell it)
        spelled = {s.f0 for s in b.structs}
        if spelled <= seen:
            known += 1
            assert all(len({id(s.f0) for s in b.structs if s.f0 == name}) == 1 for name in spelled)
        seen |= spelled
    assert known >= 3


def test_an_integer_time_keeps_its_block_exact(tmp_path: Path) -> None:
    """msgspec would read an integer time into a float field; the fast path never lets it (an integer
    or a time of any type but float sends the block to the exact reader)."""
    p = tmp_path / "run.jsonl"
    p.write_text('{"topic": "r", "time": 9007199254740993, "data": 1.0}\n{"topic": "r", "time": 1.0, "data": 1.0}\n')
    (block,) = JsonlLog(p).blocks(["data"], 10)
    assert isinstance(block, list) and [e.time for e in block] == [9007199254740992.0, 1.0]


def test_a_log_of_arrays_is_decoded_at_once_and_an_object_inside_one_is_not(tmp_path: Path,
                                                                             monkeypatch: pytest.MonkeyPatch) -> None:
    """A window or a ROS array field (an array of scalars) keeps a read on the at-once path (one
    ``decode_lines`` call), with the exact reader's events and columns; an array holding an object or an
    array sends the read to the line-by-line paths, with the same events."""
    lines = [f'{{"topic": "window", "time": {i / 100!r}, "data": [{i * 0.5!r}, {i}, -0.0, "s", null, true]}}'
             for i in range(50)]
    p = tmp_path / "run.jsonl"
    flat = jsonl_blocks._flat
    at_once: list[bool] = []
    monkeypatch.setattr(jsonl_blocks, "_flat", lambda *a: at_once.append((got := flat(*a)) is not None) or got)
    for odd, want in ((None, [True]), ('{"topic": "window", "time": 9.0, "data": [1.0, {"x": 2.0}]}', [False]),
                      ('{"topic": "window", "time": 9.0, "data": [[1.0], [2.0]]}', [False])):
        p.write_text("\n".join(lines + ([odd] if odd else [])) + "\n")
        at_once.clear()
        seen = {"fast": 0, "exact": 0}
        assert _outcome(_blockwise(p, ["data"], 1000, random.Random(1), seen)) == _outcome(read_jsonl(p))
        assert at_once == want, odd
        assert seen == {"fast": 1, "exact": 0}  # either way a fast block: at once, else line by line


# -- the command, with and without the fast path ------------------------------------------------------

CONTRACT = CLASSIFIER


def _workspace(root: Path, skew: float) -> Any:
    from rclverify.app.pipeline import Workspace
    (root / "contracts").mkdir(parents=True)
    (root / "backends/monitors").mkdir(parents=True)
    (root / "contracts/classifier.rcl").write_text(CONTRACT)
    (root / "contracts/plan.yaml").write_text("name: classifier\ncontracts: [contracts/classifier.rcl]\nnodes:\n"
                                              "  Classifier:\n    evidence: []\n")
    (root / "backends/monitors/mapping.yaml").write_text(
        f"horizon: 0.005\nskew: {skew}\ntopics:\n  reading: {{fields: [data]}}\n  status: {{fields: [data]}}\n")
    return Workspace(root, "contracts/plan.yaml").checked


def _run_log(rnd: random.Random, n: int) -> bytes:
    """A classifier run: mostly a reading and its status, with every kind of irregularity a log has."""
    out: list[str] = []
    t = 0.0
    for _ in range(n):
        t += rnd.choice([0.01, 0.01, 0.01, 0.0, 0.003])
        r = rnd.choice([rnd.uniform(0, 400), 119.99999999999999, 120.0, 250.0, -1.0])
        band = "green" if r < 120 else "orange" if r < 250 else "red"
        if rnd.random() < 0.05:
            band = rnd.choice(["green", "orange", "red", "purple"])
        kind = rnd.choices(["pair", "lone", "late", "odd", "extra", "slash", "tick", "blank", "int", "nan", "back"],
                           [80, 3, 2, 2, 2, 2, 2, 1, 1, 1, 2])[0]
        topic = "/reading" if kind == "slash" else "reading"
        if kind == "int":
            out.append(f'{{"topic": "reading", "time": {int(t) + 1}, "data": {r!r}}}')
            continue
        out.append(f'{{"topic": "{topic}", "time": {t!r}, "data": {"NaN" if kind == "nan" else repr(r)}}}')
        if kind == "odd":
            out.append(f'{{"topic": "status", "time": {t!r}, "data": {rnd.choice(["1.5", "null", "[1]", "true"])}}}')
        elif kind == "extra":
            out.append(f'{{"topic": "status", "time": {t!r}, "data": "{band}", "seq": {rnd.randint(0, 10**20)}}}')
        elif kind == "tick":
            out.append(f'{{"topic": "tick", "time": {t!r}}}')
        elif kind == "blank":
            out.append("")
        elif kind != "lone":
            dt = {"late": 0.02, "back": -0.002}.get(kind, 0.0)
            out.append(f'{{"topic": "status", "time": {t + dt!r}, "data": "{band}"}}')
    return ("\n".join(out) + "\n").encode()


def _command(checked: Any, root: Path, log: Path, as_json: bool) -> tuple[int, str, str]:
    from rclverify.cli.monitor import monitor_command
    args = argparse.Namespace(workspace=str(root), mapping=None, horizon=None, json=as_json, live=False, nodes=None,
                              traces=[str(log)])
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = monitor_command(args, checked)
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("skew", [0.0, 0.02])
def test_the_command_prints_the_same_with_and_without_the_fast_path(tmp_path: Path, skew: float,
                                                                    monkeypatch: pytest.MonkeyPatch) -> None:
    root = tmp_path / "ws"
    checked = _workspace(root, skew)
    rnd = random.Random(f"blocks-{skew}")
    fast_blocks = 0
    real_fast = jsonl_blocks._fast

    def counted(*a: Any) -> Any:
        nonlocal fast_blocks
        block = real_fast(*a)
        fast_blocks += block is not None
        return block
    for case in range(14):
        log = tmp_path / f"run{case}.jsonl"
        data = _run_log(rnd, rnd.randint(20, 600))
        if case % 4 == 3:  # a line no reader takes, midway: the verdicts before it, then the same located error
            lines = data.split(b"\n")
            lines.insert(rnd.randrange(len(lines)), rnd.choice([b'{"topic": "reading"}', b'{"topic": "r", "time": 1',
                                                               b'[1, 2]', b'{"topic": "r", "time": 1.0, "x": "\xff"}']))
            data = b"\n".join(lines)
        if case % 5 == 4:
            data = data.replace(b"\n", b"\r\n")
        log.write_bytes(data)
        monkeypatch.setattr(jsonl_blocks, "BLOCK_BYTES", rnd.choice([300, 4096, 1 << 20]))
        monkeypatch.setattr(jsonl_blocks, "_fast", counted)
        fast = [_command(checked, root, log, j) for j in (False, True)]
        monkeypatch.setattr(JsonlLog, "blocks", lambda self, fields, rows: None)  # every event made, as before
        exact = [_command(checked, root, log, j) for j in (False, True)]
        monkeypatch.undo()
        assert fast == exact, f"case {case}"
        assert fast[0][0] in (0, 1, 2) and (fast[0][0] == 2) == (case % 4 == 3), (case, fast[0])
        if fast[0][0] != 2:
            report = json.loads(fast[1][1])
            assert report[0]["node"] == "Classifier" and report[0]["events_read"] > 0
    assert fast_blocks > 14


@pytest.mark.parametrize("spelled", [b"/reading", b"\\/reading", b"\\u002freading", b"\\u002F/reading"])
def test_a_leading_slash_is_removed_however_the_log_spells_it(tmp_path: Path, spelled: bytes) -> None:
    """A read decoded at once skips looking for a leading ``/`` only when its bytes hold no ``"/`` and
    no backslash: an escaped slash (``\\/``, ``\\u002f``) still makes the topic ``reading``."""
    p = tmp_path / "run.jsonl"
    p.write_bytes(b"".join(b'{"topic": "%s", "time": %d.0, "data": 1.5}\n' % (spelled if k == 3 else b"reading", k)
                           for k in range(6)))
    blocks = list(JsonlLog(p).blocks(["data"], 100))
    assert len(blocks) == 1 and isinstance(blocks[0], LogBlock)
    assert blocks[0].topics == ["reading"] * 6 == [ev.topic for ev in read_jsonl(p)]


def test_a_column_kept_with_its_block_is_the_column_made_again(tmp_path: Path) -> None:
    """``block_column`` (the deadline judge's and the untimed check's shared columns): on random logs of
    floats, integers, strings, NaN and missing values, every request of field ``data`` at random rows, as
    a ``REAL`` and as an enumeration, equals ``column`` of the block's values there, asked first or again,
    and what a caller writes into one answer is not in the next.  The control: a block's kept column keyed
    without its field's name gives another field the first one's column."""
    from rclverify.targets.columns import block_column, column
    rnd = random.Random("kept-columns")
    values = [1.5, -0.0, 2.0, 7, float("nan"), "on", "off", None, True, [1.0]]
    codes = {"on": 0, "off": 1}
    blocks = 0
    for k in range(20):
        p = tmp_path / f"run{k}.jsonl"
        with p.open("w") as out:
            for i in range(rnd.randint(20, 80)):
                msg: dict[str, Any] = {"topic": rnd.choice(["a", "b"]), "time": 0.01 * i}
                v = rnd.choice(values)
                if v is not None:
                    msg["data"] = v
                out.write(json.dumps(msg) + "\n")
        got = JsonlLog(p).blocks(["data"], rnd.choice([7, 16, 1000]))
        assert got is not None
        for block in got:
            if not isinstance(block, LogBlock):
                continue
            blocks += 1
            for _ in range(6):
                rows = np.flatnonzero(np.array([rnd.random() < 0.5 for _ in range(len(block))]))
                for kind, c in (("real", {}), ("enum", codes)):
                    want = column(block.values(rows, "data"), kind, c)
                    for _ in range(2):
                        good, col = block_column(block, rows, "data", kind, c)
                        assert good.tolist() == want[0].tolist()
                        assert np.array_equal(col, want[1], equal_nan=True) and col.dtype == want[1].dtype
                        good[:] = False  # the caller's own copy
                        col[:] = 0
    assert blocks > 20
    # the control: a column kept without its field's name hands another field the first one's column
    p = tmp_path / "control.jsonl"
    p.write_text("".join(json.dumps({"topic": "a", "time": 0.01 * i, "data": float(i), "other": -1.0}) + "\n"
                         for i in range(10)))
    got = JsonlLog(p).blocks(["data", "other"], 100)
    assert got is not None
    block = next(iter(got))
    assert isinstance(block, LogBlock)
    every = np.arange(len(block))
    wrong = [block.kept("no name", lambda f=f: column(block.values(every, f), "real", {}))[1].tolist()
             for f in ("data", "other")]
    assert wrong[1] != block_column(block, every, "other", "real", {})[1].tolist()


def test_a_blocks_topic_counts_name_only_its_own_topics(tmp_path: Path) -> None:
    """A read decoded at once and cut into blocks counts each block's rows per topic among the read's topics
    (a leading ``/`` removed): a topic of the read that a block lacks is not named by it (the control: the
    read's last block holds every topic)."""
    p = tmp_path / "run.jsonl"
    lines = [("/limit", 0.0), ("window", 0.0), ("limit", 0.01), ("window", 0.01), ("tick", 1.0)]
    p.write_text("".join(f'{{"topic": "{t}", "time": {s!r}, "data": 1.5}}\n' for t, s in lines))
    blocks = list(JsonlLog(p).blocks(["data"], 2))
    assert [type(b).__name__ for b in blocks] == ["LogBlock"] * 3
    assert [b.topic_counts() for b in blocks] == [{"limit": 1, "window": 1}, {"limit": 1, "window": 1}, {"tick": 1}]
    whole = list(JsonlLog(p).blocks(["data"], 5))
    assert [b.topic_counts() for b in whole] == [{"limit": 2, "window": 2, "tick": 1}]


@pytest.mark.parametrize("size", [1, 5, 17, 64, 1 << 20])
def test_the_reads_are_the_logs_whole_lines_from_a_file_and_from_a_stream(tmp_path: Path, size: int,
                                                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """Each read is whole lines, the log's bytes in order, its end as it is: from a file (the bytes after a
    read's last line end read again by the next read) and from a FIFO (carried to the next read, the
    control: a stream cannot be read again)."""
    import os
    import threading
    monkeypatch.setattr(jsonl_blocks, "BLOCK_BYTES", size)
    text = b"".join(GOOD[i % len(GOOD)] + b"\n" for i in range(40)) + b'{"topic": "x", "time": 1.0}' * 9  # no end
    p = tmp_path / "run.jsonl"
    p.write_bytes(text)
    reads = [data[:cut] for data, cut in jsonl_blocks._reads(p)]
    assert b"".join(reads) == text and all(r.endswith(b"\n") for r in reads[:-1]) and not reads[-1].endswith(b"\n")
    if not hasattr(os, "mkfifo"):
        return
    fifo = tmp_path / "stream.jsonl"
    os.mkfifo(fifo)
    writer = threading.Thread(target=fifo.write_bytes, args=(text,))
    writer.start()
    streamed = [data[:cut] for data, cut in jsonl_blocks._reads(fifo)]
    writer.join()
    assert b"".join(streamed) == text and all(r.endswith(b"\n") for r in streamed[:-1])
