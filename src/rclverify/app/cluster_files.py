"""A workspace's files carried to Dask workers that do not share its file system.

A backend job reads the workspace's sources (the plan, the contracts, the
backend inputs the plan names: programs, traces, message definitions, the
property tests' implementations) and what the export stage rendered for its
node under ``artifacts/``; it writes its own artifacts there (logs, scripts,
plots) beside the evidence record.  On a worker that sees the workspace at
the same absolute path (a shared file system, or a cluster on this machine)
the job runs in place (:mod:`rclverify.app.cluster`).  On a worker that does
not, the job runs in a copy in the worker's own working folder:

* :func:`archive` packs the workspace's sources (every file but
  ``artifacts/``, ``reports/``, doit's state and hidden or cache folders) into
  one tar archive, named by their :func:`digest`.  It is sent to the
  cluster once per run (``Client.scatter``) and unpacked once per worker
  (:func:`materialise`), into ``<working folder>/rclverify-workspaces/<sha256>``;
* :func:`node_files` gives the job's own share of ``artifacts/``: the node's
  obligations, its contract snapshot and every backend's folder for the node
  (``artifacts/<backend>/<node>/``), sent with the job;
* :func:`changed_files` lists what the job wrote in its node's folders
  under ``artifacts/`` (the record itself comes back as JSON), and the
  submitting process writes those files into its workspace, atomically.

The evidence record names files by their workspace-relative paths and hashes
their contents, so a job run in a copy gives the record a run in place gives
(timing fields aside; tests/app/test_cluster.py).  Decisions: docs/scale.md,
"Workers that do not share the file system".
"""
from __future__ import annotations

import hashlib
import io
import os
import tarfile
from pathlib import Path
from rclverify.core.atomic import atomic_write_bytes, move_into_place

#: Folders of a workspace never sent: written by runs, or not part of the inputs.
SKIPPED_TOP = frozenset({"artifacts", "reports"})
#: The largest sources archive sent (bytes); a bigger workspace needs a shared file system.
MAX_ARCHIVE_BYTES = 512 * 1024 * 1024


class ShippingError(Exception):
    """The workspace's files cannot be carried to the cluster (too large, unreadable)."""


def _source_paths(root: Path) -> list[Path]:
    out = []
    for dirpath, dirnames, filenames in os.walk(root):
        here = Path(dirpath)
        rel_dir = here.relative_to(root)
        dirnames[:] = sorted(d for d in dirnames if not d.startswith(".") and d != "__pycache__"
                             and not (rel_dir == Path(".") and d in SKIPPED_TOP))
        for name in sorted(filenames):
            if name.startswith(".doit") or name.endswith(".pyc"):
                continue
            p = here / name
            if p.is_file():
                out.append(p)
    return out


def _add(tar: tarfile.TarFile, name: str, data: bytes) -> None:
    info = tarfile.TarInfo(name)
    info.size, info.mtime, info.mode = len(data), 0, 0o644
    tar.addfile(info, io.BytesIO(data))


def digest(root: Path) -> str:
    """sha256 hex of the workspace's sources: every source file's relative path
    and contents (:func:`_source_paths`).  Two folders with the same digest
    hold the same sources; a job's evidence can then come from either.

    Raises :class:`ShippingError` when a file cannot be read."""
    h = hashlib.sha256()
    for p in _source_paths(root):
        try:
            data = p.read_bytes()
        except OSError as exc:
            raise ShippingError(f"cannot read {p}: {exc.strerror}") from None
        h.update(p.relative_to(root).as_posix().encode() + b"\0" + hashlib.sha256(data).digest())
    return h.hexdigest()


def archive(root: Path) -> bytes:
    """The workspace's sources as an uncompressed tar archive with fixed metadata.

    Raises :class:`ShippingError` when a file cannot be read or the archive
    exceeds :data:`MAX_ARCHIVE_BYTES`."""
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w", format=tarfile.PAX_FORMAT) as tar:
        for p in _source_paths(root):
            try:
                data = p.read_bytes()
            except OSError as exc:
                raise ShippingError(f"cannot read {p} to send it to the cluster: {exc.strerror}") from None
            _add(tar, p.relative_to(root).as_posix(), data)
            if buf.tell() > MAX_ARCHIVE_BYTES:
                raise ShippingError(f"the workspace's sources exceed {MAX_ARCHIVE_BYTES // 2**20} MiB: run the "
                                    "workers on a file system that shares the workspace (docs/scale.md)")
    return buf.getvalue()


