"""YAML and text rules of every input (issue 20): a tag on a list or a mapping
is refused like one on a scalar, a duplicate key is a located error (plan,
review records, experiment summaries, trace mappings: one guarded loader), a
UTF-8 byte-order mark is accepted (RCL and YAML), UTF-16/32 and invalid
UTF-8 are one located message naming the encoding."""
from __future__ import annotations

import codecs
import shutil
from pathlib import Path

import pytest
import yaml

from rclverify.cli.commands import main
from rclverify.model.plan.errors import PlanError
from rclverify.model.plan.load import load_plan
from rclverify.model.plan.yamlguard import load_located, safe_load_guarded
from rclverify.lang.errors import RclError
from rclverify.lang.parser import parse_file
from rclverify.lang.source import decode_text
from rclverify.app.tasks import act_check

from _evidence_ws import REPO, copy_workspace, plan_line

RCL = "contracts/sensor.rcl"


def init_ws(tmp_path: Path) -> Path:
    ws = tmp_path / "ws"
    assert main(["init", str(ws)]) == 0
    return ws


def edit_plan(ws: Path, old: str, new: str) -> str:
    p = ws / "contracts/plan.yaml"
    text = p.read_text(encoding="utf-8")
    assert old in text
    text = text.replace(old, new, 1)
    p.write_text(text, encoding="utf-8")
    return text


@pytest.mark.parametrize("tagged", [
    "!!python/tuple [contracts/sensor.rcl, contracts/controller.rcl, contracts/actuator.rcl]",
    "!!set {contracts/sensor.rcl: null}",
    "!custom [contracts/sensor.rcl]",
    "!!python/object/apply:os.system [echo hi]",
])
def test_a_tag_on_a_collection_is_refused_like_on_a_scalar(tmp_path: Path, tagged: str) -> None:
    # Before: the tag was dropped silently and the plan ran with rc 0.
    ws = init_ws(tmp_path)
    text = (ws / "contracts/plan.yaml").read_text(encoding="utf-8")
    start = text.index("contracts:\n")
    end = text.index("\n\n", start)
    (ws / "contracts/plan.yaml").write_text(text[:start] + f"contracts: {tagged}" + text[end:], encoding="utf-8")
    line, col = plan_line(ws, "contracts: !")
    with pytest.raises(PlanError) as exc:
        load_plan(ws)
    d = exc.value.diagnostics[0]
    assert (d.loc.line, d.loc.col) == (line, col + len("contracts: ")) and d.code == "E-yaml"
    assert "is not allowed" in d.message and tagged.split()[0] in d.message


def test_a_tag_on_a_scalar_is_still_refused(tmp_path: Path) -> None:
    ws = init_ws(tmp_path)
    edit_plan(ws, 'name: "ws"', "name: !!python/name:os.system x")
    with pytest.raises(PlanError, match=r"plan\.yaml:\d+:7: error: invalid YAML: could not determine a constructor"):
        load_plan(ws)


