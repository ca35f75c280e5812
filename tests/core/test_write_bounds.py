"""Where the one writer may write (docs/integrity.md, "Where outputs go"); the reads: test_read_bounds.py.

Each refusal has its control beside it: the same call on a regular file, a
link that stays inside, a path the user named.
Nothing here may hang: every FIFO case runs under a thread with a deadline.
"""
from __future__ import annotations

import errno
import os
import stat
import threading
import time
from pathlib import Path
from typing import Callable

import pytest

from rclverify.core import atomic
from rclverify.core.atomic import atomic_write_bytes, atomic_write_text, holds, output_target, write_json
from rclverify.core.within import Refused, escape_reason, outside
from rclverify.model.plan import paths as plan_paths
from rclverify.records.published import write_published

pytestmark = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")


def _bounded(fn: Callable[[], object], seconds: float = 20.0) -> object:
    """Run ``fn`` in a thread; fail (instead of hanging the suite) when it has not returned in ``seconds``."""
    box: list[object] = []

    def run() -> None:
        try:
            box.append(fn())
        except BaseException as exc:  # handed to the test
            box.append(exc)

    t = threading.Thread(target=run, daemon=True)
    t.start()
    t.join(seconds)
    assert not t.is_alive(), f"{fn} did not return within {seconds} s"
    if isinstance(box[0], BaseException):
        raise box[0]
    return box[0]


def _device(tmp_path: Path) -> Path:
    """A character device equal to /dev/null made in ``tmp_path`` (root), else the machine's own."""
    dn = tmp_path / "dn"
    try:
        os.mknod(dn, stat.S_IFCHR | 0o666, os.makedev(1, 3))
        return dn
    except PermissionError:
        return Path("/dev/null")


@pytest.fixture
def ws(tmp_path: Path) -> Path:
    root = tmp_path / "ws"
    (root / "reports").mkdir(parents=True)
    return root


def test_a_link_out_of_the_workspace_is_refused_and_the_outside_file_kept(ws: Path, tmp_path: Path) -> None:
    outside_file = tmp_path / "victim.txt"
    outside_file.write_text("keep\n")
    link = ws / "reports" / "assurance.md"
    link.symlink_to(outside_file)
    for write in (lambda: write_published(link, "report\n", ws), lambda: atomic_write_text(link, "r\n", within=ws),
                  lambda: write_json(link, {"a": 1}, within=ws)):
        with pytest.raises(Refused, match="outside the workspace .through a symbolic link."):
            write()
    assert outside_file.read_text() == "keep\n" and link.is_symlink()
    # control: a link that stays inside is followed (the link stays a link), and the user's own path goes anywhere
    inside = ws / "kept.md"
    inside.write_text("old\n")
    link.unlink()
    link.symlink_to(inside)
    assert write_published(link, "report\n", ws) and inside.read_text() == "report\n" and link.is_symlink()
    link.unlink()
    link.symlink_to(outside_file)
    atomic_write_text(link, "named\n", named=True)
    assert outside_file.read_text() == "named\n"


def test_a_reports_folder_linked_out_is_refused(ws: Path, tmp_path: Path) -> None:
    away = tmp_path / "away"
    away.mkdir()
    (ws / "reports").rmdir()
    (ws / "reports").symlink_to(away)
    with pytest.raises(Refused, match="outside the workspace"):
        write_published(ws / "reports" / "assurance.sarif", "{}\n", ws)
    assert not list(away.iterdir())
    assert write_published(ws / "reports" / "assurance.sarif", "{}\n") and (away / "assurance.sarif").is_file()


def test_a_fifo_or_device_not_named_is_never_opened(ws: Path, tmp_path: Path) -> None:
    fifo = ws / "reports" / "assurance.md"
    os.mkfifo(fifo)
    dn = _device(ws / "reports")
    for target in (fifo, dn):
        bound = ws if target.is_relative_to(ws) else None
        for write in (lambda: write_published(target, "report\n", bound), lambda: atomic_write_text(target, "x\n"),
                      lambda: atomic_write_bytes(target, b"x", durable=True)):
            with pytest.raises(Refused, match="not a regular file; rclverify writes into a FIFO or a device only "
                                              "when the command line names it"):
                _bounded(write)
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode) and stat.S_ISCHR(os.stat(dn).st_mode)
    assert not _bounded(lambda: holds(fifo, b""))  # a comparison read never waits on it either
    plain = ws / "reports" / "assurance.json"
    assert write_published(plain, "{}\n", ws) and plain.read_text() == "{}\n"  # control


def test_a_named_fifo_with_no_reader_fails_within_the_wait(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(atomic, "READER_WAIT_S", 0.3)
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    started = time.monotonic()
    with pytest.raises(Refused, match=r"FIFO no process reads \(none opened it within 0.3 s\)") as err:
        _bounded(lambda: atomic_write_text(fifo, "out\n", named=True))
    assert err.value.errno == errno.ENXIO and 0.3 <= time.monotonic() - started < 5
    # control: a reader that opens the FIFO a little after the writer started is waited for
    got: list[bytes] = []
    reader = threading.Timer(0.1, lambda: got.append(fifo.read_bytes()))
    reader.start()
    atomic_write_text(fifo, "out\n", named=True)
    reader.join(10)
    assert got == [b"out\n"]


def test_a_named_fifo_whose_reader_stops_reading_times_out(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(atomic, "SPECIAL_WRITE_TIMEOUT_S", 0.5)
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    fd = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)  # a reader that never reads
    try:
        started = time.monotonic()
        with pytest.raises(TimeoutError, match="took no output for 0.5 s"):
            _bounded(lambda: atomic_write_bytes(fifo, b"x" * (4 << 20), named=True))
        assert time.monotonic() - started < 10
        drained = b""
        while chunk := os.read(fd, 1 << 16):
            drained += chunk
        atomic_write_bytes(fifo, b"small\n", named=True)  # control: room in the pipe, written at once
        assert os.read(fd, 100) == b"small\n" and 0 < len(drained) < 4 << 20
    finally:
        os.close(fd)


def test_a_named_device_is_written_in_place(tmp_path: Path) -> None:
    dn = _device(tmp_path)
    assert output_target(dn, named=True) == Path(os.path.realpath(dn))
    atomic_write_bytes(dn, b"discarded", named=True)
    assert stat.S_ISCHR(os.stat(dn).st_mode)
    assert output_target(tmp_path / "new.txt", named=True) is None  # a regular (missing) file: the atomic path


def test_a_socket_is_refused_even_when_named(tmp_path: Path) -> None:
    import socket
    sock_path = tmp_path / "s"
    s = socket.socket(socket.AF_UNIX)
    try:
        s.bind(str(sock_path))
        with pytest.raises(Refused, match="a socket, not a regular file"):
            atomic_write_text(sock_path, "x", named=True)
    finally:
        s.close()


def test_the_bundle_and_the_plan_use_the_one_escape_rule(ws: Path, tmp_path: Path) -> None:
    assert plan_paths.escape_reason is escape_reason
    (tmp_path / "secret").write_text("s")
    (ws / "leak").symlink_to(tmp_path / "secret")
    (ws / "fine").symlink_to(ws / "reports")
    assert escape_reason(ws, "leak") is not None and outside(ws, ws / "leak") == (tmp_path / "secret").resolve()
    assert escape_reason(ws, "fine") is None and outside(ws, ws / "fine" / "x") is None
    assert escape_reason(ws, "../x") == "climbs out of the workspace with '..'"
