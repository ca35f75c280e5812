"""Find, identify and run Dafny; read its output; inspect implementations.

Two command-line generations are supported (paper lines 1667-1762 used
Dafny 3.x; Debian ships 2.3; current releases are 4.x):

* **legacy** (2.x, 3.x): ``dafny /compile:0 /nologo /timeLimit:<s>
  /errorLimit:<n> <files>``; its version is the banner ``Dafny 2.3.0.10506``
  that ``dafny /version`` prints first;
* **verify** (4.x and later): ``dafny verify --verification-time-limit <s>
  <files>``; ``dafny --version`` prints the bare version ``4.9.1+...``.

:func:`detect` tries ``--version`` first (a bare version number means the
new CLI) and falls back to ``/version``.

Dafny reports, in both generations, ``file(line,col): Error[ code]: message``,
``file(line,col): Related location[: message]`` (for a failing
postcondition: the ``ensures`` it concerns), ``file(line,col): Timed out on
...``, ``file(line,col): Warning: ...`` and the summary ``Dafny program
verifier finished with N verified, M errors[, K time outs]``; parse and
resolution failures end in ``N parse errors detected`` / ``N
resolution/type errors detected``.  :func:`parse_output` reads all of them.

A user's implementation is read without Dafny in :mod:`.implementation`.
"""
from __future__ import annotations

import os
import re
import shutil
import tempfile
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Mapping, Sequence

from rclverify.lang.ast import Loc
from rclverify.backends.bounded import run_bounded


# ---------------------------------------------------------------------------
# Finding and identifying Dafny
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class DafnyTool:
    """An installed Dafny: ``exe`` path, ``version`` text (``2.3.0.10506``),
    ``major`` version and whether it takes the legacy ``/option`` CLI."""

    exe: str
    version: str
    major: int
    legacy: bool


def find_dafny(configured: str | None = None, path: str | None = None) -> str | None:
    """Path of the Dafny executable, or ``None`` when there is none.

    ``configured`` (the plan's ``dafny:`` key) is a command name or path;
    default ``dafny``.  ``path`` is the search path (default: ``$PATH``).
    """
    return shutil.which(configured or "dafny", path=path if path is not None else os.environ.get("PATH", ""))


_BARE_VERSION = re.compile(r"\A\s*(\d+)\.(\d+)\.(\d+)\S*")
_BANNER = re.compile(r"Dafny\s+(?:version\s+)?((\d+)\.\d+\.\d+(?:\.\d+)?)")


def _probe(exe: str, arg: str, timeout_s: float) -> str:
    """``exe arg``'s output ("" when it cannot start or exceeds ``timeout_s``); bounded and
    killed with rclverify like every tool (:func:`~rclverify.backends.bounded.run_bounded`)."""
    try:
        out, code, _ = run_bounded([exe, arg], Path(tempfile.gettempdir()), timeout_s, tool="Dafny")
    except OSError:
        return ""
    return "" if code is None else out


@lru_cache(maxsize=8)
def _detect_cached(exe: str, mtime: float, timeout_s: float) -> DafnyTool | None:
    out = _probe(exe, "--version", timeout_s)
    m = _BARE_VERSION.match(out)
    if m:
        return DafnyTool(exe, out.strip().split()[0], int(m.group(1)), int(m.group(1)) < 4)
    out = _probe(exe, "/version", timeout_s)
    b = _BANNER.search(out)
    if b:
        return DafnyTool(exe, b.group(1), int(b.group(2)), int(b.group(2)) < 4)
    return None


def detect(exe: str, timeout_s: float = 120.0) -> DafnyTool | None:
    """Identify the Dafny at ``exe`` (cached per executable and modification time).

    Returns ``None`` when ``exe`` does not run or does not say which Dafny
    it is.  Takes about a second (two process starts at most).
    """
    try:
        mtime = Path(exe).stat().st_mtime
    except OSError:
        return None
    return _detect_cached(exe, mtime, timeout_s)


def verify_argv(tool: DafnyTool | None, files: Sequence[str], time_limit_s: int, error_limit: int = 20,
                options: Sequence[str] = (), model_file: str | None = None) -> list[str]:
    """The command line verifying ``files`` (workspace-relative) with Dafny.

    ``time_limit_s`` bounds each verification condition (seconds);
    ``error_limit`` the errors reported per procedure (legacy CLI);
    ``options`` extra options passed verbatim before the files (they must
    suit the CLI generation of ``tool``); ``model_file`` (legacy CLI only:
    :func:`takes_model_file`) where Boogie writes the prover's model of each
    error (``/mv:``).  With ``tool=None`` the legacy form of the Debian
    package is returned with the command name ``dafny``.
    """
    exe = tool.exe if tool else "dafny"
    if tool is None or tool.legacy:
        mv = [f"/mv:{model_file}"] if model_file else []
        return [exe, "/compile:0", "/nologo", f"/timeLimit:{time_limit_s}", f"/errorLimit:{error_limit}",
                *options, *mv, *files]
    return [exe, "verify", "--verification-time-limit", str(time_limit_s), *options, *files]


