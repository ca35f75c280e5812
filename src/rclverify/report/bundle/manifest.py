"""What goes into an assessor's bundle, and its manifest.

Collected (workspace-relative POSIX paths, sorted):

* every regular file under ``reports/`` and ``artifacts/`` (hidden files,
  such as the temporary files of atomic writes, are left out, and so is
  ``artifacts/cache/``: a machine-local speed-up holding pickled data, which
  an assessor must never be handed to load, and the lock files
  ``artifacts/run.lock`` and ``artifacts/diagnosis.lock``, which order runs
  on one machine, and build products: compiled verifiers left under
  ``artifacts/<backend>/<Node>/spin/build/`` by earlier versions, and any
  compiled executable (ELF, Mach-O) under ``artifacts/`` -- rclverify
  builds executables in the user's cache only, and an assessor is never
  handed one to run);
* the plan, its contract files and replacement contracts, the
  Doorstop folders it reads requirements from (``requirements_from``) and
  its own standard profiles (``standards:``, docs/standards.md);
* every file the plan's evidence entries name (a directory contributes the
  files under it; the same paths :mod:`rclverify.model.plan.paths` checks), and
  every input an evidence record was hashed over;
* ``dodo.py`` when the workspace has one.

A named file that does not exist is listed under ``missing`` in the
manifest (the report says what its absence means for the evidence).  A file
that resolves outside the workspace is refused (:class:`BundleError`).
"""
from __future__ import annotations

import hashlib
import json
import platform
import re
import shutil
import subprocess
from pathlib import Path
from typing import Any, Iterable, Mapping
from importlib import import_module

import msgspec
import z3

from rclverify import __version__
from rclverify.model.plan.declarations import DECLARATIONS
from rclverify.model.plan.load import Plan
from rclverify.model.plan.paths import config_strings, escape_reason, looks_like_path
from rclverify.model.plan.entries import declared_paths
from rclverify.records.standards_rows import StandardRow, rows_of as standard_rows

#: Format tag of the manifest.
FORMAT = "rclverify-bundle/1"
MANIFEST = "MANIFEST.json"
#: Workspace folders packed whole.
TREES = ("reports", "artifacts")
#: Left out of the trees: the workspace cache (rclverify.core.cache), pickled, and the
#: lock files that order runs on this machine (rclverify.core.runlock's run.lock, the
#: diagnosis's diagnosis.lock: a process id, no evidence).
EXCLUDED = ("artifacts/cache/", "artifacts/run.lock", "artifacts/diagnosis.lock")
#: Build products under artifacts/ (a compiled SPIN verifier and its sources): never bundled.
_BUILD = re.compile(r"^artifacts/[^/]+/[^/]+/spin/build/")
#: The first bytes of a compiled executable: ELF, Mach-O (64 and 32 bit).
_EXECUTABLE_MAGIC = (b"\x7fELF", b"\xcf\xfa\xed\xfe", b"\xce\xfa\xed\xfe")


def build_product(root: Path, rel: str) -> bool:
    """Whether the workspace file ``rel`` is a build product that must not be
    bundled: under a ``spin/build/`` folder of ``artifacts/``, or a file
    under ``artifacts/`` that starts like a compiled executable."""
    if _BUILD.match(rel):
        return True
    if not rel.startswith("artifacts/"):
        return False
    try:
        with open(root / rel, "rb") as f:
            head = f.read(4)
    except OSError:
        return False
    return head.startswith(_EXECUTABLE_MAGIC)


class BundleError(Exception):
    """A bundle cannot be written or does not verify; ``problems`` lists why,
    one sentence each, naming the file concerned."""

    def __init__(self, problems: Iterable[str]) -> None:
        self.problems = list(problems)
        super().__init__("; ".join(self.problems))


def sha256_bytes(data: bytes) -> str:
    """Hex sha256 of ``data``."""
    return hashlib.sha256(data).hexdigest()


