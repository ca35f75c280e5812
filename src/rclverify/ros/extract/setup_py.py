"""What a Python package's ``setup.py`` and ``setup.cfg`` declare (read with
``ast`` and as text, never run; docs/ros.md, "Reading real code" and "Only
what is built"): its ``console_scripts`` entry points and ``scripts``, each
module found where ``package_dir`` puts it, as setuptools does."""
from __future__ import annotations

import ast
import re
from pathlib import Path

from rclverify.ros.extract import safefs

_ENTRY = re.compile(r"^\s*([A-Za-z0-9_.\-]+)\s*=\s*([A-Za-z0-9_.]+)\s*:\s*[A-Za-z0-9_]+\s*$")
#: one entry point: (executable, build file, line, module file relative to the package, found)
Entry = tuple[str, Path, int, str, bool]


def setup_py_executables(root: Path) -> dict[str, list[Path]]:
    """``{executable: [module file]}`` from ``setup.py``'s ``console_scripts`` entries
    and ``scripts=[...]`` (read with ``ast``, never run)."""
    f = root / "setup.py"
    out: dict[str, list[Path]] = {}
    try:
        tree = ast.parse(safefs.read_text(f))
    except (OSError, SyntaxError, ValueError, RecursionError):
        return out
    dirs = _package_dirs(tree)
    for n in ast.walk(tree):
        if isinstance(n, ast.Constant) and isinstance(n.value, str):
            m = _ENTRY.match(n.value)
            if m:
                mod = root / module_file(m.group(2), dirs)
                if mod.is_file():
                    out[m.group(1)] = [mod]
        elif isinstance(n, ast.keyword) and n.arg == "scripts" and isinstance(n.value, (ast.List, ast.Tuple)):
            for e in n.value.elts:
                if isinstance(e, ast.Constant) and isinstance(e.value, str) and (root / e.value).is_file():
                    p = root / e.value
                    out.setdefault(p.name, [p])
                    out.setdefault(p.stem, [p])
    return out


def entry_points(root: Path) -> list[Entry]:
    """The ``console_scripts`` entry points ``setup.py`` and ``setup.cfg`` declare
    (``exe = pkg.module:main``), each ``(name, build file, line, module file
    relative to root, found)`` (setuptools' "Entry points" specification);
    ``found`` is false when the module file is not in the package.  Read as
    text, never run."""
    out: list[Entry] = []
    dirs: dict[str, str] = {}
    for name in ("setup.py", "setup.cfg"):
        f = root / name
        try:
            text = safefs.read_text(f)
        except OSError:
            continue
        if name == "setup.py":
            try:
                dirs = _package_dirs(ast.parse(text))
            except (SyntaxError, ValueError, RecursionError):
                dirs = {}
        in_scripts = name == "setup.py"
        for i, line in enumerate(text.splitlines(), 1):
            if name == "setup.cfg" and line.strip().startswith("console_scripts"):
                in_scripts = True
                line = line.split("=", 1)[1] if "=" in line else ""
            elif name == "setup.cfg" and line[:1] not in (" ", "\t", ""):
                in_scripts = False
            if not in_scripts:
                continue
            for m in _ENTRY_IN.finditer(line):
                mod = module_file(m.group(2), dirs)
                if not any(d[0] == m.group(1) for d in out):
                    out.append((m.group(1), f, i, mod, (root / mod).is_file()))
    return out


def _package_dirs(tree: ast.AST) -> dict[str, str]:
    """``setup(package_dir={...})``'s literal mapping ``{package prefix: directory}``
    (``{'': 'src'}``: every package under ``src``); empty when absent or not a
    literal dictionary of strings."""
    for n in ast.walk(tree):
        if isinstance(n, ast.keyword) and n.arg == "package_dir" and isinstance(n.value, ast.Dict):
            out = {k.value: v.value for k, v in zip(n.value.keys, n.value.values)
                   if isinstance(k, ast.Constant) and isinstance(k.value, str)
                   and isinstance(v, ast.Constant) and isinstance(v.value, str)}
            return out
    return {}


def module_file(dotted: str, dirs: dict[str, str]) -> str:
    """The file of module ``dotted`` (``pkg.module``) relative to the package root,
    where ``package_dir`` ``dirs`` puts it: the longest package prefix mapped
    wins (setuptools' rule), ``''`` maps every package, none maps the root."""
    parts = dotted.split(".")
    for k in range(len(parts), -1, -1):
        prefix = ".".join(parts[:k])
        if prefix in dirs:
            base = dirs[prefix].strip("/")
            rest = parts[k:]
            return "/".join(([base] if base and base != "." else []) + rest) + ".py"
    return "/".join(parts) + ".py"


_ENTRY_IN = re.compile(r"(?:^|[\"'\s])([A-Za-z0-9_.\-]+)\s*=\s*([A-Za-z_][A-Za-z0-9_.]*)\s*:\s*[A-Za-z_][A-Za-z0-9_]*")
