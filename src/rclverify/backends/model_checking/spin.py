"""Running SPIN: finding it, compiling a model's verifier once, checking one claim.

SPIN's standard procedure (SPIN manual, "Verification"): ``spin -a
model.pml`` writes the verifier's C source ``pan.c`` (with every ``ltl``
block of the model as a never claim), ``gcc`` compiles it, and ``./pan -a
-N <claim>`` searches for acceptance cycles of the system with the claim
named -- a path on which the negation of the property holds.  The verdict
is the line ``State-vector ... errors: N``: ``0`` the property holds on
every path, else ``pan: wrote model.pml.trail``; ``spin -t -p -k <trail>
model.pml`` replays the trail (:mod:`.trail` reads it).

Compilation flags: ``-DNOREDUCE`` (no partial-order reduction: it brings
nothing to a one-process model, and without it every interleaving is
explored by construction), ``-DMEMLIM=<MB>`` (bounded memory: pan stops
with "pan: out of memory" rather than swapping), ``-O0`` (the verifier of
an explored graph runs in milliseconds; optimising it costs seconds of
``gcc``).  Search flags: ``-a`` acceptance cycles, no ``-f`` (weak
fairness is about processes; the model has one), ``-n`` no unreached-code
listing, ``-m<depth>`` a search depth no path of the model can exceed,
``-w<bits>`` a hash table sized to the model (:func:`hash_bits`).  A
search cut by depth or memory is ``incomplete``, never ``holds``.

A compiled verifier is an executable, so it is never taken from a
workspace (docs/integrity.md: a workspace may be anyone's clone): it is
built in the user's cache, ``$XDG_CACHE_HOME/rclverify/spin/<key>/`` (else
``~/.cache/...``; :func:`cache_dir`), where ``<key>`` is the sha256 of the
model text, SPIN's and the C compiler's versions and paths and the flags
(:func:`verifier_key`).  It is built in a temporary directory beside it and
renamed into place, so a concurrent run never sees half a build and a killed
build leaves nothing (:func:`rclverify.backends.bounded.temporary_directory`).
Each check runs in a fresh temporary directory of its own, as ``pan`` writes
its trail into its working directory.  Every tool runs through
:func:`rclverify.backends.bounded.run_bounded`: with a time limit, in its own
process group, killed with rclverify.
"""
from __future__ import annotations

import hashlib
import os
import re
import shutil
import stat
import tempfile
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from rclverify.core.atomic import move_into_place
from rclverify.core.cache.keys import user_cache_dir
from rclverify.lang.ast import Loc
from rclverify.backends.bounded import forget_directory, register_directory, run_bounded, temporary_directory

#: Install command shown when SPIN or gcc is missing (Debian/Ubuntu).
INSTALL = "apt-get install spin gcc"
#: pan's memory bound, megabytes.
MEMLIM_MB = 1024
CFLAGS = ("-O0", "-DNOREDUCE", f"-DMEMLIM={MEMLIM_MB}")
#: Default time limit of one tool run (``spin -a``, ``gcc``, one ``pan`` search), seconds.
DEFAULT_TIMEOUT_S = 300.0
#: Verifiers kept in the cache (the most recently used); older ones are removed.
KEEP_VERIFIERS = 32
#: A temporary build or run directory older than this (seconds) is a leftover of a killed run.
STALE_S = 24 * 3600
#: The layout of a cache entry; a change builds every verifier again.
CACHE_FORMAT = 2


@dataclass(frozen=True)
class Tools:
    """SPIN and the C compiler found: executables and their versions."""

    spin: str
    gcc: str
    spin_version: str
    gcc_version: str

    @property
    def version(self) -> str:
        """``Spin 6.5.2 (6 December 2019), gcc 12.2.0``."""
        return f"{self.spin_version}, {self.gcc_version}"


@dataclass(frozen=True)
class CheckResult:
    """One ``pan`` run on one claim.

    ``verdict``  ``holds`` (errors: 0, search complete), ``violated`` (an
                 acceptance cycle or a claim reaching its end: counterexample
                 in ``trail``), ``incomplete`` (search cut: ``reason``) or
                 ``error`` (``reason``);
    ``output``   pan's output; ``trail`` the trail file's text ('' if none);
    ``stored``   states stored by pan (product of model and claim); ``depth``
                 the depth reached; ``duration_s`` seconds.
    """

    verdict: str
    output: str
    trail: str = ""
    reason: str = ""
    stored: int | None = None
    depth: int | None = None
    duration_s: float = 0.0


_FOUND: dict[tuple[str, str], Tools] = {}


