"""Small rooms (issue 66): no module over 500 lines and no function over 80 unless it says why, and every
import left inside a function says why it waits (docs/architecture.md, "Small rooms")."""
from __future__ import annotations

import ast
from pathlib import Path
from typing import Iterator

import pytest

PKG = Path(__file__).resolve().parents[2] / "src" / "rclverify"
MODULE_LINES, FUNCTION_LINES = 500, 80
#: The fields of a node that hold statements (a statement, an ``except`` clause, a ``case``).
BODIES = ("body", "orelse", "finalbody", "handlers", "cases")


@pytest.fixture(scope="module")
def sources() -> list[tuple[Path, str, ast.Module]]:
    """Every module of the package, read and parsed once for this file's tests.  A fixture, not a
    cache of the module: the trees (some two million objects) go when the module's tests end, so that
    the garbage collector of the worker that runs the rest of the suite does not walk them again."""
    out = []
    for p in sorted(PKG.rglob("*.py")):
        text = p.read_text(encoding="utf-8")
        out.append((p, text, ast.parse(text)))
    return out


def _statements(tree: ast.AST, inside: bool = False) -> Iterator[tuple[ast.stmt, bool]]:
    """Every statement under ``tree`` with whether it lies inside a function.  Only statement lists
    are entered: a ``def`` or an ``import`` is a statement, and expressions hold none."""
    stack: list[tuple[ast.AST, bool]] = [(tree, inside)]
    while stack:
        node, inside = stack.pop()
        if isinstance(node, ast.stmt):
            yield node, inside
        inner = inside or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
        for field in BODIES:
            stack.extend((child, inner) for child in getattr(node, field, ()))


def long_modules(sources: list[tuple[Path, str, ast.Module]]) -> list[str]:
    """Modules over the limit whose docstring does not start a paragraph with 'Long module:'."""
    return [str(p.relative_to(PKG)) for p, text, tree in sources
            if text.count("\n") > MODULE_LINES and "Long module:" not in (ast.get_docstring(tree) or "")]


def long_functions(sources: list[tuple[Path, str, ast.Module]]) -> list[str]:
    """Functions over the limit without a '# long:' comment on the line of their def."""
    out = []
    for p, text, tree in sources:
        lines = text.splitlines()
        for node, _ in sorted(_statements(tree), key=lambda x: x[0].lineno):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and \
                    node.end_lineno - node.lineno + 1 > FUNCTION_LINES and "# long:" not in lines[node.lineno - 1]:
                out.append(f"{p.relative_to(PKG)}:{node.lineno} {node.name}")
    return out


def silent_deferred_imports(sources: list[tuple[Path, str, ast.Module]]) -> list[str]:
    """Imports inside a function whose lines carry no reason ('deferred:' or 'here, not at import')."""
    out = []
    for p, text, tree in sources:
        lines = text.splitlines()
        for st, inside in _statements(tree):
            if inside and isinstance(st, (ast.Import, ast.ImportFrom)):
                said = " ".join(lines[st.lineno - 1:st.end_lineno])
                if "deferred:" not in said and "here, not at import" not in said:
                    out.append(f"{p.relative_to(PKG)}:{st.lineno}")
    return sorted(set(out))


def test_rooms_are_small_or_say_why(sources: list[tuple[Path, str, ast.Module]]) -> None:
    assert long_modules(sources) == []
    assert long_functions(sources) == []


def test_every_import_inside_a_function_says_why_it_waits(sources: list[tuple[Path, str, ast.Module]]) -> None:
    assert silent_deferred_imports(sources) == []


def test_the_checks_find_what_they_look_for(tmp_path: Path) -> None:
    body = "\n".join(f"    x{k} = {k}" for k in range(FUNCTION_LINES + 1))
    text = f'"""A module."""\ndef f():\n    import os\n{body}\n' + "\n" * MODULE_LINES
    src = [(PKG / "fake.py", text, ast.parse(text))]
    assert long_modules(src) == ["fake.py"]
    assert long_functions(src) == ["fake.py:2 f"]
    assert silent_deferred_imports(src) == ["fake.py:3"]
    said = text.replace("def f():", "def f():  # long: a flat table").replace("import os", "import os  # deferred: start-up")
    said = '"""A module.\n\nLong module: a flat list."""' + said[len('"""A module."""'):]
    src = [(PKG / "fake.py", said, ast.parse(said))]
    assert long_modules(src) == long_functions(src) == silent_deferred_imports(src) == []
    # imports and defs deeper down: in a nested def, in a class or an except clause inside a function (all
    # inside a function), in a class at module level and under a module-level `if` (not inside one)
    nested = ("class C:\n    import json\n    def m(self):\n        try:\n            pass\n"
              "        except ImportError:\n            import re\nif True:\n    import sys\n"
              "    def g():\n        def h():\n            import io\n        class D:\n            import csv\n")
    src = [(PKG / "fake.py", nested, ast.parse(nested))]
    assert silent_deferred_imports(src) == ["fake.py:12", "fake.py:14", "fake.py:7"]
    deep = "if True:\n    class C:\n        def m(self):\n" + "".join(f"            x{k} = {k}\n"
                                                               for k in range(FUNCTION_LINES))
    src = [(PKG / "fake.py", deep, ast.parse(deep))]
    assert long_functions(src) == ["fake.py:3 m"]
