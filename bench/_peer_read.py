"""A peer of the windowed race (bench/_window_peers.py) as a program of its own: it reads the same
ROSMonitoring log the ``rclverify monitor`` command reads, rebuilds the samples from it and monitors them.

Run as ``python bench/_peer_read.py PEER SPEC LOG OUT``: ``PEER`` one of ``rtamt``, ``reelay``,
``mstlo``; ``SPEC`` the formula as JSON (the fields of ``_window_peers.Formula`` the peers read:
``name``, ``h``, ``rtamt``, ``reelay``, ``reelay_read``, ``mstlo``, ``signals``); ``LOG`` the race's
log; ``OUT`` a file the robustness at each sample is written to (native doubles), for the race to
compare with the in-memory run's.  The whole process is what is timed (its CPU, start-up included),
as the command's is: so this module imports only what such a program needs (the standard library's
``json``, ``array`` and ``sys``, msgspec, and the peer), not numpy nor the race's own modules.

The log is read as an ordinary Python program reads a large log: a megabyte at a time (cut after its
last line), each read's lines decoded by msgspec into a typed struct (``topic``, ``time``, ``data`` a
float, a list of floats or absent) by one ``decode_lines`` call, the values kept taken from them at once,
with the collector off as the command's reader runs (with it on, its passes over the decoded lines
cost a 600,000-line log's reading about half as much again); the signals are then rebuilt from the lines (a windowed log's
answers carry ``x(t) .. x(t+h)``: a sample's value is its window's first entry, the last window's
tail the trace's last ``h`` samples; the deadline's log has a line per trigger and per answer, a
sample's index its time over the 10 ms period, the trace's length told by its last line, the tick one
second after the last sample).

The three peers' monitoring functions are here too (the race runs them in its own process on the
samples held in memory, the loop alone timed): each takes the formula and the samples as lists.
"""
from __future__ import annotations

import gc
import sys
from array import array
from typing import Any, Protocol, Sequence

PERIOD = 0.01  # s between samples
STEP = 16384  # mstlo's batch call: samples at a time


class Spec(Protocol):
    """What the peers read of a formula (bench/_window_peers.py's ``Formula``)."""

    @property
    def name(self) -> str: ...

    @property
    def h(self) -> int: ...

    @property
    def rtamt(self) -> str: ...

    @property
    def reelay(self) -> str: ...

    @property
    def reelay_read(self) -> str: ...

    @property
    def mstlo(self) -> str: ...

    @property
    def signals(self) -> tuple[str, ...]: ...


def rtamt_run(f: Spec, cols: dict[str, list[float]], n: int) -> list[float]:
    """RTAMT 0.4.10's offline ``evaluate`` of ``f.rtamt`` on the first ``n`` samples of ``cols``."""
    import rtamt  # type: ignore[import-not-found,import-untyped,unused-ignore]
    spec = rtamt.StlDiscreteTimeSpecification()
    for v in f.signals:
        spec.declare_var(v, "float")
    spec.spec = f.rtamt
    spec.parse()
    data = {"time": list(range(n)), **{v: cols[v][:n] for v in f.signals}}
    return [float(r) for _, r in spec.evaluate(data)]


def reelay_run(f: Spec, cols: dict[str, list[float]], n: int) -> list[float]:
    """Reelay 25's discrete robustness monitor of ``f.reelay``, updated sample by sample (read past-time:
    shifted by ``f.h``, or on the samples backwards, as ``f.reelay_read`` says)."""
    import reelay  # type: ignore[import-not-found,import-untyped,unused-ignore]
    mon = reelay.discrete_timed_monitor(pattern=f.reelay, semantics="robustness", condense=False)
    rows = list(zip(*(cols[v][:n] for v in f.signals)))
    if f.reelay_read == "reverse":
        rows.reverse()
    update = mon.update
    names = f.signals
    if len(names) == 1:
        (a,) = names
        out = [update({"time": i, a: r[0]})["value"] for i, r in enumerate(rows)]
    else:
        a, b = names
        out = [update({"time": i, a: r[0], b: r[1]})["value"] for i, r in enumerate(rows)]
    if f.reelay_read == "reverse":
        out.reverse()
        return [float(r) for r in out]
    return [float(r) for r in out[f.h:]]


