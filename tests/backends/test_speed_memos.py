"""Fast paths of issue 67's fourth round held to their references: an
obligation's JSON mapping without ``asdict``'s deep copy, and the import
closure's parsed imports kept per file text (never a stale closure after
an edit)."""
from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import Any

from hypothesis import given, settings, strategies as st

from rclverify.backends.property_tests.closure import import_closure
from rclverify.records.records import Obligation, SourceRef

JSON = st.recursive(st.none() | st.integers() | st.text(max_size=5),
                    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=4), inner, max_size=3),
                    max_leaves=10)


def _reference(o: Obligation) -> dict[str, Any]:
    """Obligation.to_json as it was: ``asdict`` with ``inputs`` and ``data`` replaced."""
    d = asdict(o)
    d["inputs"] = list(o.inputs)
    d["data"] = dict(o.data)
    return d


@settings(max_examples=60, deadline=None)
@given(st.text(max_size=8), st.integers(1, 9), st.text(max_size=8), st.lists(st.text(max_size=6), max_size=3),
       st.dictionaries(st.text(max_size=5), JSON, max_size=4), st.integers(1, 500))
def test_an_obligations_mapping_is_the_reference_one(oid: str, g: int, instance: str, inputs: list[str],
                                                     data: dict[str, Any], line: int) -> None:
    o = Obligation(oid, "N1", g, "hoare", "proof", "x <= 1", SourceRef("c.rcl", line, 3), instance, "a.txt",
                   tuple(inputs), data)
    got, ref = o.to_json(), _reference(o)
    assert got == ref and list(got) == list(ref)  # the same keys in the same order
    assert Obligation.from_json(got) == o


def test_the_closure_follows_an_edit_of_a_file_it_already_parsed(tmp_path: Path) -> None:
    (tmp_path / "helper.py").write_text("X = 1\n")
    (tmp_path / "other.py").write_text("Y = 2\n")
    impl = tmp_path / "impl.py"
    impl.write_text("import helper\n")
    assert import_closure(tmp_path, "impl.py")[0] == ["helper.py", "impl.py"]
    assert import_closure(tmp_path, "impl.py")[0] == ["helper.py", "impl.py"]  # the kept parse
    impl.write_text("import helper\nfrom other import Y\nimport numpy\n")
    files, outside = import_closure(tmp_path, "impl.py")
    assert files == ["helper.py", "impl.py", "other.py"] and outside == ["numpy"]
    impl.write_text("import helper\n")  # back to a text parsed before: its kept imports, not the last ones
    assert import_closure(tmp_path, "impl.py")[0] == ["helper.py", "impl.py"]
    impl.write_text("def broken(:\n")
    assert import_closure(tmp_path, "impl.py")[0] == ["impl.py"]