def node_files(root: Path, node: str) -> dict[str, bytes]:
    """The node's share of ``artifacts/`` a job reads: ``artifacts/obligations/<node>.json``
    and ``<node>/``, ``artifacts/contracts/<node>.json`` and every
    ``artifacts/<folder>/<node>/`` (relative path -> bytes)."""
    art = root / "artifacts"
    out: dict[str, bytes] = {}
    candidates = [art / "obligations" / f"{node}.json", art / "contracts" / f"{node}.json"]
    for p in candidates:
        if p.is_file():
            out[p.relative_to(root).as_posix()] = p.read_bytes()
    if art.is_dir():
        for folder in sorted(art.iterdir()):
            d = folder / node
            if folder.name not in ("evidence", "cache") and d.is_dir():
                for p in sorted(d.rglob("*")):
                    if p.is_file():
                        out[p.relative_to(root).as_posix()] = p.read_bytes()
    return out


def _safe_member(base: Path, rel: str) -> Path:
    target = (base / rel).resolve()
    if not target.is_relative_to(base.resolve()) or Path(rel).is_absolute():
        raise ShippingError(f"a shipped file would leave the worker's folder: {rel}")
    return target


def _extract(tar: tarfile.TarFile, into: Path) -> None:
    """Unpack ``tar``'s folders and regular files into ``into``, each checked to
    stay inside it (:func:`_safe_member`); a link, a device or any other member
    is a :class:`ShippingError`.  The archive is :func:`archive`'s (folders and
    regular files only).  Done by hand rather than with ``extractall(filter=
    "data")``, which Python 3.11.2 (Debian 12's) does not have."""
    for m in tar.getmembers():
        target = _safe_member(into, m.name)
        if m.isdir():
            target.mkdir(parents=True, exist_ok=True)
        elif m.isfile():
            src = tar.extractfile(m)
            if src is None:
                raise ShippingError(f"a shipped file cannot be read: {m.name}")
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(src.read())
        else:
            raise ShippingError(f"a shipped member is not a file or a folder: {m.name}")


def materialise(base: Path, name: str, blob: bytes) -> Path:
    """The workspace copy ``base/rclverify-workspaces/<name>`` (``name``: the
    sources' :func:`digest`), unpacked from ``blob`` (:func:`archive`) the
    first time into a temporary folder, checked against ``name`` and renamed
    into place, so two jobs never see half a copy.  Returns its root.
    Raises :class:`ShippingError` when the unpacked sources do not have
    that digest."""
    root = base / "rclverify-workspaces" / name
    if root.is_dir():
        return root
    tmp = root.with_name(f".{name}.{os.getpid()}.{os.urandom(4).hex()}")
    tmp.mkdir(parents=True)
    with tarfile.open(fileobj=io.BytesIO(blob), mode="r:") as tar:
        _extract(tar, tmp)
    if digest(tmp) != name:
        import shutil  # deferred: optional or conditional (inside a block)
        shutil.rmtree(tmp, ignore_errors=True)
        raise ShippingError("the workspace's sources arrived damaged (their sha256 differs)")
    try:
        move_into_place(tmp, root)
    except OSError:  # another job of this worker unpacked it first
        import shutil  # deferred: optional or conditional (inside a block)
        shutil.rmtree(tmp, ignore_errors=True)
    return root


def place(root: Path, files: dict[str, bytes]) -> None:
    """Write ``files`` (relative path -> bytes) under ``root``, atomically,
    skipping a file that already holds those bytes."""
    for rel, data in files.items():
        target = _safe_member(root, rel)
        try:
            if target.read_bytes() == data:
                continue
        except OSError:
            pass
        atomic_write_bytes(target, data)


def listing(root: Path, node: str) -> dict[str, tuple[int, int]]:
    """Every file a job of ``node`` may write: under ``root/artifacts/<folder>/<node>/``
    (the backends write nowhere else; the evidence record comes back as JSON):
    relative path -> (size, mtime in ns)."""
    art = root / "artifacts"
    out = {}
    if art.is_dir():
        for folder in art.iterdir():
            d = folder / node
            if folder.name in ("evidence", "cache") or not d.is_dir():
                continue
            for p in d.rglob("*"):
                if p.is_file():
                    st = p.stat()
                    out[p.relative_to(root).as_posix()] = (st.st_size, st.st_mtime_ns)
    return out


def changed_files(root: Path, node: str, before: dict[str, tuple[int, int]]) -> dict[str, bytes]:
    """The files of ``node``'s folders written since ``before`` (:func:`listing`): path -> bytes."""
    return {rel: (root / rel).read_bytes() for rel, stamp in listing(root, node).items() if before.get(rel) != stamp}
