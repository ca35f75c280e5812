"""One reorder buffer (src/rclverify/traces/reorder.py): the live engine, the
stamp-order reader and the DDS service path hold a run's messages in it and
nowhere else, and it releases them in event-time order up to the watermark,
counting what is late."""
from __future__ import annotations

import re
from pathlib import Path

from rclverify.traces.reorder import ReorderBuffer

SRC = Path(__file__).resolve().parents[2] / "src" / "rclverify"
ENGINE = SRC / "traces" / "reorder.py"
#: a second buffer ordered by stamp: a heap, an insort into a list, or a sort keyed by a stamp or a time
_SORT_BY_TIME = re.compile(r"sort(?:ed)?\([^)]*key=lambda[^:]*:[^)]*(?:stamp|\.time\b|\[0\]\[0\])")


#: a heap (imported or used), or an insort keyed by a stamp or a time
_HEAP = re.compile(r"^\s*(?:import heapq|from heapq import)|(?:heappush|heapify)\(|insort\([^)\n]*(?:stamp|time)",
                   re.MULTILINE)


def _second_buffers(root: Path) -> list[str]:
    found = []
    for path in sorted(root.rglob("*.py")):
        if path == ENGINE:
            continue
        text = path.read_text()
        hits = list(_HEAP.finditer(text))
        if path.parent.name in ("monitors", "dds") and path.stem in ("online", "stamp_order", "services", "order"):
            hits += list(_SORT_BY_TIME.finditer(text))
        for m in hits:
            found.append(f"{path.relative_to(root)}:{text.count(chr(10), 0, m.start()) + 1}: {m.group(0).strip()}")
    return found


def test_no_second_reorder_buffer_in_the_package() -> None:
    assert _second_buffers(SRC) == []


def test_the_scan_finds_a_second_buffer(tmp_path: Path) -> None:
    # the control: a heap keyed by stamp in another module is found, as a sort by stamp in an ordering path is
    pkg = tmp_path / "rclverify" / "backends" / "monitors"
    pkg.mkdir(parents=True)
    (pkg / "other.py").write_text("import heapq\n\ndef f(h, ev):\n    heapq.heappush(h, (ev.stamp, ev))\n")
    (pkg / "online.py").write_text("def g(evs):\n    return sorted(evs, key=lambda e: e.stamp)\n")
    found = _second_buffers(tmp_path / "rclverify")
    assert any("other.py:1: import heapq" in f for f in found)
    assert any("other.py:4: heappush(" in f for f in found)
    assert any("online.py:2:" in f for f in found)


def test_released_in_event_time_order_up_to_the_watermark() -> None:
    buf: ReorderBuffer[str] = ReorderBuffer()
    buf.push(2.0, 2.0, "b")
    buf.push(1.0, 1.5, "answer")  # copies its question's stamp, published after it
    buf.push(1.0, 1.0, "question")
    buf.push(3.0, 3.0, "c")
    assert buf.head() == 1.0 and len(buf) == 4
    assert [r.item for r in buf.release(2.0)] == ["question", "answer", "b"]
    assert len(buf) == 1 and buf.late == 0
    assert [r.item for r in buf.release(3.0, strict=True)] == []  # before the watermark only
    buf.push(2.5, 2.6, "late")  # pushed after the watermark (3.0) passed its stamp: late by 0.5 s
    got = list(buf.drain())
    assert [(r.item, r.late) for r in got] == [("late", 0.5), ("c", 0.0)]  # still put before "c"
    buf.push(1.5, 3.5, "too late")  # stamped before the latest released
    assert [(r.item, r.late) for r in buf.drain()] == [("too late", 1.5)]
    assert buf.late == 2 and buf.max_late_s == 1.5 and buf.last == 3.0 and buf.head() == float("inf")
    # the control: without a watermark (released with none reached), nothing pushed in its place is late
    plain: ReorderBuffer[str] = ReorderBuffer()
    plain.push(2.0, 2.0, "x")
    assert [r.late for r in plain.release(float("inf"))] == [0.0]
    plain.push(2.5, 2.5, "y")
    assert [r.late for r in plain.release(float("inf"))] == [0.0] and plain.late == 0


def test_a_watermark_on_the_source_time() -> None:
    buf: ReorderBuffer[tuple[float, str]] = ReorderBuffer()
    buf.push(5.0, 5.0, (9.0, "old receipt"))
    buf.push(1.0, 1.0, (9.5, "young"))
    # released while the earliest is due: stamp at most 1.0, or received at or before 9.0
    got = [r.item[1] for r in buf.release_while(lambda s, _src, item: s <= 1.0 or item[0] <= 9.0)]
    assert got == ["young", "old receipt"]
