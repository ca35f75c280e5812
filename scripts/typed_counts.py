"""How much of rclverify's source reads records by string key and types values as ``dict[str, Any]``.

Issue 112's indicators of an untyped report, counted in Python's parse tree
(``ast``) of every ``*.py`` file under a source folder, so that docstrings,
comments and string contents never count:

* string-key reads: a subscript read (``x["key"]``, ``Load`` context) whose
  index is a string literal, and a ``.get("key", ...)`` call whose first
  argument is a string literal; a write (``x["key"] = v``) is counted apart;
* ``dict[str, Any]``: every annotation of a function's parameters and return
  that spells it (a signature with two counts twice), every such annotation
  naming an alias of it instead (a module-level ``X = dict[str, Any]``
  anywhere in the folder, e.g. records/report_schema.py's ``NodeJson``), and
  every other place it is spelled in code (variable annotations, the aliases
  themselves, casts).

Each figure is printed for the whole folder and for the report's two folders
(``report/``, ``records/``).  With ``--rev REV`` the tree of that git
revision is counted instead of the working tree (read with ``git archive``,
nothing checked out), so that two commits are compared by one method.

Usage::

    python3 scripts/typed_counts.py                 # src/ of the working tree
    python3 scripts/typed_counts.py --rev HEAD~50   # src/ at an earlier commit
    python3 scripts/typed_counts.py --json          # the figures as one JSON object
"""
from __future__ import annotations

import argparse
import ast
import io
import json
import subprocess
import sys
import tarfile
from pathlib import Path
from typing import AbstractSet, Iterable, Iterator

#: the figures, in the order printed
FIGURES = ("subscript_reads", "get_calls", "subscript_writes", "dict_any_signatures", "dict_any_alias_signatures",
           "dict_any_elsewhere")
#: the folders under the package counted apart
PARTS = ("report", "records")


def _is_str(node: ast.AST | None) -> bool:
    return isinstance(node, ast.Constant) and isinstance(node.value, str)


def _is_dict_str_any(node: ast.AST) -> bool:
    """``dict[str, Any]`` (or ``typing.Any``) as written in an annotation."""
    if not (isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and node.value.id == "dict"):
        return False
    idx = node.slice
    if not (isinstance(idx, ast.Tuple) and len(idx.elts) == 2):
        return False
    k, v = idx.elts
    return (isinstance(k, ast.Name) and k.id == "str"
            and ((isinstance(v, ast.Name) and v.id == "Any") or (isinstance(v, ast.Attribute) and v.attr == "Any")))


def _signature_annotations(fn: ast.FunctionDef | ast.AsyncFunctionDef) -> Iterator[ast.expr]:
    a = fn.args
    for arg in [*a.posonlyargs, *a.args, *a.kwonlyargs, a.vararg, a.kwarg]:
        if arg is not None and arg.annotation is not None:
            yield arg.annotation
    if fn.returns is not None:
        yield fn.returns


def _parse(text: str) -> ast.Module | None:
    try:
        return ast.parse(text)
    except SyntaxError:
        return None


def dict_any_aliases(trees: Iterable[ast.Module]) -> set[str]:
    """The names bound at a module's top level to ``dict[str, Any]`` in any of ``trees``."""
    names: set[str] = set()
    for tree in trees:
        for node in tree.body:
            if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
                target, value = node.targets[0].id, node.value
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and node.value is not None:
                target, value = node.target.id, node.value
            else:
                continue
            if _is_dict_str_any(value):
                names.add(target)
    return names


def count_source(tree: ast.Module | None, aliases: AbstractSet[str] = frozenset()) -> dict[str, int]:
    """The :data:`FIGURES` of one module's parse ``tree`` (``None``, a module that does not parse, counts
    nothing); ``aliases``: the names that stand for ``dict[str, Any]`` (:func:`dict_any_aliases`)."""
    out = dict.fromkeys(FIGURES, 0)
    if tree is None:
        return out
    in_signature: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            for ann in _signature_annotations(node):
                hits = [n for n in ast.walk(ann) if _is_dict_str_any(n)]
                out["dict_any_signatures"] += len(hits)
                in_signature.update(id(n) for n in hits)
                out["dict_any_alias_signatures"] += sum(
                    1 for n in ast.walk(ann) if isinstance(n, ast.Name) and n.id in aliases)
    for node in ast.walk(tree):
        if isinstance(node, ast.Subscript):
            if _is_str(node.slice):
                key = "subscript_reads" if isinstance(node.ctx, ast.Load) else "subscript_writes"
                out[key] += 1
            if _is_dict_str_any(node) and id(node) not in in_signature:
                out["dict_any_elsewhere"] += 1
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "get"
              and node.args and _is_str(node.args[0])):
            out["get_calls"] += 1
    return out


def count_files(files: Iterable[tuple[str, str]]) -> dict[str, dict[str, int]]:
    """``{"all" | part: figures}`` over ``files`` (``(path relative to the source folder, text)``)."""
    totals = {k: dict.fromkeys(FIGURES, 0) for k in ("all", *PARTS)}
    trees = [(path, _parse(text)) for path, text in files]
    aliases = dict_any_aliases(t for _, t in trees if t is not None)
    for path, tree in trees:
        figures = count_source(tree, aliases)
        parts = Path(path).parts
        for where in ("all", *[p for p in PARTS if len(parts) > 2 and parts[1] == p]):
            for k, v in figures.items():
                totals[where][k] += v
    return totals


def _working_tree(src: Path) -> Iterator[tuple[str, str]]:
    for p in sorted(src.rglob("*.py")):
        yield str(p.relative_to(src)), p.read_text(encoding="utf-8")


def _revision(rev: str, src: str) -> Iterator[tuple[str, str]]:
    data = subprocess.run(["git", "archive", "--format=tar", rev, src], check=True,
                          capture_output=True).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        for member in sorted(tar.getmembers(), key=lambda m: m.name):
            if member.isfile() and member.name.endswith(".py"):
                f = tar.extractfile(member)
                if f is not None:
                    yield str(Path(member.name).relative_to(src)), f.read().decode("utf-8")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--src", default="src", help="the source folder, relative to the repository root (default src)")
    ap.add_argument("--rev", help="count this git revision's tree instead of the working tree")
    ap.add_argument("--json", action="store_true", help="print the figures as one JSON object")
    ap.add_argument("--smoke", action="store_true", help="the same run (it takes about a second)")
    args = ap.parse_args(argv)
    files = _revision(args.rev, args.src) if args.rev else _working_tree(Path(args.src))
    totals = count_files(files)
    if args.json:
        print(json.dumps(totals, indent=1))
        return 0
    where = args.rev or "working tree"
    for part, figures in totals.items():
        label = args.src if part == "all" else f"{args.src}/rclverify/{part}"
        reads = f"{figures['subscript_reads']:,} / {figures['get_calls']:,}"
        dicts = (f"{figures['dict_any_signatures']:,} spelled + {figures['dict_any_alias_signatures']:,} by alias"
                 f" (+{figures['dict_any_elsewhere']:,} elsewhere)")
        print(f"{label} ({where}): string-key reads [\"k\"] / .get(\"k\"): {reads}; "
              f"dict[str, Any] in signatures: {dicts}; string-key writes: {figures['subscript_writes']:,}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
