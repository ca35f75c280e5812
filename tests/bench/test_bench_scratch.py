"""bench/_scratch.py: the benches' scratch folder, and the file system named in their headers."""
from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

SCRATCH = Path(__file__).resolve().parents[2] / "bench" / "_scratch.py"


@pytest.fixture(scope="module")
def scratch_mod():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location("_scratch", SCRATCH)
    assert spec and spec.loader
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _proc(tmp_path: Path, mounts: str, ext4: tuple[str, ...] = (), jbd2: tuple[str, ...] = ()) -> Path:
    proc = tmp_path / "proc"
    (proc / "fs" / "ext4").mkdir(parents=True)
    (proc / "fs" / "jbd2").mkdir(parents=True)
    (proc / "mounts").write_text(mounts, encoding="utf-8")
    for name in ext4:
        (proc / "fs" / "ext4" / name).mkdir()
    for name in jbd2:
        (proc / "fs" / "jbd2" / name).mkdir()
    return proc


MOUNTS = ("/dev/vdc /data/my\\040bench xfs rw 0 0\n"  # a longer mount point before a shorter one: length wins
          "/dev/vdb /data ext4 rw 0 0\n"
          "tmpfs /dev/shm tmpfs rw 0 0\n"
          "/dev/vda / ext4 rw,relatime 0 0\n")


def test_an_ext4_without_a_journal_is_named_so(scratch_mod, tmp_path: Path) -> None:
    proc = _proc(tmp_path, MOUNTS, ext4=("vda", "vdb"), jbd2=("vdb-8",))
    line = scratch_mod.describe(Path("/srv/ws"), proc)
    assert line.startswith("file system: ext4 without a journal on /"), line
    assert scratch_mod.describe(Path("/data/ws"), proc) == "file system: ext4 with a journal on /data"


def test_the_longest_mount_point_wins_and_other_types_are_named(scratch_mod, tmp_path: Path) -> None:
    proc = _proc(tmp_path, MOUNTS, ext4=("vda", "vdb"))
    assert scratch_mod.describe(Path("/dev/shm/x"), proc) == "file system: tmpfs on /dev/shm"
    assert scratch_mod.describe(Path("/data/my bench/ws"), proc) == "file system: xfs on /data/my bench"
    assert scratch_mod.describe(Path("/data/mybench"), proc).startswith("file system: ext4 without a journal on /data")
    assert scratch_mod.describe(Path("/dev/shmem"), proc).startswith("file system: ext4 without a journal on / ")


def test_what_cannot_be_read_is_unknown(scratch_mod, tmp_path: Path) -> None:
    assert scratch_mod.describe(Path("/"), tmp_path / "no-proc") == "file system: unknown"
    proc = _proc(tmp_path, MOUNTS)  # the device is not in fs/ext4: its journal cannot be looked up
    assert scratch_mod.describe(Path("/srv"), proc) == "file system: ext4 on /"


def test_every_run_gets_a_new_folder_and_none_is_deleted_before_the_end(scratch_mod) -> None:
    with scratch_mod.scratch() as folders:
        first = next(folders)
        (first / "f").write_text("x", encoding="utf-8")
        second = next(folders)
        assert first != second and second.is_dir() and not any(second.iterdir())
        assert (first / "f").read_text(encoding="utf-8") == "x"
        base = first.parent
    assert not base.exists()
