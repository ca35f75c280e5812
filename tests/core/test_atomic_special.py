"""The one writer never destroys what it writes over: a device, a FIFO and a
symbolic link named as an output (``-o FILE``) are written through, never
replaced by a regular file; a regular file is replaced atomically.  (Where a
write may go at all: tests/core/test_write_bounds.py.)"""
from __future__ import annotations

import os
import stat
import threading
from pathlib import Path

import pytest

from rclverify.cli.commands import main
from rclverify.core.atomic import atomic_write_bytes, atomic_write_text, move_into_place
from rclverify.core.within import Refused
from rclverify.lang.errors import RclError
from rclverify.lang.output import write_atomic


def _null_device(tmp_path: Path) -> Path:
    """A character device equal to /dev/null made in ``tmp_path`` (root), else the machine's own."""
    dn = tmp_path / "dn"
    try:
        os.mknod(dn, stat.S_IFCHR | 0o666, os.makedev(1, 3))
        return dn
    except PermissionError:
        return Path("/dev/null")


def test_device_is_written_in_place_not_replaced(tmp_path: Path) -> None:
    dn = _null_device(tmp_path)
    before = os.stat(dn)
    atomic_write_bytes(dn, b"discarded\n", durable=True, named=True)
    atomic_write_text(dn, "again\n", named=True)
    write_atomic(dn, "through -o\n")
    with pytest.raises(Refused, match="character device, not a regular file"):  # not named: never opened
        atomic_write_text(dn, "an artifact\n")
    after = os.stat(dn)
    assert stat.S_ISCHR(after.st_mode)
    assert (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev)
    assert not list(dn.parent.glob(f".{dn.name}.*.tmp")) or dn.parent == Path("/dev")


def test_fifo_is_written_in_place(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()))
    reader.start()
    atomic_write_bytes(fifo, b"to the reader\n", named=True)
    reader.join(timeout=10)
    assert got == [b"to the reader\n"]
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_symlink_stays_a_link_and_its_target_changes(tmp_path: Path) -> None:
    real = tmp_path / "real.txt"
    real.write_text("old\n")
    link = tmp_path / "link.txt"
    link.symlink_to(real)
    write_atomic(link, "new\n")
    assert link.is_symlink() and real.read_text() == "new\n"


def test_regular_file_replaced_and_directory_refused(tmp_path: Path) -> None:
    target = tmp_path / "out.txt"
    target.write_text("old\n")
    write_atomic(target, "new\n")
    assert target.read_text() == "new\n"
    with pytest.raises(RclError, match="cannot write output file"):
        write_atomic(tmp_path, "x")
    assert tmp_path.is_dir()


def test_move_into_place_never_replaces_a_file(tmp_path: Path) -> None:
    built = tmp_path / "built"
    built.mkdir()
    (built / "a").write_text("a")
    final = tmp_path / "final"
    final.write_text("keep")
    with pytest.raises(OSError):
        move_into_place(built, final)
    assert final.read_text() == "keep"
    final.unlink()
    move_into_place(built, final)
    assert (final / "a").read_text() == "a"


def test_cli_output_to_a_device(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``rclverify ... -o DEVICE`` leaves the device a device (the case an assessor saw replace /dev/null);
    the command runs in process, as the console script runs it."""
    dn = _null_device(tmp_path)
    ws = Path(__file__).resolve().parents[2]
    assert main(["review", "Navigation", "--workspace", str(ws), "-o", str(dn)]) == 0, capsys.readouterr().err
    assert stat.S_ISCHR(os.stat(dn).st_mode)
    plain = tmp_path / "review.yaml"
    assert main(["review", "Navigation", "--workspace", str(ws), "-o", str(plain)]) == 0, capsys.readouterr().err
    assert "Navigation" in plain.read_text()
