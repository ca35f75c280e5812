"""The registry of the plan's entry schemas (model/plan/entries.py) sits below
both the plan and the backends (issue 25, circle 1) and names exactly the
implemented backends; that the plan imports nothing of the backends is
tests/project/test_layers.py's rule for the model layer."""
from __future__ import annotations


from rclverify.backends import IMPLEMENTED, KNOWN
from rclverify.backends.keys import ENTRY_KEYS
from rclverify.model.plan.entries import BACKEND_NAMES, SCHEMAS, TOOL_KEYS, allowed_keys, declared_paths

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
