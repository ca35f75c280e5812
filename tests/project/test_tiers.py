"""The tiers and the module order of tests/conftest.py name real modules
(docs/ci.md, "The test suite"): a renamed module must not drop out of its tier."""
from __future__ import annotations

from pathlib import Path

import conftest

HERE = Path(__file__).resolve().parent.parent


def test_every_module_the_tiers_name_exists() -> None:
    modules = {p.stem for p in HERE.rglob("test_*.py")}
    for name in sorted(conftest.LIVE | conftest.PIPELINE | set(conftest.SECONDS) | set(conftest.WALL)):
        assert name in modules, f"tests/conftest.py names {name}, which is not a test module"


def test_the_slow_tier_holds_the_measured_and_the_pipeline_modules() -> None:
    assert conftest.PIPELINE <= conftest.SLOW
    assert {n for n, s in conftest.SECONDS.items() if s >= 2.0} <= conftest.SLOW
    assert "test_pipeline_e2e" in conftest.SLOW and "test_rcl_parser" not in conftest.SLOW | conftest.LIVE


def test_only_live_modules_are_weighed_by_their_wall_clock_time() -> None:
    assert set(conftest.WALL) <= conftest.LIVE | conftest.MARKED_IN_MODULE
    for name in conftest.MARKED_IN_MODULE:  # each marks its live tests itself
        (path,) = HERE.rglob(f"{name}.py")
        assert "@pytest.mark.live" in path.read_text(), name


def test_this_module_is_marked_by_neither_tier(request) -> None:  # type: ignore[no-untyped-def]
    names = {m.name for m in request.node.iter_markers()}
    assert not names & {"slow", "live"}


def test_a_module_is_left_unimported_only_when_the_expression_deselects_its_tier_whatever_else() -> None:
    """``-m`` leaves a slow or live module unimported only when no test in it could be selected; the
    controls: a mark the expression also names, an expression with arguments, a tier it selects."""
    assert conftest._never_selected("not slow and not live", {"slow"})
    assert conftest._never_selected("not slow and not live", {"live"})
    assert conftest._never_selected("not live", {"slow", "live"})
    assert not conftest._never_selected("slow and not live", {"slow"})  # the slow tier itself
    assert not conftest._never_selected("not slow or hypothesis", {"slow"})  # a test of it may carry the other
    assert not conftest._never_selected("not slow and not live", set())
    assert not conftest._never_selected("not slow(reason=1)", {"slow"})
