"""An assessor's bundle that was tampered with is refused (issue 63,
rows 6 and 8): member names that are not in normal form (they would
shadow a listed member when unpacked) and repeated names, whatever the
archive format; ``bundle --recheck`` streams the archive under the same
limits as ``--verify`` and says so in one line, never a MemoryError."""
from __future__ import annotations

import io
import json
import tarfile
import tracemalloc
import zipfile
from pathlib import Path

import pytest

from rclverify.report.bundle import archive
from rclverify.report.bundle.archive import verify_bundle
from rclverify.report.bundle.manifest import BundleError
from rclverify.cli.commands import main

RECORD = b'{"status": "met"}\n'


def _tar(path: Path, members: list[tuple[str, bytes]]) -> None:
    with tarfile.open(path, "w:gz") as t:
        for name, data in members:
            info = tarfile.TarInfo(name)
            info.size = len(data)
            t.addfile(info, io.BytesIO(data))


def _zip(path: Path, members: list[tuple[str, bytes]]) -> None:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        for name, data in members:
            z.writestr(name, data)


def _manifest(files: dict[str, bytes]) -> bytes:
    import hashlib
    return json.dumps({"files": {n: {"sha256": hashlib.sha256(d).hexdigest()} for n, d in files.items()}}).encode()


@pytest.mark.parametrize("write", [_tar, _zip])
@pytest.mark.parametrize("extra", ["artifacts/./notes/REQ3.txt", "artifacts//notes/REQ3.txt", "./artifacts/notes/REQ3.txt",
                                   "artifacts/notes/x/../REQ3.txt"])
def test_a_member_name_not_in_normal_form_is_refused(tmp_path: Path, write, extra: str) -> None:  # type: ignore[no-untyped-def]
    listed = {"artifacts/notes/REQ3.txt": b"proved\n"}
    path = tmp_path / ("b.zip" if write is _zip else "b.tar.gz")
    write(path, [("MANIFEST.json", _manifest(listed)), *listed.items(), (extra, b"refuted\n")])
    with pytest.raises(BundleError) as exc:
        verify_bundle(path)
    assert any(extra in p and "not a normalized member name" in p for p in exc.value.problems), exc.value.problems


def test_a_repeated_member_is_refused(tmp_path: Path) -> None:
    listed = {"artifacts/notes/REQ3.txt": b"proved\n"}
    path = tmp_path / "b.tar.gz"
    _tar(path, [("MANIFEST.json", _manifest(listed)), *listed.items(), ("artifacts/notes/REQ3.txt", b"refuted\n")])
    with pytest.raises(BundleError) as exc:
        verify_bundle(path)
    assert any("repeated" in p for p in exc.value.problems)


def test_recheck_streams_under_the_verify_limits(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    # the limits scaled down (512 MiB -> 1 MiB) so that the bomb is small to write; the code path is the same
    monkeypatch.setattr(archive, "MAX_MEMBER_BYTES", 1024 * 1024)
    path = tmp_path / "bomb.zip"
    _zip(path, [("artifacts/crosscheck/index.json", RECORD), ("artifacts/zeros.bin", bytes(6 * 1024 * 1024))])
    assert path.stat().st_size < 64 * 1024
    tracemalloc.start()
    try:
        assert main(["bundle", "--recheck", str(path)]) == 1
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    err = capsys.readouterr().err
    assert "artifacts/zeros.bin: 6291456 bytes, more than the 1048576 a bundle member may have; not checked" in err
    assert "Traceback" not in err and peak < 4 * 1024 * 1024


def test_a_signed_bundle_fails_verification_when_re_sealed_by_another_hand(tmp_path: Path,
                                                                            capsys: pytest.CaptureFixture[str]) -> None:
    """Row 7: the seals and the manifest are digests anyone can make again;
    the author's Ed25519 signature over the manifest is not."""
    from test_bundle import TOOLS, _workspace

    from rclverify.report.bundle.archive import write_bundle
    from rclverify.report.bundle.signature import load_private_key
    from rclverify.records.sealed import sealed
    from rclverify.records.store import dumps
    from rclverify.model.plan.load import load_plan
    ws = _workspace(tmp_path / "ws")
    key = tmp_path / "author.pem"
    assert main(["bundle", "--keygen", str(key)]) == 0
    assert "fingerprint SHA256:" in capsys.readouterr().out
    assert (key.stat().st_mode & 0o777) == 0o600
    assert main(["bundle", "--keygen", str(key)]) == 1  # never overwritten
    out = tmp_path / "b.tar.gz"
    write_bundle(ws, load_plan(ws), out, TOOLS, key=load_private_key(key))
    capsys.readouterr()
    assert main(["bundle", "--verify", str(out), "--key", f"{key}.pub"]) == 0
    assert "signed by the pinned key SHA256:" in capsys.readouterr().out
    # another hand swaps a record, seals it again and writes the manifest again: the seals and manifest hold
    forged = tmp_path / "forged.tar.gz"
    with tarfile.open(out) as t:
        members = {m.name: t.extractfile(m).read() for m in t if m.isfile()}  # type: ignore[union-attr]
    record = "artifacts/evidence/Sensor.g1.hoare.json"
    members[record] = dumps(sealed({"obligation": "Sensor.g1.hoare", "status": "discharged", "input_hashes": {}})).encode()
    manifest = json.loads(members["MANIFEST.json"])
    import hashlib
    manifest["files"][record]["sha256"] = hashlib.sha256(members[record]).hexdigest()
    members["MANIFEST.json"] = dumps(manifest).encode()
    _tar(forged, list(members.items()))
    assert main(["bundle", "--verify", str(forged)]) == 0  # the documented limit without a key
    assert "no key pinned" in capsys.readouterr().out
    assert main(["bundle", "--verify", str(forged), "--key", f"{key}.pub"]) == 1
    assert "MANIFEST.sig: the signature does not hold for the pinned key" in capsys.readouterr().err
    unsigned = tmp_path / "unsigned.tar.gz"
    write_bundle(ws, load_plan(ws), unsigned, TOOLS)
    assert main(["bundle", "--verify", str(unsigned), "--key", f"{key}.pub"]) == 1
    assert "MANIFEST.sig: missing: the bundle is not signed" in capsys.readouterr().err
    assert main(["bundle", "--verify", str(out), "--key", str(key)]) == 1  # a private key is not a public one
    assert "not a PEM public key" in capsys.readouterr().err
