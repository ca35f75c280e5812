"""The live engine's per-message shortcuts change no verdict and no margin (issue 106).

Each case feeds a :class:`~rclverify.runtime.live.LiveRun` (the online
engine, its log, its verdict sink, margins on) a fixed stream as the engine
worker does (the timer before each message, every 10 ms of the stream's
clock), stops it, and digests what it wrote: the log's bytes (every
released message and every verdict line, margins included), the verdict
texts it published, what each latched last-verdict topic holds at the end
and each node's status and counts.  The digests in ``tests/data/online_verdicts.json`` were written by
the engine before its per-topic plans and cheaper bookkeeping
(``python tests/backends/test_online_same_verdicts.py --write COMMIT``
with that commit's ``src`` first on ``PYTHONPATH``; the file names it); the test fails on any byte that differs.

The cases: the case study's three bundled runs (four nodes, unstamped, no
lateness bound), the live bench's three topics with negative values, NaN
and missing fields (lateness bound 50 ms), and a two-input node with
header stamps, copied stale stamps, arrivals out of order and later than
the bound, a NaN, a deadline (``triggered by ... within``) and an output
state, on three seeds.  The control: the same stream with one value
changed gives another digest.  And a verdict's ``std_msgs/String`` sample,
made without the struct's serializer, is the bytes the serializer gives.
"""
from __future__ import annotations

import hashlib
import json
import math
import random
import sys
from pathlib import Path
from typing import Any, Callable

import pytest

from rclverify.backends.monitors.config import load_mapping
from rclverify.lang.typecheck import load
from rclverify.runtime.live import LiveRun

REPO = Path(__file__).resolve().parents[2]
FIXTURE = REPO / "tests" / "data" / "online_verdicts.json"
TRACES = REPO / "backends" / "monitors" / "traces"
TICK = 0.01

BENCH = "\n".join(f"node {n} {{\n  inputs( )\n  outputs( v : REAL )\n  topics( {typ} {t} matches(out.v) )\n"
                  f"  assume( TRUE )\n  guarantee( out.v >= 0 )\n}}\n"
                  for t, typ, n in (("a", "std_msgs/Float64", "A"), ("b", "sensor_msgs/JointState", "B"),
                                    ("c", "geometry_msgs/PoseWithCovarianceStamped", "C")))
BENCH_MAP = ("topics:\n  a: {fields: ['data']}\n  b: {fields: ['position[0]']}\n"
             "  c: {fields: ['pose.pose.position.x']}\n")
FUSE = """
node Fuse {
  inputs( a : REAL, b : REAL )
  outputs( alert : BOOL, level : REAL, mode : REAL )
  topics( pkg/A a matches(in.a), pkg/B b matches(in.b), pkg/Alert alert matches(out.alert),
          pkg/Level level matches(out.level), pkg/Mode mode matches(out.mode) )
  assume( in.b >= 0 )
  guarantee( out.alert <=> (in.a <= 1.0 and in.b >= 2.0) )
  guarantee( out.level <= in.a + in.b ) triggered by in.a within 100 ms
  guarantee( out.mode >= 0 )
}
"""
FUSE_MAP = ("topics:\n  a: {fields: [value]}\n  b: {fields: [value]}\n  alert: {fields: [data]}\n"
            "  level: {fields: [data]}\n  mode: {fields: [data], state: true}\n")

#: one message heard: (arrival s, topic, fields)
Heard = list[tuple[float, str, dict[str, Any]]]


def _stamp(t: float) -> dict[str, Any]:
    sec = math.floor(t)
    return {"stamp": {"sec": sec, "nanosec": round((t - sec) * 1e9)}, "frame_id": ""}


def _case_study(run: str) -> tuple[str, Heard]:
    heard: Heard = []
    for line in (TRACES / run).read_text().splitlines():
        obj = json.loads(line)
        heard.append((float(obj["time"]), obj["topic"], {k: v for k, v in obj.items() if k not in ("topic", "time")}))
    return "case", heard