def takes_model_file(tool: DafnyTool) -> bool:
    """Whether :func:`verify_argv` can ask ``tool`` for the prover's models
    (Boogie's ``/mv:`` of the legacy CLI; ``dafny verify`` has no such option)."""
    return tool.legacy


def user_commands(files: Sequence[str], time_limit_s: int, options: Sequence[str] = ()) -> tuple[str, str]:
    """The commands a user runs by hand: ``(Dafny 2.x/3.x form, Dafny 4.x form)``.

    ``options`` starting with ``/`` go to the first form, those starting
    with ``-`` to the second.
    """
    legacy = " ".join(["dafny", "/compile:0", f"/timeLimit:{time_limit_s}",
                       *[o for o in options if o.startswith("/")], *files])
    new = " ".join(["dafny", "verify", "--verification-time-limit", str(time_limit_s),
                    *[o for o in options if o.startswith("-")], *files])
    return legacy, new


def user_command(files: Sequence[str], time_limit_s: int, options: Sequence[str] = ()) -> str:
    """Both forms of :func:`user_commands` on one line, for explanations."""
    legacy, new = user_commands(files, time_limit_s, options)
    return f"{legacy}  (Dafny 2.x/3.x), or {new}  (Dafny 4.x)"


# ---------------------------------------------------------------------------
# Running
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class RunOutput:
    """One Dafny process: ``argv``, ``returncode`` (``None`` when it was
    killed at the process timeout), combined ``output``, ``duration_s``."""

    argv: tuple[str, ...]
    returncode: int | None
    output: str
    duration_s: float
    timed_out: bool = False


def run(argv: Sequence[str], cwd: Path, timeout_s: float, env: Mapping[str, str] | None = None) -> RunOutput:
    """Run Dafny in ``cwd`` and capture stdout+stderr; kill it after ``timeout_s`` seconds.

    Dafny runs through :func:`rclverify.backends.bounded.run_bounded`: in a
    process group of its own, so Z3 and every other child die with it at
    the time limit and when rclverify is stopped.  Raises ``OSError`` when
    the executable cannot be started, and
    :class:`~rclverify.backends.bounded.ToolInterrupted` (located at the
    first ``.dfy`` file of ``argv``) when Dafny was stopped from outside:
    that run is not a result.
    """
    dfy = next((a for a in argv if a.endswith(".dfy")), str(argv[0]))
    out, code, secs = run_bounded(list(argv), cwd, timeout_s, env, where=Loc(dfy, 1, 1), tool="Dafny")
    return RunOutput(tuple(argv), code, out, secs, code is None)


# ---------------------------------------------------------------------------
# Parsing the output
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class Position:
    """A location in a Dafny file as Dafny prints it (``file(line,col)``)."""

    file: str
    line: int
    col: int

    def __str__(self) -> str:
        return f"{self.file}({self.line},{self.col})"


@dataclass
class Message:
    """One diagnostic: ``severity`` is ``error``, ``timeout`` or ``warning``;
    ``code`` e.g. ``BP5003``; ``related`` the related locations (with their
    message, possibly '') that Dafny lists under it."""

    severity: str
    at: Position
    message: str
    code: str = ""
    related: list[tuple[Position, str]] = field(default_factory=list)


@dataclass
class Output:
    """What a Dafny run said.

    ``summary``   whether the "verifier finished" line was printed;
    ``verified``/``errors``/``timeouts``/``other`` its counts (``other``:
    inconclusive, out of memory, out of resource);
    ``parse_errors`` / ``resolution_errors``: counts of the lines "N parse
    errors detected" / "N resolution/type errors detected";
    ``prover_messages``: distinct "Prover error:" lines (solver complaints
    that did not stop verification).
    """

    summary: bool = False
    verified: int = 0
    errors: int = 0
    timeouts: int = 0
    other: int = 0
    parse_errors: int = 0
    resolution_errors: int = 0
    messages: list[Message] = field(default_factory=list)
    prover_messages: list[str] = field(default_factory=list)


_POS = r"(?P<file>[^\s()\[][^()\[]*?)(?:\[[^\]]*\])?\((?P<line>-?\d+),(?P<col>-?\d+)\)"
_ERROR = re.compile(_POS + r":\s+Error(?:\s+(?P<code>[A-Z]+\d+))?:\s*(?P<msg>.*)$")
_TIMEOUT_ON = re.compile(_POS + r":\s+Timed out on(?:\s+(?P<code>[A-Z]+\d+))?:\s*(?P<msg>.*)$")
_TIMEOUT_PROC = re.compile(_POS + r":\s+(?:Error:\s+)?(?P<msg>Verification of .* timed out.*)$")
_RELATED = re.compile(_POS + r":\s+Related location(?::\s*(?P<msg>.*))?$")
_WARNING = re.compile(_POS + r":\s+Warning:\s*(?P<msg>.*)$")
_SUMMARY = re.compile(r"Dafny program verifier finished with (?P<v>\d+) verified, (?P<e>\d+) errors?(?P<rest>.*)$")
_DETECTED = re.compile(r"(?P<n>\d+) (?P<kind>parse|resolution/type) errors? detected in")