def test_a_duplicate_plan_key_is_located_at_the_second(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # Before: the last `name` won silently.
    ws = init_ws(tmp_path)
    edit_plan(ws, 'name: "ws"\n', 'name: "ws"\nname: "other"\n')
    first, _ = plan_line(ws, 'name: "ws"')
    second, _ = plan_line(ws, 'name: "other"')
    assert main(["compose", "-w", str(ws)]) == 1
    err = capsys.readouterr().err
    assert err == (f"contracts/plan.yaml:{second}:1: error: duplicate key 'name' in a mapping (first written at line "
                   f"{first}); each key may appear once\n")


def test_duplicate_keys_deep_in_the_plan_and_in_every_yaml_the_plan_names(tmp_path: Path) -> None:
    copy_workspace(tmp_path)
    rec = tmp_path / "backends/review/localisation.yaml"
    rec.write_text(rec.read_text(encoding="utf-8") + "verdict: pass\n", encoding="utf-8")
    n = len(rec.read_text(encoding="utf-8").splitlines())
    out = str(act_check(str(tmp_path)))
    assert f"backends/review/localisation.yaml:{n}:1: error: duplicate key 'verdict'" in out
    summary = tmp_path / "backends/experiment/navigation.yaml"
    text = summary.read_text(encoding="utf-8")
    key = next(l.split(":")[0] for l in text.splitlines() if l and not l.startswith((" ", "#")))
    summary.write_text(text + f"{key}: 1 cm\n", encoding="utf-8")
    n = len(summary.read_text(encoding="utf-8").splitlines())
    assert f"backends/experiment/navigation.yaml:{n}:1: error: duplicate key {key!r}" in str(act_check(str(tmp_path)))


def test_the_guarded_loader_agrees_with_safe_load_on_plain_yaml() -> None:
    for rel in ("contracts/plan.yaml", "backends/monitors/mapping.yaml", "backends/review/localisation.yaml",
                "backends/experiment/navigation.yaml"):
        text = (REPO / rel).read_text(encoding="utf-8")
        assert safe_load_guarded(text, rel) == yaml.safe_load(text), rel
    data, locs = load_located("a:\n  - 1\n  - {b: 2}\n1: x\n", "f.yaml")
    assert data == {"a": [1, {"b": 2}], 1: "x"} and (locs[("a", 1, "b")].line, locs[("a", 1, "b")].col) == (3, 9)
    with pytest.raises(PlanError, match=r"^m\.yaml:3:3: error: duplicate key 'x'"):
        safe_load_guarded("t:\n  x: 1\n  x: 2\n", "m.yaml")
    with pytest.raises(PlanError, match=r"^m\.yaml:3:3: error: merge keys \('<<'\)"):
        safe_load_guarded("a: &x {k: 1}\nb:\n  <<: *x\n", "m.yaml")
    assert safe_load_guarded("a: &x [1, 2]\nb: *x\n", "m.yaml") == {"a": [1, 2], "b": [1, 2]}


def test_a_duplicate_key_in_a_trace_mapping_is_located_in_the_mapping(tmp_path: Path) -> None:
    copy_workspace(tmp_path)
    shutil.copytree(REPO / "backends/monitors", tmp_path / "backends/monitors")
    mapping = tmp_path / "backends/monitors/mapping.yaml"
    mapping.write_text(mapping.read_text(encoding="utf-8") + "horizon: 3.0\n", encoding="utf-8")
    n = len(mapping.read_text(encoding="utf-8").splitlines())
    assert f"backends/monitors/mapping.yaml:{n}:1: error: duplicate key 'horizon'" in str(act_check(str(tmp_path)))


def test_a_utf8_byte_order_mark_is_accepted_in_rcl_and_yaml(tmp_path: Path) -> None:
    # Before: a BOM at the start of an RCL file was a syntax error.
    ws = init_ws(tmp_path)
    for rel in (RCL, "contracts/plan.yaml"):
        p = ws / rel
        p.write_bytes(codecs.BOM_UTF8 + p.read_bytes())
    spec = parse_file(ws / RCL)
    assert spec.nodes[0].loc.line == next(i for i, l in enumerate((ws / RCL).read_text("utf-8-sig").splitlines(), 1)
                                          if l.startswith("node"))
    assert load_plan(ws).name == "ws"
    assert act_check(str(ws)) is None
    assert main(["compose", "-w", str(ws)]) == 0


@pytest.mark.parametrize("codec, name", [("utf-16-le", "UTF-16 (little-endian)"), ("utf-16-be", "UTF-16 (big-endian)"),
                                         ("utf-32-le", "UTF-32 (little-endian)"), ("utf-32-be", "UTF-32 (big-endian)")])
def test_utf16_and_utf32_files_are_one_message_naming_the_encoding(
        tmp_path: Path, codec: str, name: str, capsys: pytest.CaptureFixture[str]) -> None:
    ws = init_ws(tmp_path)
    boms = {"utf-16-le": codecs.BOM_UTF16_LE, "utf-16-be": codecs.BOM_UTF16_BE,
            "utf-32-le": codecs.BOM_UTF32_LE, "utf-32-be": codecs.BOM_UTF32_BE}
    p = ws / RCL
    p.write_bytes(boms[codec] + p.read_text(encoding="utf-8").encode(codec))
    assert main(["check", str(p)]) == 1
    err = capsys.readouterr().err
    assert err.count("error:") == 1 and err.startswith(f"{p}:1:1: error: file is encoded as {name}")
    assert main(["compose", "-w", str(ws)]) == 1
    assert capsys.readouterr().err.startswith(f"{RCL}:1:1: error: file is encoded as {name}")
    plan = ws / "contracts/plan.yaml"
    plan.write_bytes(boms[codec] + plan.read_text(encoding="utf-8").encode(codec))
    with pytest.raises(PlanError, match=rf"^contracts/plan\.yaml:1:1: error: file is encoded as {name.replace('(', '.').replace(')', '.')}"):
        load_plan(ws)


def test_invalid_utf8_is_located_at_the_bad_byte(tmp_path: Path) -> None:
    with pytest.raises(RclError) as exc:
        decode_text(b"node A\n  x \xff y\n", "a.rcl")
    d = exc.value.diagnostics[0]
    assert (d.loc.line, d.loc.col, d.code) == (2, 5, "E-encoding") and "invalid UTF-8 (byte 0xff at offset 11)" in d.message
    with pytest.raises(RclError, match=r"a\.rcl:1:2: error: NUL character"):
        decode_text("a\0b".encode("utf-8"), "a.rcl")
    assert decode_text(codecs.BOM_UTF8 + "é\n".encode(), "a.rcl") == "é\n"


def test_libyaml_composes_the_nodes_pyyaml_does() -> None:
    """The guarded loader composes with libyaml where PyYAML has it; every YAML file of the
    repository gives the same node graph (kinds, tags, values, styles and marks) either way."""
    import yaml

    from rclverify.model.plan import yamlguard
    if yamlguard._COMPOSER is yaml.SafeLoader:
        pytest.skip("PyYAML built without libyaml: only its own loader is used")

    def shape(node: yaml.Node) -> object:
        marks = (node.start_mark.line, node.start_mark.column, node.end_mark.line, node.end_mark.column)
        if isinstance(node, yaml.ScalarNode):
            return ("s", node.tag, node.value, node.style or None, marks)  # plain: None or ""
        if isinstance(node, yaml.SequenceNode):
            return ("q", node.tag, [shape(c) for c in node.value], marks)
        return ("m", node.tag, [(shape(k), shape(v)) for k, v in node.value], marks)
    root = Path(__file__).resolve().parents[2]
    # the repository's own files: not what runs write (artifacts/, reports/) or a virtual environment
    skip = {"artifacts", "reports", "site-packages", "node_modules"}
    files = [p for pattern in ("*.yaml", "*.yml") for p in root.rglob(pattern)
             if not skip & set(p.relative_to(root).parts) and not any(x.startswith(".") for x in p.relative_to(root).parts)]
    assert len(files) > 10
    for p in files:
        text = p.read_text(encoding="utf-8")
        try:
            c = yaml.compose(text, Loader=yamlguard._COMPOSER)
        except yaml.YAMLError:
            continue  # malformed on purpose: composed again by PyYAML's loader for its message
        py = yaml.compose(text, Loader=yaml.SafeLoader)
        assert (c is None) == (py is None), p
        if c is not None:
            assert shape(c) == shape(py), p