def find_tools(path: str | None = None) -> tuple[Tools | None, str]:
    """``(tools, "")`` when ``spin`` and ``gcc`` are on ``path`` (default
    ``$PATH``), else ``(None, reason)`` naming what is missing and the
    command that installs it.  Versions are asked once per executable pair
    in a process."""
    spin = shutil.which("spin", path=path)
    gcc = shutil.which("gcc", path=path) or shutil.which("cc", path=path)
    missing = [name for name, exe in (("spin", spin), ("gcc", gcc)) if exe is None]
    if missing:
        return None, (f"{' and '.join(missing)} not found on PATH: SPIN needs both "
                      f"(install with: {INSTALL})")
    assert spin is not None and gcc is not None
    if (spin, gcc) not in _FOUND:
        _FOUND[(spin, gcc)] = Tools(
            spin, gcc, _version([spin, "-V"], r"Spin Version (\S+) -- (.+?)\s*$", "Spin {0} ({1})"),
            _version([gcc, "--version"], r"(\d+\.\d+(?:\.\d+)?)", "gcc {0}"))
    return _FOUND[(spin, gcc)], ""


def _version(cmd: list[str], pattern: str, fmt: str) -> str:
    try:  # stopped from outside: ToolInterrupted goes up (an interrupted run records nothing)
        out = run_bounded(cmd, Path(tempfile.gettempdir()), 30.0)[0]
    except OSError:
        return "unknown"
    m = re.search(pattern, out.splitlines()[0] if out.strip() else "", re.MULTILINE)
    return fmt.format(*m.groups()) if m else (out.strip().splitlines() or ["unknown"])[0]


def _run(cmd: list[str], cwd: Path, timeout_s: float, where: Loc | None, tool: str,
         env: Mapping[str, str] | None = None) -> tuple[str, int | None, float]:
    """Run ``cmd`` (in ``env``, default rclverify's own environment); returns
    (stdout+stderr, exit code or None on timeout, seconds).  Raises
    :class:`~rclverify.backends.bounded.ToolInterrupted` (located at
    ``where``) when the tool was stopped from outside."""
    return run_bounded(cmd, cwd, timeout_s, env, where=where, tool=tool)


def cache_dir() -> Path:
    """Where verifiers are built and kept: ``user_cache_dir("spin")`` when it
    can be made and is the user's own and not writable by others; else a
    private temporary directory of this process (removed by the reaper when
    the process ends).  Never under a workspace."""
    folder = user_cache_dir("spin")
    if folder is not None:
        try:
            st = folder.stat()
            if st.st_uid == os.getuid() and not st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
                return folder
        except OSError:
            pass
    if "private" not in _PRIVATE:
        _PRIVATE["private"] = Path(tempfile.mkdtemp(prefix="rclverify-spin-"))
        register_directory(_PRIVATE["private"])  # the reaper removes it with the process
    return _PRIVATE["private"]


_PRIVATE: dict[str, Path] = {}


def verifier_key(tools: Tools, text: str) -> str:
    """The cache key of the verifier of model ``text``: sha256 (hex) of the
    cache format, the model, SPIN's and the compiler's resolved paths and
    versions, and the flags :data:`CFLAGS`."""
    parts = [str(CACHE_FORMAT), text, os.path.realpath(tools.spin), tools.spin_version,
             os.path.realpath(tools.gcc), tools.gcc_version, *CFLAGS]
    return hashlib.sha256("\0".join(parts).encode("utf-8")).hexdigest()


class CompileError(RuntimeError):
    """``spin -a`` or ``gcc`` failed, or did not finish within its time limit
    (``timed_out``); the message holds their output or says which limit."""

    def __init__(self, message: str, timed_out: bool = False) -> None:
        super().__init__(message)
        self.timed_out = timed_out


def compile_model(tools: Tools, text: str, cache: Path | None = None, timeout_s: float = DEFAULT_TIMEOUT_S,
                  where: Loc | None = None) -> Path:
    """The directory holding ``model.pml`` and its compiled ``pan`` for the
    model ``text``, built unless ``cache`` (default :func:`cache_dir`)
    already has it under :func:`verifier_key`.  Raises :class:`CompileError`
    (also when ``spin -a`` or ``gcc`` exceeds ``timeout_s`` seconds: the
    message says so), :class:`~rclverify.backends.bounded.ToolInterrupted`
    (located at ``where``) when one was stopped from outside, ``OSError``
    when ``cache`` cannot be written."""
    cache = cache_dir() if cache is None else cache
    key = verifier_key(tools, text)
    final = cache / key
    if (final / "pan").is_file() and (final / "model.pml").is_file():
        os.utime(final)  # most recently used: kept when the cache is pruned
        return final
    cache.mkdir(parents=True, exist_ok=True)
    with temporary_directory(cache, ".build-") as tmp:
        (tmp / "model.pml").write_text(text, encoding="utf-8")
        out, code, _ = _run([tools.spin, "-a", "model.pml"], tmp, timeout_s, where, "spin -a")
        if code != 0 or not (tmp / "pan.c").is_file():
            raise CompileError("spin -a model.pml " + (f"did not finish within the time limit of {timeout_s:g} s"
                                                       if code is None else f"failed:\n{out}"), code is None)
        # gcc's intermediate files (cc*.s, cc*.o) go in the build directory, which goes when the build
        # ends or rclverify is killed: in $TMPDIR a killed compiler would leave them behind (absolute: gcc runs
        # inside it, and ignores a TMPDIR that is not a directory)
        out2, code2, _ = _run([tools.gcc, *CFLAGS, "-o", "pan", "pan.c"], tmp, timeout_s, where, "gcc",
                              {**os.environ, "TMPDIR": os.path.abspath(tmp)})
        if code2 != 0:
            raise CompileError("gcc pan.c " + (f"did not finish within the time limit of {timeout_s:g} s"
                                               if code2 is None else f"failed:\n{out2}"), code2 is None)
        for junk in tmp.glob("pan.[bchmpt]"):
            junk.unlink()
        try:
            move_into_place(tmp, final)
        except OSError:  # another run built it first
            if not (final / "pan").is_file():
                raise
        else:
            forget_directory(tmp)
            _prune(cache, key)
    return final


