"""Small rooms (issue 66): no module over 500 lines and no function over 80 unless it says why, and every
import left inside a function says why it waits (docs/architecture.md, "Small rooms")."""
from __future__ import annotations

import ast
from functools import lru_cache
from pathlib import Path

PKG = Path(__file__).resolve().parents[1] / "src" / "rclverify"
MODULE_LINES, FUNCTION_LINES = 500, 80


@lru_cache(maxsize=1)
def _sources() -> list[tuple[Path, str, ast.Module]]:
    return [(p, p.read_text(encoding="utf-8"), ast.parse(p.read_text(encoding="utf-8"))) for p in sorted(PKG.rglob("*.py"))]


def long_modules(sources: list[tuple[Path, str, ast.Module]]) -> list[str]:
    """Modules over the limit whose docstring does not start a paragraph with 'Long module:'."""
    return [str(p.relative_to(PKG)) for p, text, tree in sources
            if text.count("\n") > MODULE_LINES and "Long module:" not in (ast.get_docstring(tree) or "")]


def long_functions(sources: list[tuple[Path, str, ast.Module]]) -> list[str]:
    """Functions over the limit without a '# long:' comment on the line of their def."""
    out = []
    for p, text, tree in sources:
        lines = text.splitlines()
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and \
                    node.end_lineno - node.lineno + 1 > FUNCTION_LINES and "# long:" not in lines[node.lineno - 1]:
                out.append(f"{p.relative_to(PKG)}:{node.lineno} {node.name}")
    return out


def silent_deferred_imports(sources: list[tuple[Path, str, ast.Module]]) -> list[str]:
    """Imports inside a function whose lines carry no reason ('deferred:' or 'here, not at import')."""
    out = []
    for p, text, tree in sources:
        lines = text.splitlines()
        for fn in ast.walk(tree):
            if isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                for st in ast.walk(fn):
                    if isinstance(st, (ast.Import, ast.ImportFrom)):
                        said = " ".join(lines[st.lineno - 1:st.end_lineno])
                        if "deferred:" not in said and "here, not at import" not in said:
                            out.append(f"{p.relative_to(PKG)}:{st.lineno}")
    return sorted(set(out))


def test_rooms_are_small_or_say_why() -> None:
    sources = _sources()
    assert long_modules(sources) == []
    assert long_functions(sources) == []


def test_every_import_inside_a_function_says_why_it_waits() -> None:
    assert silent_deferred_imports(_sources()) == []


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
