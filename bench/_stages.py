"""The live monitor run with each message's stages timed (the latency benches' ``--stages``).

Run as ``python _stages.py OUT.json monitor --live --ros2 ...`` in place of ``python -m
rclverify.cli.commands monitor --live --ros2 ...``: the same command in the same process, with the
wall-clock time (``time.time()``, s, the publisher's clock on this machine) recorded at each stage
of every message, written to ``OUT.json`` when the monitor exits:

* ``offered``: per topic, in the order heard, when the source handed the sample to the engine's
  queue (the DDS bus thread's callback; the rclpy source's bus thread reading the agent's pipe);
* ``pushed``: per topic, in the same order, when the engine thread pushed it into the engine
  (decoded; the queue and the engine thread's linger are between the two);
* ``released``: per event index (the order the watermark released messages), when it was released;
* ``published``: per event index, when its verdict was handed to the verdict writer, and when that
  write returned (the rclpy source only queues it for the agent: ``flushed`` is when the engine
  thread's batch of writes went to the agent's pipe);
* ``ticks``: each timer run's start and end, the watermark it reached, the engine thread's CPU over it
  its CPU clock and its time runnable but off a core so far (``/proc``'s ``schedstat``) as it began
  (s): a late tick shows whether the thread ran, waited for a core, or waited for the interpreter.

The j-th message heard on a topic is the j-th released on it (the bench's publisher sends each topic's
messages in order and none is late), which is how :func:`stage_table` lines the stages up with the
publisher's send times and the listener's receipts.  Nothing here changes what the monitor does but
for the time it takes to note these figures (a list append per stage).
"""
from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Any

if __name__ == "__main__":  # the monitor's own command line after OUT.json
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import _venv  # noqa: F401  (the project's environment: rclverify's dependencies)
    if len(sys.argv) < 3 or sys.argv[1] in ("-h", "--help"):
        print("usage: python bench/_stages.py OUT.json monitor --live --ros2 [the monitor's options]\n\n"
              + (__doc__ or "").split("\n\n")[0])
        sys.exit(0 if sys.argv[1:2] in (["-h"], ["--help"]) else 2)
    out, argv = Path(sys.argv[1]), sys.argv[2:]
    ROOT = Path(__file__).resolve().parents[1]
    sys.path.insert(0, str(ROOT / "src"))

    from rclverify.runtime import worker as _worker
    from rclverify.runtime import live as _live
    from rclverify.runtime.dds import live as _dds_live

    now = time.time
    offered: dict[str, list[float]] = {}
    pushed: dict[str, list[float]] = {}
    released: list[float] = []
    published: dict[int, tuple[float, float]] = {}
    flushed: list[float] = []
    ticks: list[tuple[float, ...]] = []

    offer0 = _worker.EngineWorker.offer

    def offer(self: Any, topic: str, payload: Any, received: float, writer: Any = None) -> None:
        offered.setdefault(topic, []).append(now())
        offer0(self, topic, payload, received, writer)
    _worker.EngineWorker.offer = offer  # type: ignore[method-assign]

    push0 = _live.LiveRun.push

    def push(self: Any, topic: str, fields: Any, received: float, writer: Any = None) -> None:
        pushed.setdefault(topic.lstrip("/"), []).append(now())
        push0(self, topic, fields, received, writer)
    _live.LiveRun.push = push  # type: ignore[method-assign]

    event0 = _live.LiveRun._event

    def event(self: Any, ev: Any) -> None:
        released.append(now())
        event0(self, ev)
    _live.LiveRun._event = event  # type: ignore[method-assign]

    verdict0 = _live.LiveRun._verdict

    def verdict(self: Any, v: Any) -> None:
        t0 = now()
        verdict0(self, v)
        published.setdefault(v.event, (t0, now()))
    _live.LiveRun._verdict = verdict  # type: ignore[method-assign]

    tick0 = _live.LiveRun.tick

    def _waited() -> float:
        """The engine thread's time (s) runnable but waiting for a core so far (``schedstat``; 0 without it)."""
        import threading
        try:
            with open(f"/proc/self/task/{threading.get_native_id()}/schedstat") as fh:
                return int(fh.read().split()[1]) / 1e9
        except (OSError, IndexError, ValueError):
            return 0.0

    def tick(self: Any, t: float) -> None:
        t0, c0, w0 = now(), time.thread_time(), _waited()
        tick0(self, t)
        ticks.append((t0, now(), self.engine._upto, time.thread_time() - c0, c0, w0))
    _live.LiveRun.tick = tick  # type: ignore[method-assign,assignment]

    flush0 = _dds_live._Sink.flush

    def flush(self: Any) -> None:
        flush0(self)
        if self.flush_writes is not None:
            flushed.append(now())
    _dds_live._Sink.flush = flush  # type: ignore[method-assign]

    from rclverify.cli.commands import main
    try:
        code = main(argv)
    finally:
        out.write_text(json.dumps({"offered": offered, "pushed": pushed, "released": released,
                                   "published": {str(k): v for k, v in published.items()}, "flushed": flushed,
                                   "ticks": ticks}))
    sys.exit(code)