def _bench(seed: int) -> tuple[str, Heard]:
    rnd = random.Random(seed)
    heard: Heard = []
    for k in range(600):
        t = 1000.0 + k / 1000 + rnd.uniform(0, 0.0004)
        v = rnd.choice([1.0, 0.5, 0.0, -0.25, 3.0]) if k % 37 else float("nan")
        topic = "abc"[k % 3]
        if topic == "a":
            fields: dict[str, Any] = {"data": v} if k % 101 else {"other": v}
        elif topic == "b":
            fields = {"header": _stamp(0.0), "name": ["s", "e"], "position": [v, 1.0], "velocity": [], "effort": []}
        else:
            fields = {"header": _stamp(0.0), "pose": {"pose": {"position": {"x": v, "y": 0.0, "z": 0.0}},
                                                      "covariance": [0.1] * 36}}
        heard.append((t, topic, fields))
    return "bench", heard


def _fuse(seed: int) -> tuple[str, Heard]:
    """Two inputs at 200 and 300 ms, stamped; answers 5-15 ms after their question, some copying an earlier
    question's stamp, some wrong; a mode state now and then; delivery 1-40 ms, a few 80-150 ms late."""
    rnd = random.Random(seed)
    sent: list[tuple[str, float, dict[str, Any]]] = []
    bs = [(1.0 + 0.3 * k + rnd.uniform(0, 0.02), rnd.choice([1.5, 2.0, 2.5, -1.0 if k % 11 == 5 else 2.0]))
          for k in range(20)]
    for t, v in bs:
        sent.append(("b", t, {"header": _stamp(t), "value": v if rnd.random() > 0.03 else float("nan")}))
    prev = 1.0
    for k in range(30):
        t = 1.1 + 0.2 * k + rnd.uniform(0, 0.02)
        a = rnd.choice([0.5, 1.0, 1.5])
        sent.append(("a", t, {"header": _stamp(t), "value": a}))
        had = [v for s, v in bs if s < t]
        if not had:
            prev = t
            continue
        right = a <= 1.0 and had[-1] >= 2.0
        out = t + rnd.uniform(0.005, 0.015)
        stamp = prev if rnd.random() < 0.15 else out  # a stale copied stamp now and then
        sent.append(("alert", out, {"header": _stamp(stamp), "data": right if rnd.random() > 0.1 else not right}))
        if rnd.random() < 0.8:
            lvl = t + rnd.uniform(0.02, 0.13)  # within the 100 ms deadline, or past it
            sent.append(("level", lvl, {"header": _stamp(lvl), "data": a + had[-1] - rnd.choice([0.0, 0.5, -0.5])}))
        if k % 7 == 3:
            sent.append(("mode", t + 0.03, {"data": rnd.choice([1.0, 0.0, -1.0])}))
        prev = t
    heard: Heard = []
    last: dict[str, float] = {}
    for topic, t, fields in sorted(sent, key=lambda x: x[1]):
        delay = rnd.uniform(0.08, 0.15) if rnd.random() < 0.04 else rnd.uniform(0.001, 0.04)
        arrival = max(last.get(topic, 0.0), t + delay)
        last[topic] = arrival
        heard.append((arrival, topic, {**fields, "_sent": round(t, 6)}))
    heard.sort(key=lambda x: x[0])
    return "fuse", heard


CASES: dict[str, Callable[[], tuple[str, Heard]]] = {
    **{f"case-{run}": (lambda run=run: _case_study(run)) for run in ("nominal.jsonl", "env_fault.jsonl",
                                                                    "sensor_fault.jsonl")},
    "bench-1": lambda: _bench(1),
    **{f"fuse-{s}": (lambda s=s: _fuse(s)) for s in (1, 2, 3)},
}


