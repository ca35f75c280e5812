"""FRET's scopes and timings stated from FRET's own past-time formalisation, against that formalisation.

Every (scope, condition, timing) combination that the importer states from
the export's ``ptExpanded`` (rclverify.model.plan.fret.pasttime: the scopes
in, notin, before, after, onlyIn, onlyBefore and onlyAfter, the timings
after and before, ...) carries, in its export entry, the ``ptExpanded``
FRET v3.1.0 gives that combination (``tests/data/fret/pt_templates.json``,
FRET's ``semantics.json`` over this test's names, duration 2).  On random
finite traces the oracle of tests/model/test_fret_differential.py evaluates
it at the trace's last step, and rclverify's verdict on the imported
statement (parsed and type-checked by rclverify, its state variables run by
rclverify's evaluator) must agree: FRET true exactly when rclverify's verdict
is not false.  The combinations whose formalisation is not prefix-closed
are refused, and the test shows why on FRET's formula: a trace at whose end
it holds though it failed at the end of a prefix.  The control: an
importer fed FRET's formula with ``Z`` read as ``Y`` disagrees with FRET.
"""
from __future__ import annotations

import json
import random
import zlib
from fractions import Fraction
from pathlib import Path
from typing import Any

import pytest

from rclverify.lang.parser import parse_text
from rclverify.lang.typecheck import check
from rclverify.model.plan.fret.pasttime import CLOSED
from rclverify.model.plan.fret.requirements import Options, import_export
from rclverify.model.plan.fret.translate import SUPPORTED
from test_fret_differential import CONTRACT, VARS, _disagree_on, _disagreements, _export, _pt, _pt_parse

DATA = json.loads((Path(__file__).parents[1] / "data" / "fret" / "pt_templates.json").read_text(encoding="utf-8"))
NAMES = {"scope_mode": "manual", "regular_condition": "obstacle", "post_condition": "braking",
         "stop_condition": "clear"}
DURATION = 2
TRACES = 12


def _step(rng: random.Random) -> dict[str, Any]:
    return {n: (rng.random() < 0.5) if d == "boolean" else Fraction(rng.choice([0, 1, 2, 3])) for n, (_, d) in VARS.items()}


def _trace(rng: random.Random) -> list[dict[str, Any]]:
    """A random trace of 1 to 10 steps whose values change at a step with probability 0.4 (modes and
    conditions that last, so that scopes open and close and windows fill)."""
    now = _step(rng)
    out = [now]
    for _ in range(rng.randint(0, 9)):
        nxt = _step(rng)
        now = {n: nxt[n] if rng.random() < 0.4 else v for n, v in now.items()}
        out.append(now)
    return out


def _formula(template: str) -> str:
    t = template.replace("$duration$+1", str(DURATION + 1)).replace("$duration$", str(DURATION))
    for k, v in NAMES.items():
        t = t.replace(f"${k}$", v)
    return t


def _case(key: str, pt: str) -> tuple[Any, ...]:
    scope, cond, timing = key.split(",")
    extra = {"duration": DURATION, "stop_condition": "(clear)", "scope_mode": "manual"}
    return (key, scope, cond, timing, None if cond == "null" else "(obstacle)", "(braking)", extra, pt)


@pytest.fixture(scope="module")
def checked() -> Any:
    return check([parse_text(CONTRACT, "rover.rcl")])


def test_the_templates_are_the_combinations_stated_from_fret() -> None:
    """The data file holds exactly the combinations the importer states from ptExpanded: every one is tested."""
    stated = {f"{s},{c},{t}" for s in CLOSED for c in ("null", "regular", "holding") for t in CLOSED[s]
              if t not in SUPPORTED.get((s, c), ())}
    assert set(DATA["closed"]) == stated
    assert len(stated) == 191


