"""The caches of docs/scale.md ("What is kept between runs") keep their outputs: the
outline printer's text, and Graphviz layouts reused from the cache."""
from __future__ import annotations

import shutil
from pathlib import Path

import pytest
import z3

from rclverify.backends.hoare.outline import z3_text
from rclverify.report import diagram, layoutcache


def test_printer_text_of_each_kind_of_term() -> None:
    x, y = z3.Reals("x y")
    i = z3.Int("i")
    f = z3.Function("radiation_at", z3.IntSort(), z3.RealSort())
    assert z3_text(z3.And(f(i) < 120, z3.Or(x == y, z3.Not(x >= 0)))) == \
        "radiation_at(i) < 120 and (x == y or not x >= 0)"
    assert z3_text(z3.Implies(z3.BoolVal(True), z3.BoolVal(False))) == "TRUE -> FALSE"
    assert z3_text(x * (y + 1) - z3.RealVal("1/3")) == "x * (y + 1) - 1/3"
    assert z3_text(x + z3.RealVal("2.5")) == "x + 2.5"
    assert z3_text(-x <= z3.ToReal(i)) == "-x <= i"
    assert z3_text(z3.ForAll([i], z3.Exists([x], f(i) != x))) == \
        "forall(i in INTEGER | exists(x in REAL | radiation_at(i) != x))"
    assert z3_text(z3.Real("Node.in.r") > 0, {"Node.in.r": "in.r"}) == "in.r > 0"


@pytest.mark.skipif(shutil.which("dot") is None, reason="graphviz not installed")
def test_layout_is_reused_byte_for_byte(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    dot = 'digraph "cache test" { a -> b [label="v"]; }\n'
    layoutcache.use_directory(tmp_path / "layout")
    try:
        first = diagram.render_dot(dot)
        assert first.svg is not None and first.svg.startswith("<svg")
        assert len(list((tmp_path / "layout").glob("*.svg"))) == 1
        layoutcache.forget()  # as in a new process: only the directory remains

        def no_dot(*args: object, **kwargs: object) -> None:
            raise AssertionError("dot ran although its layout was cached")
        monkeypatch.setattr(diagram.subprocess, "run", no_dot)
        assert diagram.render_dot(dot) == first
        # a different text is laid out again (here: dot cannot run, and the reason is given)
        monkeypatch.setattr(diagram.subprocess, "run", lambda *a, **k: (_ for _ in ()).throw(OSError("no")))
        assert diagram.render_dot(dot + "// changed\n").svg is None
    finally:
        layoutcache.use_directory(None)
        layoutcache.forget()
