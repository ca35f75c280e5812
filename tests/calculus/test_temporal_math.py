"""Temporal requirements over contracts applying sqrt/sin/cos (calculus/requirements/math_runs.py;
docs/semantics.md, "Mathematical functions"): the facts in every state of the transition system, and no
refutation through a sine read as an unknown function.  A small workspace through the pipeline, real Z3."""
from __future__ import annotations

import json
from pathlib import Path

OSC = """node Osc { inputs( x : REAL ) outputs( y : REAL )
  guarantee( out.y == sin(in.x) )
  progress( within 0 steps ) }
node Root { inputs( x : REAL ) outputs( r : REAL )
  guarantee( out.r == sqrt(in.x * in.x) )
  progress( within 0 steps ) }
"""

def test_temporal_requirements_read_the_facts_and_never_refute_through_an_unknown_sine(tmp_path: Path) -> None:
    """Over the transition system every state carries the facts (proofs of ``y <= 1`` and ``r >= 0``);
    a refutation through ``sqrt`` alone is a verdict; one found reading ``sin`` as an unknown function
    and not confirmed on its values is ``inconclusive`` with the reason (here even where the real sine
    violates it: the run is not confirmed, docs/semantics.md, "Mathematical functions")."""
    from rclverify.app.pipeline import Workspace, stage_check, stage_requirements
    ws = tmp_path / "osc"
    (ws / "contracts").mkdir(parents=True)
    (ws / "contracts/osc.rcl").write_text(OSC)
    formals = ["always Osc.out.y <= 1", "always Root.out.r >= 0", "always Root.out.r <= 3", "always Osc.out.y <= 0.5"]
    reqs = "".join(f"  - id: T{k}\n    text: t{k}\n    formal: {json.dumps(f)}\n" for k, f in enumerate(formals, 1))
    (ws / "contracts/plan.yaml").write_text(f"contracts: [contracts/osc.rcl]\nrequirements:\n{reqs}")
    w = Workspace(ws)
    stage_check(w)
    got = {rec["id"]: rec for rec, _ in stage_requirements(w)}
    assert [got[f"T{k}"]["verdict"] for k in (1, 2, 3)] == ["proved", "proved", "refuted"]
    assert got["T4"]["verdict"] == "inconclusive"
    assert "sin/cos read as unknown functions" in json.dumps(got["T4"])
