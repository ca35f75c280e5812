"""Write an assessor's bundle as one archive and check an archive against
its manifest.

Formats: gzip-compressed tar (``.tar.gz``/``.tgz``, the default) or zip
(``.zip``), both with the standard library.  Archives are deterministic:
members in sorted path order, ``MANIFEST.json`` first, every mtime fixed
(1980-01-01 for zip, the epoch for tar and the gzip header), owner 0, mode
0644, so the same workspace gives the same bytes.  The archive is written to
a temporary file beside the destination and moved into place, so a failure
never leaves a half-written archive or destroys an earlier one.
"""
from __future__ import annotations

import gzip
import hashlib
import io
import json
import posixpath
import tarfile
import zipfile
import zlib
from pathlib import Path, PurePosixPath
from typing import Any, Iterator, Mapping

from rclverify.records.store import atomic_write_bytes, dumps
from rclverify.model.plan.load import Plan
from rclverify.report.bundle.manifest import MANIFEST, BundleError, build_manifest, collect, tool_versions
from rclverify.records.sealed import is_sealed_path, check_text
from rclverify.records.store import SEAL
from rclverify.stages.crosscheck.stage import INDEX
from rclverify.stages.crosscheck.ties import TAIL_BYTES, bundle_items, index_rows, is_tied, tie_problems

_ZIP_TIME = (1980, 1, 1, 0, 0, 0)


def is_zip(path: Path) -> bool:
    """``path`` is to be a zip archive (by its suffix)."""
    return path.suffix.lower() == ".zip"


def _tar_bytes(members: Mapping[str, bytes]) -> bytes:
    raw = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=raw, mtime=0) as gz:
        with tarfile.open(fileobj=gz, mode="w", format=tarfile.GNU_FORMAT) as tar:
            for name, data in members.items():
                info = tarfile.TarInfo(name)
                info.size, info.mtime, info.mode = len(data), 0, 0o644
                info.uid = info.gid = 0
                info.uname = info.gname = ""
                tar.addfile(info, io.BytesIO(data))
    return raw.getvalue()


