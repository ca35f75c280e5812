"""The live monitor's engine thread, per message, in one process.

What ``bench/monitor_live_rclpy.py``'s latency run makes the engine thread
do, without the middleware's threads and the other processes: the bench's
workspace (three nodes, ``/a`` ``std_msgs/Float64``, ``/b``
``sensor_msgs/JointState`` and ``/c``
``geometry_msgs/PoseWithCovarianceStamped``, each ``guarantee( out.v >= 0
)``), the bench publisher's messages serialized to CDR with the monitor's
own Cyclone DDS structs (the header stamps left at zero, as the publisher
sends them), placed 1 / ``--rate`` s apart round-robin, and for each one
what the engine worker does (``runtime/worker.py``): decode (CDR to
fields), :meth:`~rclverify.runtime.live.LiveRun.push`, and
:meth:`~rclverify.runtime.live.LiveRun.tick` whenever the watermark
reaches the earliest buffered message (``due()``) or the 20 ms timer comes
round, with the CLI's lateness bound (``--lateness``, 50 ms).  Each verdict,
and each latched last verdict, is serialized as the DDS run makes its
``std_msgs/String`` sample (its ``write`` into Cyclone is not included); the log is written to a
temporary file.

``--worker``: the messages offered in real time instead, at ``--rate``
(the wall clock's), to the live monitor's engine thread itself
(:class:`~rclverify.runtime.worker.EngineWorker`, its queue, its wake-ups
and its timer on ``time.time``), as the middleware's thread offers them:
the thread's CPU a message with what waking for each message and each
release costs (``EngineWorker.cpu_s``), and its profile.

``--log FILE``: the messages of a recorded live log instead (JSON lines of
``rclverify monitor --live``'s ``--log``, each line's ``topic``, ``time``
and fields; verdict lines skipped), pushed as decoded fields at their
logged times, with ``--workspace``'s contracts and mapping: no decode.

Prints the thread's CPU microseconds per message (``time.thread_time``,
without the profiler, best of ``--repeat`` passes), the verdicts given, and
then, under ``cProfile``, the ``--top`` functions by own time and by
cumulative time.  Usage::

    python3 bench/engine_profile.py [--messages 5000] [--rate 1000] [--lateness 0.05] [--top 25]
    python3 bench/engine_profile.py --worker [--messages 5000] [--rate 1000]
    python3 bench/engine_profile.py --log live.jsonl --workspace WS [--mapping mapping.yaml]
    python3 bench/engine_profile.py --smoke     # 300 messages, one pass (CI)
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import cProfile
import io
import json
import math
import pstats
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable, Mapping

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "bench"))

#: the timer period of the live monitor's engine worker (s; ``--tick``'s default)
TICK_S = 0.02
#: the topics and types of bench/monitor_live_rclpy.py
TYPES = {"a": "std_msgs/msg/Float64", "b": "sensor_msgs/msg/JointState",
         "c": "geometry_msgs/msg/PoseWithCovarianceStamped"}

#: one message as the engine thread takes it: (topic, its fields or None to decode ``raw``, raw CDR, time s)
Message = tuple[str, "Mapping[str, object] | None", bytes, float]


def bench_messages(n: int, rate: float, start: float) -> tuple[list[Message], Callable[[str, bytes], Any],
                                                                  Callable[[str], bytes]]:
    """``n`` messages of the rclpy bench's publisher, serialized, ``1 / rate`` s apart from ``start`` (s);
    the decoder the DDS and rclpy sources share (CDR to fields, :func:`~rclverify.runtime.dds.cdr_fields.read_fields`)
    and the verdict sample's serializer."""
    from rclverify.runtime.dds.types import TypeBook, to_fields
    book = TypeBook()
    structs = {t: book.message(typ) for t, typ in TYPES.items()}
    string = book.message("std_msgs/msg/String")
    a = book.build(structs["a"], {"data": 1.0})
    b = book.build(structs["b"], {"name": ["shoulder", "elbow", "wrist"], "position": [0.5, 1.0, 1.5],
                                  "velocity": [0.0] * 3, "effort": [2.0] * 3})
    c = book.build(structs["c"], {"pose": {"pose": {"position": {"x": 1.0}}, "covariance": [0.1] + [0.0] * 35}})
    raw = {"a": a.serialize(), "b": b.serialize(), "c": c.serialize()}
    msgs: list[Message] = []
    for k in range(n):
        t = "abc"[k % 3]
        msgs.append((t, None, raw[t], start + k / rate))

    try:  # the DDS run's decoder (runtime/dds/live.py), else the struct's deserializer and to_fields
        from rclverify.runtime.dds.cdr_fields import read_fields
    except ImportError:
        def read_fields(cls: Any, raw: bytes) -> Any:
            return to_fields(cls.deserialize(raw))

    def decode(topic: str, data: bytes) -> Any:
        return read_fields(structs[topic], data)

    try:  # the verdict's bytes as the DDS run makes them (runtime/dds/live.py), else the struct's serializer
        from rclverify.runtime.dds.live import string_cdr as serialize
    except ImportError:
        def serialize(text: str) -> bytes:
            out: bytes = string(data=text).serialize()
            return out
    return msgs, decode, serialize


