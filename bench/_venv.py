"""The benches run in the project's environment: ``python3 bench/X.py`` with a
Python that lacks rclverify's dependencies runs again under the ``.venv/``
that ``scripts/setup.sh`` makes (docs/install.md), when there is one."""
from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path


def ensure() -> None:
    """Replace this process by the same command under ``.venv/bin/python`` when
    z3 or lark cannot be imported here and that environment exists; else return."""
    if all(importlib.util.find_spec(m) is not None for m in ("z3", "lark")):
        return
    env = Path(__file__).resolve().parents[1] / ".venv"
    python = env / "bin" / "python"  # a link to the base interpreter: the environment is told by sys.prefix
    if python.exists() and Path(sys.prefix).resolve() != env.resolve():
        os.execv(str(python), [str(python), *sys.argv])


ensure()