def mstlo_run(f: Spec, cols: dict[str, list[float]], n: int) -> list[float]:
    """mstlo 0.2.2's ``DelayedQuantitative`` monitor of ``f.mstlo``, fed by its batch call ``STEP`` samples
    at a time (its time unit a sample)."""
    import mstlo_python  # type: ignore[import-not-found,import-untyped,unused-ignore]
    mon = mstlo_python.Monitor(mstlo_python.parse_formula(f.mstlo), semantics="DelayedQuantitative")
    sigs = {v: cols[v][:n] for v in f.signals}
    out: list[float] = []
    for a in range(0, n, STEP):
        b = min(n, a + STEP)
        ts = [float(i) for i in range(a, b)]  # its bounds are in its time unit: a sample a unit
        got = mon.update_batch({v: list(zip(c[a:b], ts)) for v, c in sigs.items()}).verdicts()
        out += [r for _, r in got]
    return [float(r) for r in out]


RUNS = {"rtamt": rtamt_run, "reelay": reelay_run, "mstlo": mstlo_run}


def read_log(log: str, f: Spec) -> tuple[dict[str, list[float]], int]:
    """The samples of ``f``'s signals and their count, rebuilt from the log at path ``log`` (module
    docstring), read a megabyte at a time (cut after its last line), each read's lines decoded by one call
    and the values kept taken from them at once (so the decoded lines are freed as they are read, as a
    reader of a large log reads it)."""
    import msgspec

    class Line(msgspec.Struct, gc=False):
        topic: str
        time: float
        data: float | list[float] | None = None

    decode = msgspec.json.Decoder(Line).decode_lines
    gc.disable()  # as the command's reader runs (its batch path): the collector's passes would free nothing (main
    # turns it on again to monitor)
    if f.name.startswith("G(trig"):  # the deadline: a line per trigger and per answer
        stamps: dict[str, list[int]] = {"trig": [], "ans": []}
        end = [0.0]

        def take(lines: list[Any]) -> None:
            for line in lines:
                if line.topic in stamps:
                    stamps[line.topic].append(round(line.time / PERIOD))
            end[0] = lines[-1].time
        _read(log, decode, take)
        n = round((end[0] - 1.0) / PERIOD)  # the tick, a second after the last sample
        cols: dict[str, list[float]] = {"trig": [0.0] * n, "ans": [0.0] * n}
        for topic, at in stamps.items():
            col = cols[topic]
            for i in at:
                col[i] = 1.0
        return cols, n
    # G[0,2]: the answer's window is x's; until: the question's window is x's, the answer's y's
    topics = {"window": f.signals[0]} if len(f.signals) == 1 else {"limit": f.signals[0], "window": f.signals[1]}
    cols = {v: [] for v in f.signals}
    last: dict[str, Any] = {}

    def windows(lines: list[Any]) -> None:
        for topic, v in topics.items():
            got = [ln.data for ln in lines if ln.topic == topic]
            if got:
                cols[v] += [w[0] for w in got]  # a sample's value: its window's first entry
                last[v] = got[-1]
    _read(log, decode, windows)
    for v, w in last.items():
        cols[v] += w[1:]  # the last window's tail: the trace's last h samples
    return cols, len(cols[f.signals[0]])


def _read(log: str, decode: Any, take: Any) -> None:
    """``take(lines)`` for the lines of the log at path ``log`` decoded by ``decode`` (msgspec's
    ``decode_lines``), a read of a megabyte (cut after its last line) at a time; a read's lines are
    freed before the next read's are decoded."""
    with open(log, "rb") as fh:
        rest = b""
        while True:
            data = fh.read(1 << 20)
            if not data:
                break
            data = rest + data
            cut = data.rfind(b"\n") + 1
            rest = data[cut:]
            take(decode(data[:cut]))
        if rest.strip():
            take(decode(rest))


def main(argv: Sequence[str]) -> int:
    import json
    if len(argv) != 4 or argv[0] in ("-h", "--help"):
        print(f"usage: python bench/_peer_read.py PEER SPEC_JSON LOG OUT (PEER one of {', '.join(sorted(RUNS))}): "
              "a peer as a program of its own reading the log, run by bench/_window_peers.py")
        return 0 if argv[:1] in (["-h"], ["--help"]) else 2
    peer, spec, log, out = argv
    f = _Formula(json.loads(spec))
    cols, n = read_log(log, f)
    gc.enable()  # the peer monitors with the collector on, as in the race's own process
    got = RUNS[peer](f, cols, n)
    with open(out, "wb") as fh:
        array("d", got).tofile(fh)
    return 0


class _Formula:
    """A formula's fields from the race's JSON."""

    def __init__(self, d: dict[str, Any]) -> None:
        self.name, self.h, self.rtamt, self.reelay = str(d["name"]), int(d["h"]), str(d["rtamt"]), str(d["reelay"])
        self.reelay_read, self.mstlo, self.signals = str(d["reelay_read"]), str(d["mstlo"]), tuple(d["signals"])


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
