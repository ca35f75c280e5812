"""The report's kept pieces (report/fragments.py): a report rendered with a
warm cache is byte for byte the one rendered without any."""
from __future__ import annotations

import json
from pathlib import Path

import pytest
# the case study after one `doit verify` (whose report task filled the cache), as the end-to-end tests use it
from test_pipeline_e2e import _doit, workspace  # noqa: F401

from rclverify.evidence.store import dumps
from rclverify.pipeline import Workspace
from rclverify.report.build import build_report
from rclverify.report.fragments import FragmentCache, cached_dumps, fingerprint
from rclverify.report.parts import FRAGMENTS, PARTS, write_part

#: Every file the report task writes (argument.svg only with Graphviz).
FILES = ("assurance.html", "assurance.md", "assurance.json", "assurance.sarif", "assurance.junit.xml",
         "argument.json", "argument.gsn.yaml", "argument.dot", "argument.svg")


def _render(ws: Path, out: Path, fragments: FragmentCache | None) -> dict[str, bytes]:
    """Every report file of ``ws`` rendered into ``out`` (as the report task does)."""
    from rclverify.argument.export import write_argument
    from rclverify.report.ci import write_ci_reports
    from rclverify.report.render import render_all
    report = build_report(Workspace(ws))
    render_all(report, out, fragments=fragments)
    write_ci_reports(report, out, fragments)
    write_argument(report, out, fragments)
    return {name: (out / name).read_bytes() for name in FILES if (out / name).exists()}


def _reports(ws: Path, sub: str = "reports") -> dict[str, bytes]:
    return {name: (ws / sub / name).read_bytes() for name in FILES if (ws / sub / name).exists()}


def test_empty_and_warm_cache_give_the_uncached_report(workspace: Path, tmp_path: Path) -> None:
    plain = _render(workspace, tmp_path / "plain", None)
    assert set(plain) >= set(FILES) - {"argument.svg"}
    empty = FragmentCache(tmp_path / "cache.pickle")
    assert _render(workspace, tmp_path / "empty", empty) == plain
    assert empty.misses > 0 and empty.save()
    warm = FragmentCache(tmp_path / "cache.pickle")
    assert _render(workspace, tmp_path / "warm", warm) == plain
    assert warm.misses == 0 and warm.hits == empty.hits + empty.misses
    # what the doit run wrote with its own cache is the same text too
    assert _reports(workspace) == plain


def test_after_an_edit_the_warm_cache_gives_the_uncached_report(workspace: Path, tmp_path: Path) -> None:
    rcl = workspace / "contracts" / "remote_inspection.rcl"
    original = rcl.read_text()
    try:
        rcl.write_text(original.replace("and (250 <= in.r -> out.radiationStatus == red)",
                                        "and (251 <= in.r -> out.radiationStatus == red)"))
        r = _doit(workspace, "verify")  # its report task renders with the previous run's pieces
        assert r.returncode == 0, r.stdout + r.stderr
        assert _reports(workspace) == _render(workspace, tmp_path / "plain", None)
        report = build_report(Workspace(workspace))
        for part, rel in FRAGMENTS.items():  # each report task keeps the pieces of its own files
            kept = FragmentCache(workspace / rel)
            write_part(report, tmp_path / "warm", part, kept)
            assert kept.misses == 0, part  # the run kept exactly the pieces of the edited report
        assert _reports(tmp_path / "warm", "") == _reports(workspace)
    finally:
        rcl.write_text(original)
        assert _doit(workspace, "verify").returncode == 0


def test_the_report_parts_write_disjoint_files_that_together_are_the_whole_report(workspace: Path,
                                                                                 tmp_path: Path) -> None:
    plain = _render(workspace, tmp_path / "plain", None)
    report = build_report(Workspace(workspace))
    for part in reversed(PARTS):  # the order the two report tasks finish in does not matter
        written = [p.name for p in write_part(report, tmp_path / part, part)]
        assert set(written) <= set(PARTS[part]) and set(PARTS[part]) - set(written) <= {"argument.svg"}
        assert sorted(p.name for p in (tmp_path / part).iterdir()) == sorted(written)
    assert not set(PARTS["html"]) & set(PARTS["text"])
    both = {**_reports(tmp_path, "html"), **_reports(tmp_path, "text")}
    assert both == plain


def test_a_damaged_or_foreign_cache_file_is_an_empty_cache(tmp_path: Path) -> None:
    path = tmp_path / "c.pickle"
    path.write_bytes(b"not a pickle")
    cache = FragmentCache(path)
    assert cache.text("k", {"a": 1}, lambda: "x") == "x" and cache.misses == 1
    assert cache.save()
    again = FragmentCache(path)
    assert again.text("k", {"a": 1}, lambda: "y") == "x"  # kept
    assert again.text("k", {"a": 2}, lambda: "y") == "y"  # other data, other piece
    assert again.text("other", {"a": 1}, lambda: "z") == "z"  # other kind, other piece


def test_fingerprints_tell_apart_what_renders_differently() -> None:
    from markupsafe import Markup
    same = [{"a": [1, "x"], "b": None}, {"a": [1, "x"], "b": None}]
    assert fingerprint(same[0]) == fingerprint(same[1])
    # each of these renders differently (JSON, HTML or text), so none may share a key
    values = [1, True, 1.0, "1", [1], (1,), {"a": 1}, {"a": "1"}, None, "", Markup("<b>"), "<b>", [], {}]
    prints = [fingerprint(v) for v in values]
    assert len(set(prints)) == len(values)
    assert fingerprint(Markup("<b>")).startswith(b"j")  # marshal cannot hold a str subclass: canonical JSON
    with pytest.raises(TypeError):
        fingerprint({"a": object()})


def test_only_the_pieces_used_last_are_kept(tmp_path: Path) -> None:
    path = tmp_path / "c.pickle"
    first = FragmentCache(path)
    first.text("k", 1, lambda: "one")
    first.text("k", 2, lambda: "two")
    first.save()
    second = FragmentCache(path)
    second.text("k", 2, lambda: "changed")
    assert second.save()
    third = FragmentCache(path)
    assert third.text("k", 1, lambda: "again") == "again"
    assert not FragmentCache(None).save()


@pytest.mark.parametrize("value", [
    {}, [], {"a": []}, {"a": {}}, {"b": [1, 2.5, None, True, "x"], "a": {"z": [[]], "y": [{}]}},
    {"lists": [[{"deep": [1, {"k": "é\n\"q\\"}]}], [], [[[]]]], "n": [{"x": float("1e100")}]},
    {"top": [{"1": "a", "10": "b", "2": "c"}, ("tuple", 1)], "s": "\u2705 \ud83d"},
    [{"x": 1}, [{"y": [2, 3]}]], "scalar", 3,
])
def test_cached_json_text_is_the_standard_text(value: object, tmp_path: Path) -> None:
    cache = FragmentCache(tmp_path / "c.pickle")
    assert cached_dumps(value, cache) == dumps(value)
    cache.save()
    warm = FragmentCache(tmp_path / "c.pickle")
    assert cached_dumps(value, warm) == dumps(value) and warm.misses == 0


def test_cached_json_of_the_case_study_report(workspace: Path, tmp_path: Path) -> None:
    report = json.loads((workspace / "reports" / "assurance.json").read_text(encoding="utf-8"))
    assert cached_dumps(report, FragmentCache()) == dumps(report)
