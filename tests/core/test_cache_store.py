"""The cache layer (rclverify.core.cache): one keying function, one file format, one rule of what is
kept.  A kept file from other code, damaged or truncated reads as empty; a run keeps what it used."""
from __future__ import annotations

import pickle
import subprocess
import sys
from pathlib import Path

import pytest

from rclverify.core.cache import Blobs, Keyer, Shelf, kept_files, read_stream, salt, write_stream
from rclverify.core.cache.keys import fingerprint


def test_keys_differ_for_different_contents_kinds_and_salts() -> None:
    k = Keyer(salt("a"))
    assert k("p", "ab", "c") != k("p", "a", "bc")  # contents are length-prefixed
    assert k("p", "x") != k("q", "x") and k("p", b"x") == k("p", "x")
    assert Keyer(salt("a"))("p", "x") != Keyer(salt("b"))("p", "x")
    assert Keyer(salt("a", ("z3 1",)))("p", "x") != Keyer(salt("a", ("z3 2",)))("p", "x")
    assert fingerprint({"a": 1, "b": 2}) != fingerprint({"b": 2, "a": 1})  # another order: a miss, never a wrong hit


def test_a_shelf_keeps_what_the_run_used(tmp_path: Path) -> None:
    path = tmp_path / "s.pickle"
    first = Shelf(path, "t")
    a, b = first.key("e", "a"), first.key("e", "b")
    first.put(a, 1)
    first.put(b, [2])
    assert first.save() and not first.save()  # nothing new the second time
    second = Shelf(path, "t")
    assert second.get(a) == 1 and second.hits == 1  # b not used in this run
    assert second.save()  # dropped b
    third = Shelf(path, "t")
    assert third.get(b) is None and third.get(a) == 1 and len(third) == 1


def test_keep_holds_earlier_entries_up_to_its_size(tmp_path: Path) -> None:
    path = tmp_path / "s.pickle"
    s = Shelf(path, "t", keep=2)
    for x in "abc":
        s.put(s.key("e", x), x)
    s.save()
    again = Shelf(path, "t", keep=2)
    again.put(again.key("e", "d"), "d")
    again.save()
    kept = Shelf(path, "t")
    assert kept.get(kept.key("e", "d")) == "d" and len(kept) == 2


