"""Each backend declares itself once, in its folder's ``declaration.yaml``, and every table reads it.

The plan's entry schemas, the implementations, the ``expected`` check's whole-contract backends,
the GSN strength, the report's columns and model-checking problems, the evidence tasks' tool
fingerprint and the bundle's tool versions are all derived from the declarations; a malformed
declaration is refused naming its file and the fault.
"""
from __future__ import annotations

from pathlib import Path

import pytest

from rclverify.app.task_checks import tool_fingerprint
from rclverify.backends import IMPLEMENTED, get_backend
from rclverify.model.plan.declarations import (BACKEND_NAMES, DECLARATIONS, REGISTRY, DeclarationError, declared_in,
                                               parse)
from rclverify.model.plan.entries import SCHEMAS, TOOL_PATH_KINDS
from rclverify.model.plan.expected import WHOLE_CONTRACT_BACKENDS
from rclverify.report.argument.strength import BACKEND_KIND
from rclverify.report.problems_mc import MC_BACKENDS
from rclverify.records.statuses import EVIDENCE_KINDS
from rclverify.report.dashboard import TECHNIQUES

SRC = Path(__file__).resolve().parents[2] / "src" / "rclverify" / "backends"


def test_every_registered_backend_has_its_declaration_in_its_own_folder() -> None:
    assert tuple(REGISTRY) == BACKEND_NAMES
    on_disk = {p.parent.relative_to(SRC).as_posix() for p in SRC.rglob("declaration.yaml")}
    assert on_disk == set(REGISTRY.values())
    for name, d in DECLARATIONS.items():
        backend = get_backend(name)
        assert (backend.name, backend.kind) == (d.name, d.evidence_kind)
        module = __import__(IMPLEMENTED[name][0], fromlist=["_"])
        assert declared_in(str(module.__file__)) is d


def test_every_table_is_read_from_the_declarations() -> None:
    assert set(SCHEMAS) == set(BACKEND_KIND) == set(IMPLEMENTED) == set(DECLARATIONS)
    assert TECHNIQUES == ("health", "side conditions", *BACKEND_NAMES)
    assert set(WHOLE_CONTRACT_BACKENDS) == {"dafny", "monitors"}
    assert MC_BACKENDS == ("ajpf",)
    assert TOOL_PATH_KINDS == {"dafny": "executable", "mcapl_home": "directory"}
    for name, d in DECLARATIONS.items():
        assert SCHEMAS[name].keys == d.plan.keys and BACKEND_KIND[name] == d.strength
    assert {t.name for d in DECLARATIONS.values() for t in d.tools} <= set(tool_fingerprint())
    # the evidence kinds the report's schema publishes are exactly the declared ones
    assert {d.evidence_kind for d in DECLARATIONS.values()} == set(EVIDENCE_KINDS)


GOOD = """\
name: sketch
implementation: pkg.mod:Sketch
evidence_kind: proof
strength: proof
whole_contract: false
plan:
  keys: [program, exe]
  path_keys: [program]
  tool_keys: [exe]
  tool_paths: {exe: executable}
tools:
  - {name: sketcher, which: sketcher}
"""


def test_a_well_formed_declaration_is_read_whole() -> None:
    d = parse(GOOD, "sketch", "sketch")
    assert (d.name, d.implementation, d.evidence_kind, d.strength, d.whole_contract) == \
        ("sketch", "pkg.mod:Sketch", "proof", "proof", False)
    assert d.plan.keys == ("program", "exe") and d.plan.tool_paths == {"exe": "executable"}
    assert [(t.name, t.which, t.env) for t in d.tools] == [("sketcher", "sketcher", ())]


@pytest.mark.parametrize("edit, fault", [
    (("name: sketch", "name: other"), "the registry calls it 'sketch'"),
    (("strength: proof", "strength: strong"), "strength 'strong' is none of"),
    (("evidence_kind: proof", "evidence_kind: vibes"), "evidence_kind 'vibes' is none of"),
    (("evidence_kind: proof\n", "colour: red\nevidence_kind: proof\n"), "unknown key(s) colour"),
    (("path_keys: [program]", "path_keys: [programme]"), "plan.path_keys names keys not in plan.keys: programme"),
    (("tool_paths: {exe: executable}", "tool_paths: {exe: file}"), "tool_paths must map"),
    (("{name: sketcher, which: sketcher}", "{name: sketcher}"), "exactly one of which, env"),
    (("whole_contract: false", "whole_contract: maybe"), "whole_contract true or false"),
    (("keys: [program, exe]", "keys: [program, exe"), "not YAML"),
])
def test_a_malformed_declaration_is_refused_naming_its_file(edit: tuple[str, str], fault: str) -> None:
    text = GOOD.replace(*edit)
    assert text != GOOD
    with pytest.raises(DeclarationError) as exc:
        parse(text, "sketch", "sketch")
    assert str(exc.value).startswith("rclverify/backends/sketch/declaration.yaml") and fault in str(exc.value)
