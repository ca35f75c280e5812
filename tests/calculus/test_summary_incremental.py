"""Incremental equals clean where side conditions are decided from cone
summaries (calculus/summary.py): the query over the summaries runs in the
node's solver session, before the whole cone's when it fails, so a
counterexample's values depend on the order of the session's queries; an
incremental ``doit verify`` after an edit upstream must still write what a
run from scratch writes (docs/integrity.md)."""
from __future__ import annotations

import json
from pathlib import Path

from _chain import write_chain
from _incremental import compare, verify


def _statuses(root: Path) -> dict[str, str]:
    out = {}
    for f in sorted((root / "artifacts/calculus").glob("*.json")):
        for sc in json.loads(f.read_text(encoding="utf-8"))["side_conditions"]:
            out[sc["id"]] = sc.get("verdict") or sc["status"]
    return out


def test_an_upstream_edit_gives_what_a_clean_run_gives(tmp_path: Path) -> None:
    # x_i <= 50 + i along the chain; every assumption x_i <= 60: it holds in context up to N10, not after
    ws = write_chain(tmp_path / "chain", 14, bound=60, requirements=[("SYS", "N13.out.x14 <= 70")])
    first = verify(ws)
    assert first.returncode == 0, first.stdout[-2000:] + first.stderr[-2000:]
    before = _statuses(ws)
    assert before["N5.sc2"] == before["N10.sc2"] == "discharged in context" and before["N11.sc2"] == "failed"
    rcl = ws / "contracts/chain.rcl"  # N4 now adds 6: the assumptions fail in context from N6 on
    rcl.write_text(rcl.read_text(encoding="utf-8").replace("out.x5 <= in.x4 + 1", "out.x5 <= in.x4 + 6"),
                   encoding="utf-8")
    assert compare(ws, tmp_path / "scratch" / "chain") == []
    after = _statuses(ws)
    assert after["N5.sc2"] == "discharged in context" and after["N6.sc2"] == after["N11.sc2"] == "failed"
