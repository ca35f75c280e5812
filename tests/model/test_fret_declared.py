"""What the plan declares for a FRET export (rclverify.model.plan.fret.declared; docs/requirements.md,
"Requirements from FRET"): FRET's sqrt/sin/cos as RCL's own, a model function defined in RCL by
``fret: functions:``, the idType of a variable by ``fret: variables:``; each without its declaration
refused at its reqid, naming the key that would import it."""
from __future__ import annotations

from typing import Any

import msgspec

from rclverify.lang import ast
from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.plan.fret.export import FretExport, FretRequirement, FretSemantics, FretVariable
from rclverify.model.plan.fret.requirements import Imported, import_export, options_of
from rclverify.model.plan.state import state_types
from rclverify.model.plan.temporal import Temporal, parse_temporal

CONTRACT = """
node Arm {
  inputs( a : REAL, b : REAL, c : REAL, d : REAL, theta : REAL, v : REAL )
  outputs( ok : BOOL, x : REAL, y : REAL )
  assume( TRUE )
  guarantee( TRUE )
}
"""
VARS = {"a": "Input", "b": "Input", "c": "Input", "d": "Input", "theta": "Input", "ok": "Output", "x": "Output",
        "y": "Output", "v": ""}  # v: declared without an idType


def _import(post: str, fret: dict[str, Any] | None = None) -> Imported:
    sem = {"scope": {"type": "null"}, "condition": "null", "timing": "always", "response": "satisfaction",
           "component_name": "arm", "post_condition": post}
    req = FretRequirement("R-1", f"arm shall always satisfy {post}", "arm", msgspec.convert(sem, FretSemantics),
                          ast.Loc("x.json", 3, 1), "", {})
    variables = {("arm", n): FretVariable("arm", n, k, "boolean" if n == "ok" else "double", "") for n, k in VARS.items()}
    (imp,) = import_export(FretExport("x.json", (req,), variables), options_of({"fret": {"components": {"arm": "Arm"},
                                                                                             **(fret or {})}}))
    return imp


def _formal(imp: Imported) -> str:
    assert imp.requirement.formal is not None, imp.refusal
    return imp.requirement.formal.text


def _checks(imp: Imported) -> None:
    checked = check([parse_text(CONTRACT, "arm.rcl")])
    assert imp.requirement.formal is not None
    assert isinstance(parse_temporal(imp.requirement.formal, checked, "R-1", state_types(imp.states, checked)),
                      Temporal)


def test_fret_math_functions_are_rcl_s_own() -> None:
    imp = _import("(x = sqrt(a) * cos(theta) & y <= sin(theta))")
    assert imp.refusal is None
    assert "sqrt(Arm.in.a)" in _formal(imp) and "cos(Arm.in.theta)" in _formal(imp)
    _checks(imp)


DET2 = {"functions": {"det2": {"args": ["p", "q", "r", "s"], "rcl": "p * s - q * r"}}}


def test_a_model_function_is_defined_in_the_plan() -> None:
    post = "(det2(a, b + 1.0, c, d) = x)"
    refused = _import(post)  # the control: the export carries only the name
    assert refused.refusal is not None and "det2" in refused.refusal.reason
    assert "fret: functions" in refused.refusal.fix
    imp = _import(post, DET2)
    assert imp.refusal is None
    assert "((Arm.in.a) * (Arm.in.d) - ((Arm.in.b + 1.0)) * (Arm.in.c))" in _formal(imp)
    _checks(imp)


def test_a_declared_function_with_other_arguments_or_names_is_refused_with_the_reason() -> None:
    imp = _import("(det2(a, b, c) = x)", DET2)
    assert imp.refusal is not None and "with 3 arguments" in imp.refusal.reason and "with 4" in imp.refusal.reason
    bad = {"functions": {"det2": {"args": ["p", "q", "r", "s"], "rcl": "p * s - q * w"}}}
    imp = _import("(det2(a, b, c, d) = x)", bad)
    assert imp.refusal is not None and "reads w, which is no parameter" in imp.refusal.reason
    broken = {"functions": {"det2": {"args": ["p", "q", "r", "s"], "rcl": "p * * s"}}}
    imp = _import("(det2(a, b, c, d) = x)", broken)
    assert imp.refusal is not None and "does not parse" in imp.refusal.reason


def test_a_variable_without_an_idtype_is_placed_by_the_plan() -> None:
    refused = _import("(y <= v)")
    assert refused.refusal is not None and "v is declared without an idType" in refused.refusal.reason
    assert "the plan's fret: variables" in refused.refusal.fix
    imp = _import("(y <= v)", {"variables": {"v": "input"}})
    assert imp.refusal is None and "Arm.in.v" in _formal(imp)
    _checks(imp)
    as_output = _import("(y <= v)", {"variables": {"v": "output"}})
    assert "Arm.out.v" in _formal(as_output)