def log_messages(path: Path) -> list[Message]:
    """The contract messages of a recorded live log (verdict and call lines skipped)."""
    out: list[Message] = []
    for line in path.read_text(encoding="utf-8").splitlines():
        if not line.strip():
            continue
        obj = json.loads(line)
        topic = str(obj.get("topic", ""))
        if topic.startswith("rclverify/") or "kind" in obj:
            continue
        fields = {k: v for k, v in obj.items() if k not in ("topic", "time", "late_s")}
        out.append((topic, fields, b"", float(obj["time"])))
    return out


def bench_workspace(ws: Path) -> None:
    """The rclpy bench's workspace (bench/monitor_live_rclpy.py)."""
    from monitor_live_rclpy import _workspace
    _workspace(ws)


def make_run(ws: Path, mapping: str | None, log: Path, lateness: float,
             publish: Callable[[str], None]) -> Any:
    """A :class:`~rclverify.runtime.live.LiveRun` on the workspace's monitored nodes, its verdicts and
    its latched last verdicts given to ``publish``."""
    from rclverify.backends.monitors.config import load_mapping
    from rclverify.lang.typecheck import load
    from rclverify.runtime.live import LiveRun
    plan = (ws / "contracts" / "plan.yaml").read_text()
    files = [ws / line.strip() for line in plan.split("[", 1)[1].split("]", 1)[0].split(",") if line.strip()]
    checked = load(files)
    cfg = load_mapping(ws, mapping)
    return LiveRun(checked, list(checked.nodes.values()), cfg.rules, cfg.horizon, log, reorder_window=lateness,
                   publish=publish, publish_last=lambda node, text: publish(text))


def drive(run: Any, msgs: list[Message], decode: Callable[[str, bytes], Any] | None) -> int:
    """What the engine worker does with ``msgs``, in their order: the timer at each time the watermark
    reaches the earliest buffered message and every :data:`TICK_S`, before the message that
    arrives after it; each message decoded (unless its fields are given) and pushed.  Returns
    the messages pushed."""
    next_tick = msgs[0][3] + TICK_S if msgs else 0.0
    for topic, fields, raw, t in msgs:
        while True:
            due = min(run.due(), next_tick)
            if due > t:
                break
            run.tick(due)
            if due >= next_tick:
                next_tick = due + TICK_S
        run.push(topic, fields if fields is not None else decode(topic, raw) if decode else {}, t)
    end = msgs[-1][3] + 2.0 if msgs else 0.0
    while (due := run.due()) <= end and math.isfinite(due):
        run.tick(due)
    run.tick(end)
    return len(msgs)