def _zip_bytes(members: Mapping[str, bytes]) -> bytes:
    raw = io.BytesIO()
    with zipfile.ZipFile(raw, "w") as zf:
        for name, data in members.items():
            info = zipfile.ZipInfo(name, date_time=_ZIP_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            zf.writestr(info, data)
    return raw.getvalue()


def write_bundle(root: Path, plan: Plan, out: Path, tools: Mapping[str, str] | None = None,
                 key: Any = None, named: bool = False) -> dict[str, Any]:
    """Pack the workspace ``root`` (plan ``plan``) into the archive ``out``;
    with ``key`` (an Ed25519 private key, :mod:`.signature`) the member
    ``MANIFEST.sig`` signs the manifest's bytes.

    ``named``: the user named ``out`` (``-o``), which may then be a FIFO or
    device, written in place (:func:`rclverify.core.atomic.atomic_write_bytes`);
    a default ``out`` is written only as a regular file.
    ``tools`` overrides :func:`.manifest.tool_versions` (tests).  Returns the
    manifest.  Raises :class:`BundleError` when the report has not been
    written yet, a file comes from outside the workspace or a record's seal
    does not hold (:func:`seal_problem`), ``OSError`` when
    a file cannot be read or ``out`` cannot be written.
    """
    if not (root / "reports" / "assurance.json").is_file():
        raise BundleError(["reports/assurance.json: no assurance report yet; run `doit verify` first"])
    files, missing = collect(root, plan)
    out_res = out.resolve()
    files = [f for f in files if (root / f).resolve() != out_res]
    contents = {f: (root / f).read_bytes() for f in files}
    # a record whose seal does not hold says what rclverify never recorded: never handed to an assessor
    broken = [p for f in files if is_record(f) and (p := seal_problem(f, contents[f]))]
    if broken:
        raise BundleError(broken)
    manifest = build_manifest(root, plan, files, missing, contents, tools if tools is not None else tool_versions())
    members = {MANIFEST: dumps(manifest).encode("utf-8")}
    if key is not None:
        from rclverify.report.bundle.signature import SIGNATURE, sign  # deferred: optional or conditional (inside a block)
        members[SIGNATURE] = sign(members[MANIFEST], key)
    members.update(contents)
    out.parent.mkdir(parents=True, exist_ok=True)
    # durable, and 0644: an archive is for others to read
    atomic_write_bytes(out, _zip_bytes(members) if is_zip(out) else _tar_bytes(members), durable=True, mode=0o644,
                       named=named)
    return manifest


def _unsafe(name: str) -> bool:
    """Whether member ``name`` may not be believed as a path: absolute, with
    ``..``, a backslash, or not in normal form (``./``, ``//``, a trailing
    ``/``: ``artifacts/./requirements/R.json`` names the same file as a
    listed member and would shadow it when unpacked)."""
    p = PurePosixPath(name)
    return p.is_absolute() or ".." in p.parts or "\\" in name or posixpath.normpath(name) != name \
        or name.startswith("./")


def _each_member(path: Path, problems: list[str]) -> Iterator[tuple[str, int, Any]]:
    """``(name, declared size, open binary stream)`` of each regular-file
    member of the archive at ``path`` (tar.gz or zip), in order, streamed
    (tarfile's headers are not kept).  A member that is a link, a device, an
    absolute or ``..`` path, or repeated is not yielded but named in
    ``problems``.  Archive errors propagate (callers turn them into
    :class:`BundleError`)."""
    seen: set[str] = set()
    if zipfile.is_zipfile(path):
        with zipfile.ZipFile(path) as zf:
            for info in zf.infolist():
                if info.is_dir():
                    continue
                if _unsafe(info.filename) or info.filename in seen:
                    problems.append(f"{info.filename}: unsafe, repeated or not a normalized member name")
                    continue
                seen.add(info.filename)
                with zf.open(info) as fh:
                    yield info.filename, info.file_size, fh
    else:
        with tarfile.open(path, "r:*") as tar:
            for m in tar:  # streamed: members are visited in order, never all held
                if m.isdir():
                    continue
                if not m.isfile() or _unsafe(m.name) or m.name in seen:
                    problems.append(f"{m.name}: unsafe, repeated, not a normalized member name or not a regular file")
                    continue
                seen.add(m.name)
                member = tar.extractfile(m)
                yield m.name, m.size, member if member is not None else io.BytesIO(b"")
                setattr(tar, "members", [])  # tarfile keeps every header it read (a private list): not needed here


_ARCHIVE_ERRORS = (OSError, tarfile.TarError, zipfile.BadZipFile, EOFError, zlib.error)


def read_members(path: Path) -> dict[str, bytes]:
    """The regular-file members of the archive at ``path`` (tar.gz or zip).

    Raises :class:`BundleError` for an unreadable or corrupt archive, and for
    members that are links, devices, absolute or ``..`` paths, or repeated.
    Nothing is extracted to disk.
    """
    problems: list[str] = []
    try:
        out = {name: fh.read() for name, _, fh in _each_member(path, problems)}
    except _ARCHIVE_ERRORS as exc:
        raise BundleError([f"cannot read the archive: {exc}"]) from None
    if problems:
        raise BundleError(problems)
    return out


#: Largest member ``--verify`` hashes (bytes): a bundle holds text records, contracts, reports and the
#: plan's inputs; a larger member is refused from its header, before any of it is read (a small
#: compressed archive can declare gigabytes: a decompression bomb).
MAX_MEMBER_BYTES = 512 * 1024 * 1024
#: Largest total of the members' sizes ``--verify`` reads (bytes).
MAX_TOTAL_BYTES = 2 * 1024 * 1024 * 1024
#: Largest ``MANIFEST.json`` (bytes): the one member read into memory.
MAX_MANIFEST_BYTES = 64 * 1024 * 1024
_CHUNK = 1024 * 1024


#: Largest record whose seal ``--verify`` checks (bytes): evidence records are a few KiB; a larger
#: JSON record under ``artifacts/`` is named as not checked.
MAX_RECORD_BYTES = 16 * 1024 * 1024


def is_record(name: str) -> bool:
    """Whether member ``name`` may be a sealed record: a JSON file under
    ``artifacts/`` (its seal is checked when it has one, or must have one:
    :func:`must_be_sealed`)."""
    return name.startswith("artifacts/") and name.endswith(".json")


def must_be_sealed(name: str) -> bool:
    """Whether member ``name`` is a record rclverify always writes sealed:
    an evidence record (``artifacts/evidence/<id>.json``) or one of
    :func:`rclverify.records.sealed.is_sealed_path`."""
    return (name.startswith("artifacts/evidence/") and name.count("/") == 2 and name.endswith(".json")) \
        or is_sealed_path(name)


def _hash_stream(name: str, fh: Any, limit: int, keep: bool = False) -> tuple[str, int, bytes | None, bytes]:
    """``(sha256 hex, size, bytes or None, last bytes)`` of the stream ``fh``
    read in chunks of :data:`_CHUNK`: memory stays bounded whatever the
    member's size.  The bytes are kept only for :data:`MANIFEST` and for
    records (:func:`is_record`, or any member when ``keep``) of at most
    :data:`MAX_RECORD_BYTES`, whose seals are checked; the last bytes are
    the last :data:`TAIL_BYTES` (a kept query's or proof's tie line).
    Raises :class:`BundleError` when more than ``limit`` bytes come out (a
    zip member whose header understates its size)."""
    h = hashlib.sha256()
    size = 0
    tail = b""
    kept: list[bytes] | None = [] if name == MANIFEST or is_record(name) or keep else None
    while chunk := fh.read(_CHUNK):
        size += len(chunk)
        if size > limit:
            raise BundleError([f"{name}: more than {limit} bytes, the most a bundle member may have; not checked"])
        h.update(chunk)
        tail = (tail + chunk[-TAIL_BYTES:])[-TAIL_BYTES:]
        if kept is not None:
            kept.append(chunk)
            if name != MANIFEST and size > MAX_RECORD_BYTES:
                kept = None
    return h.hexdigest(), size, b"".join(kept) if kept is not None else None, tail


def scan_members(path: Path, seals: list[str] | None = None, kept: dict[str, bytes] | None = None,
                 signature: dict[str, bytes] | None = None, ties: dict[str, bytes] | None = None
                 ) -> tuple[bytes | None, dict[str, tuple[str, int]]]:
    """``(MANIFEST.json bytes or None, {member: (sha256, size)})`` of the
    archive at ``path`` (tar.gz or zip), every member streamed and hashed in
    chunks (bounded memory), nothing extracted to disk.  When ``seals`` is
    a list, every record member's seal is checked as it is read
    (:func:`seal_problem`) and each problem appended to it.  When ``kept``
    is a dict, the bytes of every member under ``artifacts/`` (records and
    stored queries) of at most :data:`MAX_RECORD_BYTES` are put in it, by
    name (``bundle --recheck``); ``signature``, when a dict, gets the
    bytes of ``MANIFEST.sig`` (:mod:`.signature`) if the archive has it;
    ``ties``, when a dict, the bytes of every record (:func:`is_record`, of
    at most :data:`MAX_RECORD_BYTES`) and the last :data:`TAIL_BYTES` of
    every kept query and proof (:func:`rclverify.stages.crosscheck.ties.is_tied`).

    Raises :class:`BundleError` for an unreadable or corrupt archive, for
    members that are links, devices, absolute or ``..`` paths, or repeated,
    and, with one sentence and before reading it, for a member larger than
    :data:`MAX_MEMBER_BYTES` (:data:`MAX_MANIFEST_BYTES` for the manifest)
    or members larger than :data:`MAX_TOTAL_BYTES` together.
    """
    out: dict[str, tuple[str, int]] = {}
    manifest: bytes | None = None
    problems: list[str] = []
    total = 0

    def admit(name: str, size: int) -> int:
        nonlocal total
        limit = MAX_MANIFEST_BYTES if name == MANIFEST else MAX_MEMBER_BYTES
        if size > limit:
            raise BundleError([f"{name}: {size} bytes, more than the {limit} a bundle member may have; not checked"])
        total += size
        if total > MAX_TOTAL_BYTES:
            raise BundleError([f"{name}: the members come to more than {MAX_TOTAL_BYTES} bytes, the most a bundle "
                               "may hold; not checked"])
        return limit

    def record(name: str, fh: Any, limit: int) -> None:
        nonlocal manifest
        keep = (kept is not None and name.startswith("artifacts/")) or (signature is not None and name == "MANIFEST.sig")
        digest, size, data, tail = _hash_stream(name, fh, limit, keep)
        out[name] = (digest, size)
        if ties is not None and is_tied(name):
            ties[name] = tail
        elif ties is not None and is_record(name) and data is not None:
            ties[name] = data
        if name == "MANIFEST.sig" and signature is not None and data is not None:
            signature[name] = data
        elif keep and data is not None and kept is not None:
            kept[name] = data
        if name == MANIFEST:
            manifest = data
        elif seals is not None and is_record(name):
            problem = seal_problem(name, data)
            if problem:
                seals.append(problem)
    try:
        for name, size, fh in _each_member(path, problems):
            record(name, fh, admit(name, size))
    except _ARCHIVE_ERRORS as exc:
        raise BundleError([f"cannot read the archive: {exc}"]) from None
    if problems:
        raise BundleError(problems)
    return manifest, out


def seal_problem(name: str, data: bytes | None) -> str:
    """Why the record member ``name`` (its bytes ``data``; ``None`` when it
    was too large to keep) cannot be believed, or ``""``: its seal
    (``record_sha256``, docs/integrity.md) does not match its content, it
    has none though rclverify always seals it (:func:`must_be_sealed`), or
    it cannot be read.  A JSON file with no seal that rclverify does not
    seal (a tool's own output) is not a record: ``""``."""
    if data is None:
        return f"{name}: larger than {MAX_RECORD_BYTES} bytes: its seal was not checked" if must_be_sealed(name) else ""
    try:
        text = data.decode("utf-8")
        raw = json.loads(text)
    except (UnicodeDecodeError, ValueError):
        return f"{name}: seal broken: the record is not JSON text" if must_be_sealed(name) else ""
    if not (isinstance(raw, dict) and SEAL in raw) and not must_be_sealed(name):
        return ""
    _, problem = check_text(text, "record")
    return f"{name}: seal broken: {problem}" if problem else ""


def _tie_problems(ties: Mapping[str, bytes], members: Mapping[str, Any]) -> list[str]:
    """Each kept query of the bundle not tied to its item's statement and
    each kept proof not tied to its query, one sentence naming the item
    (:func:`rclverify.stages.crosscheck.ties.tie_problems`); ``ties`` as
    :func:`scan_members` fills it, ``members`` the bundle's member names.
    Raises :class:`BundleError` when the records cannot be read back."""
    try:
        items = bundle_items(ties)
    except OSError as exc:
        raise BundleError([f"cannot read the bundle's records back: {exc}"]) from None
    rows, _ = index_rows(ties.get(INDEX))  # an index whose seal does not hold is named with the seals
    return tie_problems(items, rows, members, ties)[0]


def verify_bundle(path: Path, kept: dict[str, bytes] | None = None, key: Any = None) -> dict[str, Any]:
    """Check the archive at ``path`` against its ``MANIFEST.json``, and
    every record in it against its own seal.

    Returns the manifest when every listed file is present with its sha256,
    nothing else is in the archive and every record's seal holds.  Raises
    :class:`BundleError` listing each changed, missing or extra file by
    name, and each record whose seal does not hold (:func:`seal_problem`: a
    record edited before it was packed, or in the archive with the manifest
    edited to match, says what rclverify never recorded), and a missing or
    malformed manifest, and a member too large to check
    (:func:`scan_members`), and each kept query not tied to the statement
    its sealed record states and each kept proof not tied to its query
    (:func:`rclverify.stages.crosscheck.ties.tie_problems`: a query borrowed
    from another item, two proofs swapped).  Members are streamed: memory stays bounded
    whatever their size.  ``kept``: as :func:`scan_members` (the records'
    bytes, for ``--recheck``).  ``key``: the author's pinned Ed25519 public
    key; then ``MANIFEST.sig`` must be its signature of the manifest
    (:func:`.signature.check`), else it is a problem.  The returned
    manifest has ``signed`` set to the key's fingerprint, ``None`` when no
    key was given.
    """
    from rclverify.report.bundle.signature import SIGNATURE, check, fingerprint  # deferred: start-up (loads cryptography, rclverify.report.bundle and more only when called)
    seals: list[str] = []
    signature: dict[str, bytes] = {}
    ties: dict[str, bytes] = {}
    manifest_bytes, members = scan_members(path, seals, kept, signature, ties)
    if manifest_bytes is None:
        raise BundleError([f"{MANIFEST}: missing from the archive"])
    members.pop(MANIFEST, None)
    members.pop(SIGNATURE, None)  # over the manifest, so not in it
    try:
        manifest = json.loads(manifest_bytes.decode("utf-8"))
        listed = {str(k): str(v["sha256"]) for k, v in manifest["files"].items()}
    except (ValueError, KeyError, TypeError, AttributeError) as exc:
        raise BundleError([f"{MANIFEST}: malformed manifest ({exc})"]) from None
    problems = []
    for name in sorted(listed):
        if name not in members:
            problems.append(f"{name}: missing from the archive")
        elif (h := members[name][0]) != listed[name]:
            problems.append(f"{name}: changed (sha256 {h}, manifest says {listed[name]})")
    problems += [f"{name}: in the archive but not in the manifest" for name in sorted(set(members) - set(listed))]
    problems += sorted(seals)
    problems += _tie_problems(ties, members)
    if key is not None and (why := check(manifest_bytes, signature.get(SIGNATURE), key)):
        problems.append(why)
    if problems:
        raise BundleError(problems)
    return {**manifest, "signed": fingerprint(key) if key is not None else None}