def stage_table(stages: dict[str, Any], sent: list[tuple[str, float]], log_topics: list[str],
                verdicts: list[tuple[float, str]], window: float, worst: float = 0.01) -> list[str]:
    """Lines saying, over the verdicts decided on arrival, how long each stage took (ms, median and p99 over
    all; then the mean over the slowest ``worst`` share by publication -> verdict received): publication ->
    offered (the source), offered -> pushed (the engine's queue and linger), pushed -> released (the
    watermark: the lateness bound and the tick that releases), released -> verdict written (judging),
    written -> received (the verdict's way to the listener); and, apart, ``released past the bound``:
    released less (publication + ``window``, the lateness bound, s), how much later than the rule's
    earliest the watermark released it; then :func:`late_ticks`' line (due: publication + ``window``).  ``sent``: the publisher's (topic, send time);
    ``log_topics``: the live log's topics in order; ``verdicts``: the listener's (receipt, JSON text)."""
    from _live import p99
    per: dict[str, int] = {}
    index: list[tuple[str, int]] = []  # event -> (topic, j-th on it)
    for topic in log_topics:
        if topic.startswith("rclverify/"):
            continue
        index.append((topic, per.get(topic, 0)))
        per[topic] = per.get(topic, 0) + 1
    sent_at: dict[tuple[str, int], float] = {}
    seen: dict[str, int] = {}
    for topic, t in sent:
        sent_at[(topic, seen.get(topic, 0))] = t
        seen[topic] = seen.get(topic, 0) + 1
    flushed = sorted(stages.get("flushed") or [])
    rows: list[tuple[float, list[float], float, float]] = []  # latency, stages (ms), released, due (s)
    for recv, text in verdicts:
        v = json.loads(text)
        if not v.get("node") or abs(v["decided_at"] - v["time"]) > 1e-9 or v["event"] >= len(index):
            continue
        topic, j = index[v["event"]]
        pub = stages["published"].get(str(v["event"]))
        try:
            at: list[float] = [sent_at[(topic, j)], stages["offered"][topic][j], stages["pushed"][topic][j],
                               stages["released"][v["event"]], pub[1], recv]
        except (KeyError, IndexError, TypeError):
            continue
        if flushed:  # the rclpy source: written when the batch went to the agent
            import bisect
            k = bisect.bisect_left(flushed, pub[1])
            if k < len(flushed):
                at[4] = flushed[k]
        rows.append((recv - at[0], [(b - a) * 1e3 for a, b in zip(at, at[1:])] + [(at[3] - at[0] - window) * 1e3],
                     at[3], at[0] + window))
    if not rows:
        return ["stages: no verdict lined up"]
    names = ["source", "queue", "watermark", "judge", "to listener", "released past the bound"]
    rows.sort()
    slow = rows[-max(1, int(len(rows) * worst)):]
    out = []
    for i, name in enumerate(names):
        xs = sorted(r[1][i] for r in rows)
        out.append(f"{name}: p50 {xs[len(xs) // 2]:.2f} ms, p99 {p99(xs):.2f} ms, slowest {worst:.0%} mean "
                   f"{sum(r[1][i] for r in slow) / len(slow):.2f} ms")
    return out + late_ticks(stages, [r[2] for r in rows], [r[3] for r in rows])


def late_ticks(stages: dict[str, Any], released: list[float], due: list[float], late_s: float = 0.005) -> list[str]:
    """One line on the timer runs that released a message more than ``late_s`` (s) after its due time
    (``released`` and ``due``: wall-clock s, message by message): how long the engine thread had been
    away before each (from the end of the run before), and how much of that it was runnable without a
    core (``schedstat``) and how much it ran; the rest it slept or waited for the interpreter."""
    import bisect
    ticks = stages.get("ticks") or []
    starts = [t[0] for t in ticks]
    late = set()
    for r, d in zip(released, due):
        k = bisect.bisect_right(starts, r) - 1
        if k > 0 and ticks[k][0] - d > late_s and len(ticks[k]) > 5:
            late.add(k)
    if not late:
        return [f"timer runs releasing more than {late_s * 1e3:g} ms past the bound: none"]
    away = sum(ticks[k][0] - ticks[k - 1][1] for k in late)
    queued = sum(ticks[k][5] - ticks[k - 1][5] for k in late)
    ran = sum(ticks[k][4] - ticks[k - 1][4] - ticks[k - 1][3] for k in late)
    return [f"timer runs releasing more than {late_s * 1e3:g} ms past the bound: {len(late)}; the engine thread away "
            f"{away * 1e3:.0f} ms before them in all, runnable without a core {queued * 1e3:.0f} ms of it "
            f"(with the run before), running {ran * 1e3:.0f} ms"]
