"""Which source files make up a package's executable.

* ``CMakeLists.txt``: ``add_executable(name src...)`` (``${PROJECT_NAME}``
  is the package name) -- CMake's command syntax, read with a regular
  expression over comment-stripped text (no CMake is run);
* ROS 2 ``setup.py``: ``console_scripts`` entries ``exe = module.path:func``,
  read with ``ast``;
* ROS 1 Python nodes: a script is its own executable (``scripts/talker.py``
  is ``talker.py``; its stem is accepted too).
"""
from __future__ import annotations

from . import safefs

import ast
import re
from pathlib import Path

_ADD_EXE = re.compile(r"add_executable\s*\(([^)]*)\)", re.I)
_ENTRY = re.compile(r"^\s*([A-Za-z0-9_.\-]+)\s*=\s*([A-Za-z0-9_.]+)\s*:\s*[A-Za-z0-9_]+\s*$")


def cmake_executables(root: Path, pkg: str) -> dict[str, list[Path]]:
    f = root / "CMakeLists.txt"
    out: dict[str, list[Path]] = {}
    try:
        text = safefs.read_text(f)
    except OSError:
        return out
    text = re.sub(r"#.*", "", text).replace("${PROJECT_NAME}", pkg)
    for m in _ADD_EXE.finditer(text):
        toks = m.group(1).split()
        if not toks:
            continue
        name, srcs = toks[0], [t for t in toks[1:] if t not in ("WIN32", "MACOSX_BUNDLE", "EXCLUDE_FROM_ALL")]
        out[name] = [root / s for s in srcs if (root / s).is_file()]
    return out


def setup_py_executables(root: Path) -> dict[str, list[Path]]:
    f = root / "setup.py"
    out: dict[str, list[Path]] = {}
    try:
        tree = ast.parse(safefs.read_text(f))
    except (OSError, SyntaxError, ValueError):
        return out
    for n in ast.walk(tree):
        if isinstance(n, ast.Constant) and isinstance(n.value, str):
            m = _ENTRY.match(n.value)
            if m:
                mod = root / (m.group(2).replace(".", "/") + ".py")
                if mod.is_file():
                    out[m.group(1)] = [mod]
    return out


def executables(root: Path, pkg: str, py_nodes: list[Path]) -> dict[str, list[Path]]:
    """``{executable: [source files]}`` of one package."""
    out = cmake_executables(root, pkg)
    out.update(setup_py_executables(root))
    for p in py_nodes:
        out.setdefault(p.name, [p])
        out.setdefault(p.stem, [p])
    return out
