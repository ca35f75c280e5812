"""An interpreter that cannot import some packages, as one without them
installed: the tests of the lean install (core/extras.py) run the CLI there."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

#: A prelude that makes the packages named in argv[1] (comma-separated) unimportable, then runs the CLI.
BLOCKED = """
import importlib.abc, sys
blocked = set(sys.argv[1].split(","))
class Refuse(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in blocked:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None
sys.meta_path.insert(0, Refuse())
from rclverify.cli.commands import main
sys.exit(main(sys.argv[2:]))
"""


def cli_without(packages: str, *args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    """``rclverify ARGS`` in a fresh interpreter where ``packages`` (comma-separated top-level names) are missing."""
    return subprocess.run([sys.executable, "-c", BLOCKED, packages, *args], cwd=cwd, capture_output=True,
                          text=True, timeout=120, stdin=subprocess.DEVNULL)