def _prune(cache: Path, keep: str) -> None:
    """Remove all but the :data:`KEEP_VERIFIERS` most recently used verifiers,
    and temporary directories older than :data:`STALE_S` (left by killed runs)."""
    now = time.time()
    entries = []
    for p in cache.iterdir():
        try:
            mtime = p.stat().st_mtime
        except OSError:
            continue
        if p.name.startswith("."):
            if now - mtime > STALE_S:
                shutil.rmtree(p, ignore_errors=True)
        elif p.name != keep:
            entries.append((mtime, p))
    for _, p in sorted(entries, reverse=True)[KEEP_VERIFIERS - 1:]:
        shutil.rmtree(p, ignore_errors=True)


_ERRORS = re.compile(r"errors:\s*(\d+)")
_STORED = re.compile(r"(\d+)\s+states, stored")
_DEPTH = re.compile(r"depth reached\s+(\d+)")


def hash_bits(size: int) -> int:
    """pan's ``-w`` for a model of ``size`` states and transitions: a hash
    table of about four slots per product state (never below 2**12 or above
    2**24, pan's default, which pan would otherwise allocate and clear for
    every run: 128 MB).  The table's size changes speed, not the verdict."""
    return max(12, min(24, (4 * max(size, 1)).bit_length()))


def check(tools: Tools, built: Path, claim: str, max_depth: int, timeout_s: float = DEFAULT_TIMEOUT_S,
          size: int = 1 << 22, where: Loc | None = None) -> CheckResult:
    """Search ``built``'s verifier (a directory :func:`compile_model` made)
    for a violation of ``claim``; on one, replay its trail with SPIN (the
    replay's text is ``CheckResult.trail``).  ``size`` (states plus
    transitions of the graph) sizes pan's hash table.  A search that exceeds
    ``timeout_s`` seconds is ``incomplete`` (the reason says so).  Raises
    :class:`~rclverify.backends.bounded.ToolInterrupted` (located at
    ``where``) when ``pan`` or the replay was stopped from outside."""
    with temporary_directory(built.parent, ".run-") as work:
        shutil.copy(built / "model.pml", work / "model.pml")
        out, code, secs = _run([str(built / "pan"), "-a", "-n", f"-N{claim}", f"-m{max_depth}",
                                 f"-w{hash_bits(size)}"], work, timeout_s, where, "pan")
        stored = _int(_STORED, out)
        depth = _int(_DEPTH, out)
        if code is None:
            return CheckResult("incomplete", out, reason=f"pan did not finish within the time limit of "
                                                         f"{timeout_s:g} s (timeout_s)",
                               stored=stored, depth=depth, duration_s=secs)
        errors = _int(_ERRORS, out)
        trail_file = work / "model.pml.trail"
        if errors and trail_file.is_file():
            replay, rcode, rsecs = _run([tools.spin, "-T", "-t", "-p", "-k", "model.pml.trail", "model.pml"],
                                        work, timeout_s, where, "spin -t")
            if rcode is None:
                return CheckResult("incomplete", out, reason=f"SPIN's replay of the trail did not finish within "
                                                             f"the time limit of {timeout_s:g} s (timeout_s)",
                                   stored=stored, depth=depth, duration_s=secs + rsecs)
            if rcode != 0 and "@" not in replay:
                return CheckResult("error", out, reason=f"spin could not replay the trail:\n{replay}",
                                   stored=stored, depth=depth, duration_s=secs + rsecs)
            return CheckResult("violated", out, trail=replay, stored=stored, depth=depth,
                               duration_s=round(secs + rsecs, 3))
        if "out of memory" in out:
            return CheckResult("incomplete", out, reason=f"pan ran out of memory ({MEMLIM_MB} MB)",
                               stored=stored, depth=depth, duration_s=secs)
        if "max search depth too small" in out:
            return CheckResult("incomplete", out, reason=f"pan's search depth bound {max_depth} was reached",
                               stored=stored, depth=depth, duration_s=secs)
        if errors == 0 and code == 0:
            return CheckResult("holds", out, stored=stored, depth=depth, duration_s=secs)
        return CheckResult("error", out, reason=f"pan stopped without a verdict (exit code {code})",
                           stored=stored, depth=depth, duration_s=secs)


def _int(pattern: re.Pattern[str], text: str) -> int | None:
    m = pattern.search(text)
    return int(m.group(1)) if m else None