def _named(plan: Plan) -> set[str]:
    """Workspace-relative paths the plan names (contracts, replacements, evidence inputs)."""
    out = {plan.file, *plan.contracts}
    out.update(spec.rpartition(":")[0] for spec, _ in plan.replacements.values())
    if plan.requirements_from:  # Doorstop trees: their items are requirements (with each .doorstop.yml)
        from rclverify.model.plan.doorstop import doorstop_files  # deferred: optional or conditional (inside a block)
        for folder, _ in plan.requirements_from:
            out.update(doorstop_files(plan.root, folder) or [folder])

    for entries in plan.evidence.values():
        for e in entries:
            # the backend's declared path keys, a "<file>:<callable>" value by its file part (model/plan/entries.py),
            # as the plan check reads them; other strings that look like paths as they are
            entry = {"backend": e.backend, **e.config}
            declared = dict(declared_paths(entry))
            out.update(declared.values())
            keys = {p[0] for p in declared}
            rest = {k: v for k, v in e.config.items() if k != "backend" and k not in keys}
            out.update(v for _, v in config_strings(rest) if looks_like_path(plan.root, v))
    ros = getattr(plan, "ros", None) or {}  # the software the contracts are grounded in (docs/ros.md)
    for key in ("workspaces", "launch", "bags"):
        out.update(str(v) for v in ros.get(key, []) or [])
    if ros.get("mapping"):
        out.add(str(ros["mapping"]))
    # a workspace's own standard profile (the built-in ones are package data, docs/standards.md)
    out.update(c.profile.file for c in getattr(plan, "standards", ()) if not c.profile.builtin)
    return out


def _hashed_inputs(root: Path) -> set[str]:
    """Every input path an evidence record was hashed over while it existed."""
    out: set[str] = set()
    for p in sorted((root / "artifacts" / "evidence").glob("*.json")):
        try:
            hashes = json.loads(p.read_text(encoding="utf-8")).get("input_hashes", {})
            # an input recorded as "missing" (a result log not imported yet) was absent then too
            out.update(str(k) for k, h in hashes.items() if h != "missing")
        except (OSError, ValueError, AttributeError):
            continue
    return out


def _files_under(root: Path, rel: str) -> list[str]:
    base = root / rel
    out = []
    for p in base.rglob("*"):
        r = p.relative_to(root)
        if any(part.startswith(".") for part in r.parts) or not p.is_file() \
                or r.as_posix().startswith(EXCLUDED) or build_product(root, r.as_posix()):
            continue
        out.append(r.as_posix())
    return out


def collect(root: Path, plan: Plan) -> tuple[list[str], list[str]]:
    """``(files, missing)``: the sorted workspace-relative files of the bundle
    and the sorted named paths that do not exist.

    Raises :class:`BundleError` when a file would come from outside the
    workspace (a symbolic link leading out, an absolute or ``..`` path).
    """
    files: set[str] = set()
    missing: set[str] = set()
    for rel in TREES:
        if (root / rel).is_dir():
            files.update(_files_under(root, rel))
    if (root / "dodo.py").is_file():
        files.add("dodo.py")
    for rel in _named(plan) | _hashed_inputs(root):
        p = root / rel
        if p.is_dir():
            files.update(_files_under(root, rel))
        elif p.is_file():
            files.add(Path(rel).as_posix())
        else:
            missing.add(rel)
    problems = [f"{f}: {why}" for f in sorted(files) if (why := escape_reason(root, f)) is not None]
    if problems:
        raise BundleError(problems)
    return sorted(files), sorted(missing)


def _declared_versions() -> dict[str, str]:
    """Each backend tool's version, from the ``version`` function its backend's declaration names."""
    out: dict[str, str] = {}
    for d in DECLARATIONS.values():
        for t in d.tools:
            if t.version:
                module, _, function = t.version.partition(":")
                out[t.name] = str(getattr(import_module(module), function)())
    return out