def drive_worker(run: Any, msgs: list[Message], decode: Callable[[str, bytes], Any] | None, rate: float,
                 lateness: float, prof: cProfile.Profile | None = None, linger: float = 0.0) -> float:
    """``msgs`` offered to a real :class:`~rclverify.runtime.worker.EngineWorker` feeding ``run``, one every
    ``1 / rate`` s of the wall clock, each at its offer time (``time.time``); waits the lateness bound
    and a little more, stops the worker.  Returns its thread's CPU seconds per message; ``prof``, when
    given, profiles that thread; ``linger`` is the worker's ``linger_s``."""
    from rclverify.runtime.worker import EngineWorker

    class Profiled(EngineWorker):
        def _loop(self) -> None:
            if prof is None:
                return super()._loop()
            prof.enable()
            try:
                return super()._loop()
            finally:
                prof.disable()

    def fields_of(topic: str, payload: Any) -> Any:
        return payload if not isinstance(payload, bytes) else decode(topic, payload) if decode else {}
    worker = (Profiled(run, fields_of, time.time, tick_s=TICK_S, linger_s=linger) if linger
              else Profiled(run, fields_of, time.time, tick_s=TICK_S)).start()
    start = time.monotonic()
    for k, (topic, fields, raw, _t) in enumerate(msgs):
        wait = start + k / rate - time.monotonic()
        if wait > 0:
            time.sleep(wait)
        worker.offer(topic, fields if fields is not None else raw, time.time())
    time.sleep(lateness + 0.2)  # the last release
    worker.stop()
    return worker.cpu_s / max(worker.handled, 1)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--messages", type=int, default=5000)
    p.add_argument("--rate", type=float, default=1000.0, help="messages/s (their times' spacing)")
    p.add_argument("--lateness", type=float, default=0.05, help="the lateness bound, --reorder-window (s)")
    p.add_argument("--repeat", type=int, default=3, help="timed passes (the best is printed)")
    p.add_argument("--top", type=int, default=25)
    p.add_argument("--worker", action="store_true",
                   help="offer the messages in real time to the live engine thread (EngineWorker) at --rate")
    p.add_argument("--linger", type=float, default=None,
                   help="with --worker: the worker's linger_s (s; default the live DDS run's, LINGER_S)")
    p.add_argument("--log", type=Path, help="a recorded live log's messages instead of the bench's")
    p.add_argument("--workspace", type=Path, help="with --log: the workspace of its contracts")
    p.add_argument("--mapping", default=None, help="with --log: the mapping file, relative to the workspace")
    p.add_argument("--smoke", action="store_true", help="CI: 300 messages, one timed pass, the top 5")
    a = p.parse_args(argv)
    if a.smoke:
        a.messages, a.repeat, a.top = 300, 1, 5
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        serialize: Callable[[str], bytes] = str.encode
        decode = None
        if a.log is not None:
            if a.workspace is None:
                p.error("--log needs --workspace")
            ws, mapping = a.workspace, a.mapping
            msgs = log_messages(a.log)
        else:
            ws, mapping = tmp / "ws", "mapping.yaml"
            bench_workspace(ws)
            msgs, decode, serialize = bench_messages(a.messages, a.rate, 1.7e9)
        sent: list[bytes] = []

        def publish(text: str) -> None:
            sent.append(serialize(text))

        best = math.inf
        if a.worker:
            prof = cProfile.Profile()
            run = make_run(ws, mapping, tmp / "worker.jsonl", a.lateness, publish)
            try:
                from rclverify.runtime.worker import LINGER_S
            except ImportError:  # a worker that wakes for every message
                LINGER_S = 0.0
            linger = LINGER_S if a.linger is None else a.linger
            per = drive_worker(run, msgs, decode, a.rate, a.lateness, linger=linger)
            run.stop()
            given = len(sent)
            run = make_run(ws, mapping, tmp / "worker_profiled.jsonl", a.lateness, publish)
            drive_worker(run, msgs, decode, a.rate, a.lateness, prof, linger)
            run.stop()
            print(f"engine thread (EngineWorker, offered at {a.rate:g} msg/s of the wall clock, linger "
                  f"{linger * 1e3:g} ms): {len(msgs)} "
                  f"message(s), {given} verdict sample(s): {per * 1e6:.1f} us CPU per message (wake-ups, "
                  "decode, push, ticks, log, verdict samples)")
            _print_profile(prof, a.top)
            return 0
        for i in range(max(1, a.repeat)):
            sent.clear()
            run = make_run(ws, mapping, tmp / f"live{i}.jsonl", a.lateness, publish)
            t0 = time.thread_time()
            n = drive(run, msgs, decode)
            best = min(best, time.thread_time() - t0)
            run.stop()
        print(f"engine thread: {n} message(s), {len(sent)} verdict sample(s): {best / max(n, 1) * 1e6:.1f} us CPU per "
              f"message (best of {max(1, a.repeat)}; decode, push, ticks, log, verdict samples)")
        run = make_run(ws, mapping, tmp / "profiled.jsonl", a.lateness, publish)
        prof = cProfile.Profile()
        prof.enable()
        drive(run, msgs, decode)
        prof.disable()
        run.stop()
    _print_profile(prof, a.top)
    return 0


def _print_profile(prof: cProfile.Profile, top: int) -> None:
    """The ``top`` functions of ``prof`` by own time, then by cumulative time."""
    if top <= 0:
        return
    for key in ("tottime", "cumulative"):
        s = io.StringIO()
        pstats.Stats(prof, stream=s).sort_stats(key).print_stats(top)
        text = s.getvalue()
        print(f"-- top {top} by {key} --")
        print(text[text.find("   ncalls"):].rstrip())


if __name__ == "__main__":
    sys.exit(main())