@pytest.mark.parametrize("damage", ["truncate", "garbage", "other-kind", "other-salt", "empty"])
def test_a_bad_or_foreign_file_is_an_empty_cache(tmp_path: Path, damage: str) -> None:
    path = tmp_path / "s.pickle"
    s = Shelf(path, "t")
    s.put(s.key("e", "a"), "value")
    s.save()
    data = path.read_bytes()
    if damage == "truncate":
        path.write_bytes(data[: len(data) // 2])
    elif damage == "garbage":
        path.write_bytes(b"not a pickle at all")
    elif damage == "other-kind":
        write_stream(path, "u", salt("t"), [{}])
    elif damage == "other-salt":
        write_stream(path, "t", salt("t", ("other version",)), [{s.key("e", "a"): "stale"}])
    else:
        path.write_bytes(b"")
    again = Shelf(path, "t")
    assert again.get(again.key("e", "a")) is None and len(again) == 0
    again.put(again.key("e", "a"), "fresh")
    assert again.save() and Shelf(path, "t").get(again.key("e", "a")) == "fresh"


def test_the_file_format_has_a_header_then_the_objects(tmp_path: Path) -> None:
    path = tmp_path / "f.pickle"
    write_stream(path, "k", salt("k"), [1, {"a": 2}])
    assert read_stream(path, "k", salt("k"), 2) == [1, {"a": 2}]
    assert read_stream(path, "k", salt("k"), 3) is None  # truncated after the header
    with open(path, "rb") as fh:
        head = pickle.load(fh)
    assert head["kind"] == "k" and head["salt"] == salt("k")
    assert (path.stat().st_mode & 0o777) != 0o600  # readable as a plain open() would make it


def test_blobs_keep_successful_results_across_processes(tmp_path: Path) -> None:
    made: list[int] = []

    def make() -> str:
        made.append(1)
        return "<svg/>"
    one = Blobs(tmp_path / "b", "layout", "svg")
    k = one.key("svg", "digraph {}")
    assert one.text(k, make) == "<svg/>" and one.text(k, make) == "<svg/>" and len(made) == 1
    two = Blobs(tmp_path / "b", "layout", "svg")  # as a new process: only the directory remains
    assert two.text(k, make) == "<svg/>" and len(made) == 1
    assert two.text(two.key("svg", "other"), lambda: None) is None  # a failure is not kept
    assert len(list((tmp_path / "b").iterdir())) == 1


def test_rclverify_cache_lists_and_clears(tmp_path: Path) -> None:
    s = Shelf(tmp_path / "artifacts" / "cache" / "x.pickle", "x")
    s.put(s.key("e", "a"), 1)
    s.save()
    (tmp_path / "artifacts" / "cache" / "old.json").write_text("{}")
    rows = {r["file"]: r for r in kept_files(tmp_path)}
    assert rows["artifacts/cache/x.pickle"]["current"] and rows["artifacts/cache/x.pickle"]["kind"] == "x"
    assert rows["artifacts/cache/old.json"]["current"] is False
    run = [sys.executable, "-m", "rclverify.cli.commands", "cache", "-w", str(tmp_path)]
    out = subprocess.run(run, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and "x.pickle" in out.stdout and "other code: not used" in out.stdout
    out = subprocess.run(run + ["--clear"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0 and not (tmp_path / "artifacts" / "cache").exists()
    missing = subprocess.run([sys.executable, "-m", "rclverify.cli.commands", "cache", "-w", str(tmp_path / "nope")],
                             capture_output=True, text=True, timeout=60)
    assert missing.returncode == 1 and "no such workspace directory" in missing.stderr
    assert "Traceback" not in missing.stderr


def test_a_shelf_that_keeps_earlier_entries_is_not_rewritten_when_nothing_changed(tmp_path: Path) -> None:
    path = tmp_path / "s.pickle"
    s = Shelf(path, "t", keep=5)
    for x in "abc":
        s.put(s.key("e", x), x)
    assert s.save()
    again = Shelf(path, "t", keep=5)
    assert again.get(again.key("e", "a")) == "a"
    assert not again.save()  # used one, keeps all three: the file already holds them


_MAKER = """
import sys, time
from pathlib import Path
from rclverify.core.cache import Blobs
d, log = Path(sys.argv[1]), Path(sys.argv[2])
b = Blobs(d, "summaries", "json")
def make():
    with log.open("a") as f:
        f.write("made\\n")
    time.sleep(0.4)  # long enough that the other process finds the claim
    return "the entry"
print(b.text(b.key("x", "same inputs"), make, wait_s=10))
"""


def test_claimed_blobs_are_made_once_by_two_processes(tmp_path: Path) -> None:
    """Two processes asking for the same entry at once: one makes it, the
    other waits for its file; no claim is left."""
    log = tmp_path / "log"
    procs = [subprocess.Popen([sys.executable, "-c", _MAKER, str(tmp_path / "b"), str(log)],
                              stdout=subprocess.PIPE, text=True) for _ in range(2)]
    outs = [p.communicate(timeout=60)[0].strip() for p in procs]
    assert outs == ["the entry", "the entry"]
    assert log.read_text() == "made\n"
    assert sorted(f.suffix for f in (tmp_path / "b").iterdir()) == [".json"]


def test_a_claim_left_behind_or_given_up_only_costs_the_wait(tmp_path: Path) -> None:
    """A claim whose process died is waited on for ``wait_s`` only; a claim
    whose maker failed (no file, claim removed) is made again at once."""
    b = Blobs(tmp_path / "b", "summaries", "json")
    k = b.key("x", "inputs")
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / f"{k.hex()}.claim").touch()  # one being written, or not rclverify's: waited on
    assert b.text(k, lambda: "made here", wait_s=0.2) == "made here"
    other = Blobs(tmp_path / "b", "summaries", "json")
    assert other.text(k, lambda: "not made", wait_s=0.2) == "made here"  # read from the file
    k2 = b.key("x", "other inputs")
    assert b.text(k2, lambda: None, wait_s=5) is None  # failed: nothing kept, no claim left
    assert not list((tmp_path / "b").glob(f"{k2.hex()}.*"))


def test_a_claim_whose_process_is_gone_is_not_waited_on(tmp_path: Path, monkeypatch) -> None:
    """A claim names its process; a waiter that finds the process gone makes
    the entry at once, without sleeping."""
    import rclverify.core.cache.store as store
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    b = Blobs(tmp_path / "b", "summaries", "json")
    k = b.key("x", "inputs")
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / f"{k.hex()}.claim").write_text(str(gone.pid))
    monkeypatch.setattr(store.time, "sleep", lambda s: pytest.fail("waited on a dead process's claim"))
    assert b.text(k, lambda: "made here", wait_s=60) == "made here"
