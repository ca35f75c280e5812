"""What Debian 12's own Python (3.11.2) needs: the suite, run with it from a
clean clone, failed three tests.  `tarfile`'s `filter=` does not exist there
(the cluster's shipped workspace is unpacked by hand, each member checked),
and an enum member is pickled as `getattr(cls, name)` (the kept ROS scan was
refused as unsafe and never reused: every rescan parsed every file)."""
from __future__ import annotations

import io
import pickle
import tarfile
from pathlib import Path

import pytest

from rclverify.app.cluster_files import ShippingError, _extract
from rclverify.core.cache.safeload import loads


def _tar(members: list[tuple[str, bytes | None, str | None]]) -> tarfile.TarFile:
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:") as tar:
        for name, data, link in members:
            info = tarfile.TarInfo(name)
            if link is not None:
                info.type, info.linkname = tarfile.SYMTYPE, link
                tar.addfile(info)
            else:
                info.size = len(data or b"")
                tar.addfile(info, io.BytesIO(data or b""))
    buf.seek(0)
    return tarfile.open(fileobj=buf, mode="r:")


def test_a_shipped_workspace_unpacks_files_and_refuses_what_would_leave_or_link(tmp_path: Path) -> None:
    _extract(_tar([("contracts/a.rcl", b"node A {}", None)]), tmp_path / "ok")
    assert (tmp_path / "ok" / "contracts" / "a.rcl").read_bytes() == b"node A {}"
    for bad in ([("../evil.txt", b"x", None)], [("link", None, "/etc/passwd")]):
        with pytest.raises(ShippingError):
            _extract(_tar(bad), tmp_path / "bad")
    assert not (tmp_path / "evil.txt").exists()


class _ByName:
    """Pickles as ``getattr(owner, name)``, as Python 3.11.0-3.11.3 pickle an enum member."""

    def __init__(self, owner: object, name: str) -> None:
        self.owner, self.name = owner, name

    def __reduce__(self) -> tuple[object, tuple[object, str]]:
        return getattr, (self.owner, self.name)


def test_an_enum_member_pickled_by_name_loads_and_nothing_else_does() -> None:
    from rosbags.interfaces import Nodetype  # a kept enumeration (the ROS scan's field kinds)
    assert loads(pickle.dumps(_ByName(Nodetype, "BASE"))) is Nodetype.BASE
    with pytest.raises(pickle.UnpicklingError):  # any other attribute through getattr is refused
        loads(pickle.dumps(_ByName(Nodetype, "__dict__")))
    with pytest.raises(pickle.UnpicklingError):  # and so is an object the cache does not keep
        loads(pickle.dumps(_ByName(Path("x"), "parent")))