def _sample(key: str, pt_text: str) -> list[list[dict[str, Any]]]:
    """Random traces (module's generator, seeded by ``key``) on which FRET's formula is false and true, up to
    ``TRACES // 2`` of each, drawn from at most 400."""
    pt, rng = _pt_parse(pt_text), random.Random(zlib.crc32(key.encode()))
    by: dict[bool, list[list[dict[str, Any]]]] = {True: [], False: []}
    for _ in range(400):
        tr = _trace(rng)
        got = by[bool(_pt(pt, tr, len(tr) - 1))]
        if len(got) < TRACES // 2:
            got.append(tr)
        if all(len(v) == TRACES // 2 for v in by.values()):
            break
    return by[False] + by[True]


@pytest.mark.parametrize("key", sorted(DATA["closed"]))
def test_stated_reading_equals_fret(key: str, checked: Any) -> None:
    """Over traces on which FRET's formula is false and traces on which it is true (both found for every
    combination), rclverify's verdict on the statement agrees."""
    pt = _formula(DATA["closed"][key])
    (imp,) = import_export(_export([_case(key, pt)]), Options(components={"rover": "Rover"}))
    assert imp.refusal is None, imp.refusal
    assert imp.requirement.formal is not None and imp.requirement.formal.text.startswith("always (")
    traces = _sample(key, pt)
    tree = _pt_parse(pt)
    assert {bool(_pt(tree, tr, len(tr) - 1)) for tr in traces} == {True, False}
    assert _disagree_on(imp, checked, pt, traces) == []


def test_z_read_as_y_disagrees_with_fret(checked: Any) -> None:
    """The control: the importer given FRET's formula with its first-step operator Z read as Y states
    another requirement, and the comparison finds a trace where it differs from FRET's."""
    key = "in,regular,immediately"
    pt = _formula(DATA["closed"][key])
    (imp,) = import_export(_export([_case(key, pt.replace("Z", "Y"))]), Options(components={"rover": "Rover"}))
    assert imp.refusal is None
    assert _disagreements(imp, checked, pt, 100, 3, _trace) != []


@pytest.mark.parametrize("key", sorted(DATA["open"]))
def test_a_formalisation_not_prefix_closed_is_refused(key: str) -> None:
    """FRET's formula holds at the end of some trace but not at the end of one of its prefixes, so no
    ``always`` statement has its reading: the importer refuses it, saying why."""
    pt = _formula(DATA["open"][key])
    tree, rng = _pt_parse(pt), random.Random(5)
    witness = None
    for _ in range(3000):
        tr = _trace(rng)
        vals = [bool(_pt(tree, tr, i)) for i in range(len(tr))]
        if vals[-1] and not all(vals):
            witness = tr
            break
    assert witness is not None
    (imp,) = import_export(_export([_case(key, pt)]), Options(components={"rover": "Rover"}))
    assert imp.refusal is not None and imp.requirement.formal is None
    assert "finally" in imp.refusal.reason or "liveness" in imp.refusal.reason


def test_a_combination_stated_by_hand_stays_so() -> None:
    """A combination of translate.py's table keeps its hand-written statement (no ptExpanded state)."""
    case = ("UPON", "null", "regular", "immediately", "(obstacle)", "(braking)", {}, "(H (Y TRUE))")
    (imp,) = import_export(_export([case]), Options(components={"rover": "Rover"}))
    assert imp.requirement.formal is not None and "_pt" not in imp.requirement.formal.text


def test_a_look_back_beyond_the_bound_is_refused() -> None:
    pt = "(H ((O[=40] obstacle) -> braking))"
    (imp,) = import_export(_export([("LONG", "after", "null", "for", None, "(braking)",
                                      {"duration": 40, "scope_mode": "manual"}, pt)]),
                           Options(components={"rover": "Rover"}))
    assert imp.refusal is not None and "looks back 40 steps" in imp.refusal.reason
    short = pt.replace("40", "3")
    (ok,) = import_export(_export([("SHORT", "after", "null", "for", None, "(braking)",
                                    {"duration": 3, "scope_mode": "manual"}, short)]),
                          Options(components={"rover": "Rover"}))
    assert ok.refusal is None