def _workspace(tmp: Path, kind: str) -> tuple[Any, Any, float]:
    """(checked, rules, horizon, lateness bound) of a case's contracts."""
    if kind == "case":
        cfg = load_mapping(REPO, "backends/monitors/mapping.yaml", 2.0)
        return load([REPO / "contracts" / "remote_inspection.rcl"]), cfg, 0.0
    d = tmp / kind
    d.mkdir(exist_ok=True)
    (d / "c.rcl").write_text(BENCH if kind == "bench" else FUSE)
    (d / "mapping.yaml").write_text(BENCH_MAP if kind == "bench" else FUSE_MAP)
    return load([d / "c.rcl"]), load_mapping(d, "mapping.yaml", 1.0), 0.05


def digest(tmp: Path, name: str, change: Callable[[Heard], None] | None = None) -> dict[str, Any]:
    """What the live run of case ``name`` wrote (module docstring): its sha256 and sizes."""
    kind, heard = CASES[name]()
    if change is not None:
        change(heard)
    checked, cfg, window = _workspace(tmp, kind)
    published: list[str] = []
    lasts: dict[str, str] = {}  # what each latched last-verdict topic holds
    log = tmp / f"{name}.jsonl"
    live = LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, log, reorder_window=window,
                   silence_s=0.5, publish=published.append, publish_last=lasts.__setitem__,
                   margins=True)
    now = heard[0][0]
    for arrival, topic, fields in heard:
        while now + TICK <= arrival:
            now += TICK
            live.tick(now)
        sent = fields.pop("_sent", None)
        live.push(topic, fields, arrival if sent is None else sent)
    live.tick(now + 2.0)
    record = live.stop()
    nodes = [{k: n.get(k) for k in ("node", "status", "explanation", "counts")} for n in record["nodes"]]
    h = hashlib.sha256()
    for part in (log.read_bytes(), "\n".join(published).encode(), json.dumps(lasts, sort_keys=True).encode(),
                 json.dumps([nodes, record["events"], record["late_events"], record["verdicts"],
                             record.get("topic_deadlines"), record["silent_topics"]], sort_keys=True).encode()):
        h.update(hashlib.sha256(part).digest())
    return {"sha256": h.hexdigest(), "log_lines": len(log.read_text().splitlines()), "published": len(published)}


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_live_run_writes_what_the_engine_before_the_shortcuts_wrote(tmp_path: Path, name: str) -> None:
    want = json.loads(FIXTURE.read_text())["cases"][name]
    assert digest(tmp_path, name) == want


def test_the_control_one_value_changed_is_another_digest(tmp_path: Path) -> None:
    def flip(heard: Heard) -> None:
        k = next(i for i, (_t, topic, _f) in enumerate(heard) if topic == "alert")
        heard[k][2]["data"] = not heard[k][2]["data"]
    want = json.loads(FIXTURE.read_text())["cases"]["fuse-1"]
    got = digest(tmp_path, "fuse-1", flip)
    assert got["sha256"] != want["sha256"]
    assert digest(tmp_path, "fuse-1") == want  # the unchanged stream, after the changed one, is the fixture's


@pytest.mark.parametrize("text", ["", "abc", '{"node": "A", "verdict": "satisfied", "time": 1.5}', "\u00e9\u2603x"])
def test_a_verdict_is_sent_as_the_bytes_the_string_struct_serializes(text: str) -> None:
    from rclverify.runtime.dds.live import string_cdr
    from rclverify.runtime.dds.types import TypeBook
    string = TypeBook().message("std_msgs/msg/String")
    assert string_cdr(text) == string(data=text).serialize(use_version_2=False)
    assert string_cdr(text + "x") != string(data=text).serialize(use_version_2=False)  # the control


def _write(commit: str) -> None:
    """The fixture, from the engine importable here (``PYTHONPATH`` at a checkout of ``commit``)."""
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        cases = {name: digest(Path(d), name) for name in sorted(CASES)}
    FIXTURE.write_text(json.dumps({"written_at": commit, "cases": cases}, indent=1, sort_keys=True) + "\n")


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--write":
        _write(sys.argv[2])