def _dot_version() -> str:
    exe = shutil.which("dot")
    if exe is None:
        return "not installed"
    try:
        p = subprocess.run([exe, "-V"], capture_output=True, text=True, timeout=30, check=False)
    except (OSError, subprocess.TimeoutExpired):
        return "unidentified"
    return (p.stderr or p.stdout).strip() or "unidentified"


def tool_versions() -> dict[str, str]:
    """Versions of the tools the evidence depends on: rclverify, Z3, each backend
    tool whose declaration names a version function (Dafny, identified as its
    backend does), Hypothesis, Python, Graphviz and doit.  A tool that is absent
    is ``"not installed"``."""
    import doit  # deferred: start-up (loads doit only when called)
    from importlib import metadata  # deferred: start-up (loads importlib.metadata only when called)
    try:  # the installed distribution's version (hypothesis.__version__) without importing it
        hyp = metadata.version("hypothesis")
    except metadata.PackageNotFoundError:
        hyp = "not installed"
    return {"rclverify": __version__, "z3": z3.get_version_string(), **_declared_versions(),
            "hypothesis": hyp, "python": platform.python_version(), "graphviz": _dot_version(),
            "doit": ".".join(map(str, doit.__version__))}


def build_manifest(root: Path, plan: Plan, files: list[str], missing: list[str], contents: Mapping[str, bytes],
                   tools: Mapping[str, str]) -> dict[str, Any]:
    """The manifest (a JSON value, no timestamp).

    ``contents`` maps each of ``files`` to its bytes.  Keys: ``format``,
    ``workspace``, ``plan``, ``files`` (path -> ``{"sha256", "bytes"}``),
    ``missing``, ``tools``, ``reproduce`` (the command to run in the
    unpacked archive, and the one that checks it), ``verdict`` (the
    report's overall status and headline, when the report exists) and,
    when the plan names standards, ``standards`` (each one's clauses with
    their status and supporting obligations, docs/standards.md).
    """
    verdict: dict[str, Any] = {}
    standards: list[dict[str, Any]] = []
    if "reports/assurance.json" in contents:
        try:  # a stored report of any version: its summary read by key, its standards decoded into their rows
            report = json.loads(contents["reports/assurance.json"].decode("utf-8"))
            summary = report["summary"]
            verdict = {"status": summary["status"], "headline": summary["headline"]}
            standards = [_standard_brief(row) for row in standard_rows(report.get("standards") or ())]
        except (ValueError, KeyError, TypeError, AttributeError):  # msgspec.ValidationError is a ValueError
            verdict, standards = {}, []
    out: dict[str, Any] = {
        "format": FORMAT,
        "workspace": plan.name or root.resolve().name,
        "plan": plan.file,
        "files": {f: {"sha256": sha256_bytes(contents[f]), "bytes": len(contents[f])} for f in files},
        "missing": list(missing),
        "tools": dict(sorted(tools.items())),
        "reproduce": {"verify": f"rclverify verify -w . --plan {plan.file}",
                      "check_bundle": "rclverify bundle --verify <this archive>"},
        "verdict": verdict,
    }
    if standards:  # the evidence mapped onto the plan's standards (docs/standards.md): a traceability aid
        out["standards"] = standards
    return out


def _standard_brief(row: StandardRow) -> dict[str, Any]:
    """A report ``standards[]`` row (decoded) as the manifest carries it: the profile,
    where it comes from (``origin``: built-in with its edition, or the
    workspace file with its sha256), its level, and each clause's status,
    recommendation, why, what the plan says of it, the evidence in its scope
    and what covers it."""
    return {"profile": row.profile, "edition": row.edition, "level": row.level,
            "origin": msgspec.to_builtins(row.origin),
            "clauses": {c.id: {"status": c.status, "recommendation": c.recommendation, "why": c.why,
                               "plan": msgspec.to_builtins(c.plan),
                               "evidence": sorted({e.obligation for e in c.evidence}),
                               "covered_by": list(c.covered_by)}
                        for c in row.clauses},
            "required_not_covered": list(row.required_not_covered)}
