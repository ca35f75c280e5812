"""Finding an MCAPL installation and running AJPF on one property.

AJPF is started as the MCAPL manual describes: ``java -jar
<MCAPL>/lib/3rdparty/RunJPF.jar <config>.jpf``.  The generated ``.jpf`` says
``@using = mcapl``, which JPF resolves through the key ``mcapl`` of the
user's ``~/.jpf/site.properties``; when that file does not define it, the
run passes JPF a site file of its own (``+site=<file>``, written to a
temporary directory outside the workspace) naming the installation found.
``AJPF_HOME`` is set for the child, as MCAPL uses it to resolve relative
file names.  The working directory is the workspace root, so the
workspace-relative paths inside the generated files resolve.

Where the installation comes from, first found wins: the plan entry's
``mcapl_home``, then the environment variables ``MCAPL_HOME`` and
``AJPF_HOME``.  It counts as installed when ``lib/3rdparty/RunJPF.jar``
exists under it and ``java`` is on the ``PATH``.
"""
from __future__ import annotations

import os
import re
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

from rclverify.lang.ast import Loc
from rclverify.backends.bounded import run_bounded

#: Where RunJPF.jar lives inside an MCAPL distribution.
RUNJPF = Path("lib") / "3rdparty" / "RunJPF.jar"
#: Placeholder for the installation directory in commands shown to users.
HOME_PLACEHOLDER = "<MCAPL_HOME>"


@dataclass(frozen=True)
class McaplInstall:
    """A usable MCAPL installation: ``home`` (absolute), the RunJPF ``jar``,
    the ``java`` executable and where ``home`` was configured (``source``)."""

    home: Path
    jar: Path
    java: str
    source: str


@dataclass(frozen=True)
class RunOutcome:
    """One AJPF run: combined stdout+stderr ``log``, the exit ``returncode``
    (``None`` when killed on timeout), ``timed_out`` and ``duration_s`` (seconds)."""

    log: str
    returncode: int | None
    timed_out: bool
    duration_s: float


def locate(config_home: str | None, root: Path, environ: Mapping[str, str] | None = None
           ) -> tuple[McaplInstall | None, str]:
    """Find MCAPL.  Returns ``(install, "")`` or ``(None, reason)``.

    ``config_home`` is the plan's ``mcapl_home`` (relative to ``root`` unless
    absolute, ``~`` expanded); ``environ`` defaults to ``os.environ``.
    """
    env = os.environ if environ is None else environ
    candidates: list[tuple[str, str]] = []
    if config_home:
        candidates.append(("plan key mcapl_home", config_home))
    for var in ("MCAPL_HOME", "AJPF_HOME"):
        if env.get(var):
            candidates.append((f"environment variable {var}", env[var]))
    if not candidates:
        return None, ("AJPF (MCAPL) not installed: no plan key mcapl_home and neither MCAPL_HOME nor "
                      "AJPF_HOME is set")
    source, value = candidates[0]
    home = Path(value).expanduser()
    if not home.is_absolute():
        home = (root / home).resolve()
    jar = home / RUNJPF
    if not jar.is_file():
        return None, f"AJPF (MCAPL) not installed: {source} points at a directory without {RUNJPF.as_posix()}"
    java = shutil.which("java", path=env.get("PATH"))
    if java is None:
        return None, "AJPF (MCAPL) cannot run: no 'java' on PATH"
    return McaplInstall(home, jar, java, source), ""


def user_command(jpf: str, log: str) -> str:
    """The command a user runs from the workspace root to check one property
    and leave its log where :mod:`.backend` imports it."""
    return f"java -jar {HOME_PLACEHOLDER}/{RUNJPF.as_posix()} {jpf} > {log} 2>&1"


def _site_defines_mcapl(home_dir: Path) -> bool:
    site = home_dir / ".jpf" / "site.properties"
    try:
        text = site.read_text(encoding="utf-8", errors="replace")
    except OSError:
        return False
    return re.search(r"^\s*mcapl\s*[=:]", text, re.MULTILINE) is not None


def run(install: McaplInstall, root: Path, jpf: str, timeout_s: float, where: Loc | None = None) -> RunOutcome:
    """Run AJPF on the workspace-relative configuration ``jpf``.

    Kills the whole process group after ``timeout_s`` seconds (and when
    rclverify is stopped: :func:`~rclverify.backends.bounded.run_bounded`).
    Raises ``OSError`` when the process cannot be started at all, and
    :class:`~rclverify.backends.bounded.ToolInterrupted` (located at
    ``where``) when it was stopped from outside: nothing is recorded then.
    """
    env = dict(os.environ)
    env["AJPF_HOME"] = str(install.home)
    cmd = [install.java, "-jar", str(install.jar)]
    with tempfile.TemporaryDirectory(prefix="rclverify-ajpf-") as tmp:
        if not _site_defines_mcapl(Path(env.get("HOME", str(Path.home())))):
            site = Path(tmp) / "site.properties"
            site.write_text(f"mcapl = {install.home.as_posix()}\n", encoding="utf-8")
            cmd.append(f"+site={site.as_posix()}")
        cmd.append(jpf)
        out, code, duration = run_bounded(cmd, root, timeout_s, env, where=where, tool="AJPF (java)")
        timed_out = code is None
    return RunOutcome(out, code, timed_out,
                      duration)
