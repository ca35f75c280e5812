"""The texts kept per contract file (stages/contract_texts.py): the same with the
cache as without it, made again for an edited file, and a bad cache file is
an empty cache."""
from __future__ import annotations

import pickle
from pathlib import Path

from rclverify.stages.contract_texts import CACHE, ContractTexts, lint_json, node_texts
from rclverify.app.pipeline import Workspace

RCL = """node A {
  inputs( x : REAL )
  outputs( y : REAL )
  assume( 0 <= in.x )
  guarantee( 0 <= out.y -> out.y <= in.x + 1 -> out.y <= 9 )
}
node B {
  inputs( y : REAL )
  outputs( z : REAL, w : REAL )
  guarantee( out.z == in.y )
}
"""


def _ws(root: Path, text: str = RCL) -> Workspace:
    (root / "contracts").mkdir(parents=True, exist_ok=True)
    (root / "contracts" / "a.rcl").write_text(text)
    (root / "contracts" / "plan.yaml").write_text("contracts: [contracts/a.rcl]\n")
    return Workspace(root)


def _all(texts: ContractTexts, ws: Workspace) -> tuple[list[dict[str, object]], list[object]]:
    return ([texts.node(cn.node) for cn in ws.checked.nodes.values()],
            [w for s in ws.checked.specs for w in texts.lint(s)])


def test_kept_texts_are_the_texts_made_from_the_syntax_tree(tmp_path: Path) -> None:
    ws = _ws(tmp_path)
    made = ([node_texts(cn.node) for cn in ws.checked.nodes.values()],
            [w for s in ws.checked.specs for w in lint_json(s)])
    (text, src), = made[0][0]["guarantees"]
    assert text.startswith("0 <= out.y ->") and src == "contracts/a.rcl:5:3"
    assert made[0][0]["assumptions"] == [["0 <= in.x", "contracts/a.rcl:4:3"]]
    assert made[0][0]["inputs"] == [["x", "REAL"]] and made[0][1]["outputs"] == [["z", "REAL"], ["w", "REAL"]]
    assert {w["code"] for w in made[1]} == {"W-implication-precedence", "W-unconstrained-output"}
    first = ContractTexts(ws)
    assert _all(first, ws) == made
    assert first.save() and not first.save()  # written once; nothing new to write
    again = Workspace(tmp_path)
    kept = ContractTexts(again)
    assert _all(kept, again) == made and not kept.save()  # all from the file


def test_an_edited_file_gets_its_texts_made_again(tmp_path: Path) -> None:
    ws = _ws(tmp_path)
    texts = ContractTexts(ws)
    _all(texts, ws)
    texts.save()
    edited = _ws(tmp_path, RCL.replace("out.z == in.y", "out.z == in.y + 2"))
    texts = ContractTexts(edited)
    nodes, _ = _all(texts, edited)
    assert nodes[1]["guarantees"][0][0] == "out.z == in.y + 2"
    assert texts.save()


def test_a_damaged_or_foreign_cache_is_an_empty_cache(tmp_path: Path) -> None:
    ws = _ws(tmp_path)
    path = tmp_path / CACHE
    path.parent.mkdir(parents=True)
    for content in (b"not a pickle", pickle.dumps({"salt": "other", "files": {}}), pickle.dumps([1, 2])):
        path.write_bytes(content)
        texts = ContractTexts(ws)
        assert _all(texts, ws)[0][0]["rcl"].startswith("node A {")
        assert texts.save()  # made, so written
