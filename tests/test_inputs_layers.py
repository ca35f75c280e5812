"""The plan layer imports nothing of the backends (issue 25, circle 1): the
registry of entry schemas (plan/entries.py) sits below both, and the
backends' own check-time validation is called from the pipeline."""
from __future__ import annotations

import ast
from pathlib import Path

from rclverify.backends import IMPLEMENTED, KNOWN
from rclverify.backends.keys import ENTRY_KEYS
from rclverify.plan.entries import BACKEND_NAMES, SCHEMAS, TOOL_KEYS, allowed_keys, declared_paths

SRC = Path(__file__).resolve().parents[1] / "src" / "rclverify"


def _imports(path: Path, package: str) -> set[str]:
    """Absolute names of the rclverify modules ``path`` imports (anywhere in it)."""
    out: set[str] = set()
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.add(mod)
            out.update(f"{mod}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return {m for m in out if m.startswith("rclverify")}


def test_no_module_under_plan_imports_the_backends() -> None:
    offenders = {}
    for path in sorted((SRC / "plan").glob("*.py")):
        bad = sorted(m for m in _imports(path, "rclverify.plan") if m.startswith("rclverify.backends"))
        if bad:
            offenders[path.name] = bad
    assert offenders == {}


def test_the_plan_imports_only_the_layer_below_it() -> None:
    # layers (docs/architecture.md): rcl -> plan -> system/logic -> ... -> backends -> ...
    offenders = {}
    for path in sorted((SRC / "plan").glob("*.py")):
        bad = sorted(m for m in _imports(path, "rclverify.plan")
                     if not m.startswith(("rclverify.rcl", "rclverify.plan")) and m != "rclverify")
        if bad:
            offenders[path.name] = bad
    assert offenders == {}


def test_the_import_checker_sees_a_relative_import_into_the_backends(tmp_path: Path) -> None:
    f = tmp_path / "m.py"
    f.write_text("def f():\n    from ..backends.entry_checks import check_entries\n", encoding="utf-8")
    assert "rclverify.backends.entry_checks" in _imports(f, "rclverify.plan")


def test_the_registry_names_exactly_the_implemented_backends_in_order() -> None:
    assert BACKEND_NAMES == KNOWN == tuple(IMPLEMENTED)
    assert ENTRY_KEYS == {n: s.keys for n, s in SCHEMAS.items()}
    for name, schema in SCHEMAS.items():
        keys = set(allowed_keys(name))
        assert schema.path_keys <= keys and schema.tool_keys <= keys and schema.qualified_keys <= schema.path_keys
    assert TOOL_KEYS == {"dafny", "options", "mcapl_home"}


def test_declared_paths_give_the_file_part_of_an_implementation() -> None:
    got = dict(declared_paths({"backend": "property_tests", "implementation": "..\\..\\evil.py:agent"}))
    assert got == {("implementation",): "..\\..\\evil.py"}
    got = dict(declared_paths({"backend": "monitors", "traces": ["a.jsonl", 3, "b.bag"], "mapping": "m.yaml"}))
    assert got == {("traces", 0): "a.jsonl", ("traces", 2): "b.bag", ("mapping",): "m.yaml"}
    assert dict(declared_paths({"backend": "dafny", "dafny": "/usr/bin/dafny"})) == {}
    assert dict(declared_paths({"backend": "nope", "program": "/x"})) == {}
