"""Put a verified workspace back as it was after a test edited it in place.

A test that edits a module's verified workspace and runs ``doit verify`` again can do it in place (an
incremental run: only the tasks the edit concerns) instead of on a copy: doit's state names the
workspace's files by absolute path, so a copy re-runs every task.  :func:`restored` keeps a copy of the
whole workspace (inputs, artifacts, reports, doit's state, with their modification times) and puts it
back afterwards, so the module's later tests meet the workspace as verified, without a run that undoes
the edit."""
from __future__ import annotations

import contextlib
import shutil
from pathlib import Path
from typing import Iterator


@contextlib.contextmanager
def restored(workspace: Path, keep: Path) -> Iterator[Path]:
    """Run the block on ``workspace`` (yielded), then put back every file of it as it was on entry.

    ``keep``: a directory that does not exist yet, where the copy is kept (a test's ``tmp_path / ...``).
    Symbolic links are copied as links; modification times are kept (doit's checker compares them)."""
    shutil.copytree(workspace, keep, symlinks=True)
    try:
        yield workspace
    finally:
        shutil.rmtree(workspace)
        shutil.copytree(keep, workspace, symlinks=True)