def _pos(m: re.Match[str]) -> Position:
    return Position(m.group("file").strip(), int(m.group("line")), int(m.group("col")))


def parse_output(text: str) -> Output:
    """Read Dafny's console output (any supported version) into an :class:`Output`."""
    out = Output()
    last: Message | None = None
    for raw in text.splitlines():
        line = raw.rstrip()
        if m := _SUMMARY.search(line):
            out.summary = True
            out.verified, out.errors = int(m.group("v")), int(m.group("e"))
            for n, what in re.findall(r"(\d+) ([a-z ]+?)(?=,|$)", m.group("rest")):
                if what.startswith("time out"):
                    out.timeouts += int(n)
                else:
                    out.other += int(n)
            continue
        if m := _DETECTED.search(line):
            if m.group("kind") == "parse":
                out.parse_errors += int(m.group("n"))
            else:
                out.resolution_errors += int(m.group("n"))
            continue
        if line.startswith("Prover error:"):
            gist = re.sub(r"line \d+ column \d+: ", "", line)
            if all(re.sub(r"line \d+ column \d+: ", "", p) != gist for p in out.prover_messages):
                out.prover_messages.append(line)
            continue
        if m := _RELATED.match(line):
            if last is not None:
                last.related.append((_pos(m), (m.group("msg") or "").strip()))
            continue
        if m := _TIMEOUT_ON.match(line):
            last = Message("timeout", _pos(m), m.group("msg").strip(), m.group("code") or "")
            out.messages.append(last)
            continue
        if m := _TIMEOUT_PROC.match(line):
            last = Message("timeout", _pos(m), m.group("msg").strip())
            out.messages.append(last)
            continue
        if m := _ERROR.match(line):
            last = Message("error", _pos(m), m.group("msg").strip(), m.group("code") or "")
            out.messages.append(last)
            continue
        if m := _WARNING.match(line):
            last = Message("warning", _pos(m), m.group("msg").strip())
            out.messages.append(last)
            continue
    return out


_PROVER_OPTION = re.compile(r"^Prover error: line \d+ column \d+: unknown parameter '([A-Za-z0-9_.]+)'\s*$")
_LEGAL_HEADER = re.compile(r"^Legal parameters are:\s*$")
_LEGAL_ROW = re.compile(r"^\s+\S.*$")


def filter_log(text: str) -> tuple[str, list[str]]:
    """Dafny's output without the known harmless prover messages.

    Dafny 2.3 (Boogie) sets Z3 options that newer Z3 releases dropped
    (``model_compress``); Z3 then prints, for every verification condition,
    "Prover error: ... unknown parameter 'model_compress'" and its whole
    table of legal parameters.  The option only shapes how counterexample
    models are printed; the verification result is unaffected (Dafny still
    reports each postcondition it cannot prove).  Returns ``(filtered text,
    notes)``; each note says which message was removed and how often, so the
    record says what was filtered.  The verdict is always computed from the
    unfiltered output.
    """
    out: list[str] = []
    removed: dict[str, int] = {}
    lines = text.splitlines()
    k = 0
    while k < len(lines):
        m = _PROVER_OPTION.match(lines[k])
        if m:
            removed[m.group(1)] = removed.get(m.group(1), 0) + 1
            k += 1
            if k < len(lines) and _LEGAL_HEADER.match(lines[k]):
                k += 1
                while k < len(lines) and _LEGAL_ROW.match(lines[k]):
                    k += 1
            continue
        out.append(lines[k])
        k += 1
    notes = [f"removed {n} \"Prover error: unknown parameter '{opt}'\" message(s) with Z3's table of legal "
             f"parameters: this Dafny sets the Z3 option {opt}, which the installed Z3 no longer has; it only "
             "affects how models are printed" for opt, n in sorted(removed.items())]
    return "\n".join(out) + ("\n" if text.endswith("\n") else ""), notes


def installed_version() -> str:
    """The version of the Dafny on ``PATH`` as the backend identifies it (:func:`detect`):
    ``"4.9.1"``, ``"not installed"``, or ``"unidentified (<path>)"``; the bundle's tool versions
    call it through the backend's declaration (``tools[].version``)."""
    exe = find_dafny()
    if exe is None:
        return "not installed"
    tool = detect(exe)
    return tool.version if tool else f"unidentified ({exe})"
