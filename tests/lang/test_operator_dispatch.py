"""Every operator reaches every translation: the operator sets are closed
(``Literal`` types in lang/exprs.py), the semantics table has exactly one
entry per operator, and each translation that dispatches on a unary
operator ends in :func:`rclverify.lang.ast.unhandled`, so that the type
checker names every place a new operator must reach, instead of one being
read as another (a new unary operator used to be read as minus in Z3,
SMT-LIB, Dafny, the experiment criterion, C++, the carried evaluator, the
printer and LaTeX).  ``abs`` (tests/semantics/test_abs.py) was added this way."""
from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import get_args

import pytest

from rclverify.lang import ast
from rclverify.semantics.operators import OPERATORS, UNARY

SRC = Path(__file__).resolve().parent.parent.parent / "src"

#: each place that gives a unary operator its meaning in another language, by dispatch on the operator
DISPATCHES = {
    "rclverify/semantics/translate.py": 1,  # Z3
    "rclverify/targets/smtlib.py": 1,  # SMT-LIB text
    "rclverify/targets/dafny/translate.py": 1,  # Dafny
    "rclverify/backends/experiment/criterion.py": 1,  # the experiment criterion's sort (its Z3 is unary_z3)
    "rclverify/targets/cpp/expr.py": 1,  # C++
    "rclverify/lang/printer.py": 2,  # RCL text and its precedence
    "rclverify/lang/latex.py": 1,  # LaTeX
    "rclverify/lang/typecheck_expr.py": 1,  # types
    "rclverify/lang/unitcheck.py": 1,  # units
}


def test_each_operator_has_exactly_one_entry_in_the_semantics_table() -> None:
    assert set(UNARY) == set(get_args(ast.UnaryOp))
    assert set(OPERATORS) == set(get_args(ast.BinaryOp)) | set(get_args(ast.CompareOp))


def test_unhandled_raises_naming_the_operator() -> None:
    with pytest.raises(AssertionError, match="'sgn' is not handled here"):
        ast.unhandled("sgn")  # type: ignore[arg-type]


@pytest.mark.slow
def test_a_new_unary_operator_is_named_by_the_type_checker_at_every_translation(tmp_path: Path) -> None:
    """mypy strict over the package with lang/exprs.py's ``UnaryOp`` given one more operator (a shadow
    file: the sources are not touched): an error at each dispatch of :data:`DISPATCHES`, and nowhere else.
    mypy starts from a copy of the project's cache where there is one (it checks again whatever the
    shadow file or an edit since changed, so the verdict is the cold run's, in a quarter of the time)."""
    pytest.importorskip("mypy", reason="mypy is installed by the test setup (scripts/setup.sh --tests)")
    text = (SRC / "rclverify/lang/exprs.py").read_text()
    shadow = tmp_path / "exprs.py"
    shadow.write_text(text.replace('UnaryOp = Literal["not", "-", "abs", "sqrt", "sin", "cos"]',
                                   'UnaryOp = Literal["not", "-", "abs", "sqrt", "sin", "cos", "sgn"]'))
    assert shadow.read_text() != text
    cache = tmp_path / "cache"
    if (SRC.parent / ".mypy_cache").is_dir():  # the project's own run's cache (CI runs mypy first): a warm start
        shutil.copytree(SRC.parent / ".mypy_cache", cache)
    r = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", str(cache), "--shadow-file",
                        str(SRC / "rclverify/lang/exprs.py"), str(shadow), str(SRC / "rclverify")],
                       capture_output=True, text=True, cwd=SRC.parent, timeout=300)
    errors = [ln for ln in r.stdout.splitlines() if ": error:" in ln]
    found: dict[str, int] = {}
    for ln in errors:
        assert "unhandled" in ln and "Literal['sgn']" in ln, ln  # no other error: nothing else breaks
        path = re.sub(r"^.*?src/", "", ln.split(":")[0])
        found[path] = found.get(path, 0) + 1
    assert found == DISPATCHES, r.stdout
