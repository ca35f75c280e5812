"""How the assurance argument and the bundle scale with the amount of evidence.

Builds a synthetic report dict of N nodes (3 guarantees each, 4 obligations
per guarantee with discharged evidence, one side condition per node, one
requirement per node) and prints, per N: the number of GSN elements, the
time to build and propagate the goal structure
(``rclverify.report.argument.build.build_argument``), to render the gsn2x YAML and
the DOT text, and to lay the diagram out with Graphviz ``dot`` (skipped when
it is not installed).  It then writes a workspace of N evidence records of
4 KiB each and times ``rclverify bundle`` and ``--verify`` on it.

Times are CPU seconds of this process (``dot`` is wall-clock, it is another
process); expect +-25% on a shared machine.  Figures are printed, not
asserted.

Usage::

    PYTHONPATH=src python3 bench/argument_scale.py [--sizes 4,16,64]
    PYTHONPATH=src python3 bench/argument_scale.py --smoke    # N = 2, 4: a few seconds
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

from rclverify.report.argument.build import build_argument
from rclverify.report.argument.export import to_dot, to_gsn_yaml
from rclverify.report.bundle.archive import verify_bundle, write_bundle
from rclverify.records.store import SEAL, seal_of
from rclverify.model.plan.load import load_plan
from rclverify.report.diagram import render_dot
from rclverify.records.report_record import AssuranceReport

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "records"))
from _typed_rows import typed_report  # noqa: E402 - the tests' completion of a partial report into a whole one, decoded


def synthetic_report(n: int) -> AssuranceReport:
    nodes, obligations, evidence, sides, reqs = [], [], [], [], []
    for i in range(n):
        name = f"N{i}"
        gs = []
        for k in (1, 2, 3):
            ids = [f"{name}.g{k}.hoare.c{c}" for c in range(4)]
            gs.append({"index": k, "text": f"out.v{k} > {i}", "source": f"s.rcl:{i}:{k}", "status": "discharged",
                       "obligations": ids})
            for oid in ids:
                obligations.append({"id": oid, "node": name, "guarantee": k, "backend": "hoare", "kind": "proof",
                                    "status": "discharged"})
                evidence.append({"obligation": oid, "backend": "hoare", "kind": "proof", "status": "discharged",
                                 "tool": "z3", "tool_version": "4", "explanation": "proved"})
        nodes.append({"name": name, "source": f"s.rcl:{i}:1", "status": "discharged", "guarantees": gs})
        sides.append({"id": f"{name}.sc1", "node": name, "rule": "R1", "conjunct": "in.v1 > 0", "source": "s",
                      "status": "discharged", "smt2": f"artifacts/calculus/{name}.sc1.smt2", "explanation": "proved"})
        reqs.append({"id": f"REQ{i}", "text": "t", "status": "discharged",
                     "support": [{"node": name, "guarantee": 1}, {"node": name, "guarantee": 2}]})
    # every field the synthetic rows leave out given an empty value of its type, as the report's record asks
    return typed_report({"meta": {"tool": "rclverify", "version": "bench", "workspace": "bench",
                                               "plan": "contracts/plan.yaml", "contracts": ["s.rcl"]},
            "requirements": reqs, "nodes": nodes, "side_conditions": sides, "obligations": obligations,
            "evidence": evidence, "findings": [], "environment_assumptions": [],
            "derived_properties": [{"node": "N0", "loop_assumption": None}]})


def cpu(fn: Any) -> tuple[float, Any]:
    t = time.process_time()
    out = fn()
    return time.process_time() - t, out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", default="4,16,64")
    ap.add_argument("--smoke", action="store_true", help="N = 2 and 4 only: a few seconds (CI)")
    args = ap.parse_args()
    sizes = [2, 4] if args.smoke else [int(x) for x in args.sizes.split(",")]
    print(f"{'nodes':>6} {'elements':>9} {'build s':>8} {'yaml s':>7} {'dot-text s':>10} {'dot layout s':>12}")
    for n in sizes:
        rep = synthetic_report(n)
        t_build, arg = cpu(lambda: build_argument(rep))
        t_yaml, _ = cpu(lambda: to_gsn_yaml(arg))
        t_dot, dot = cpu(lambda: to_dot(arg))
        w = time.perf_counter()
        r = render_dot(dot, timeout_s=300)
        layout = f"{time.perf_counter() - w:12.2f}" if r.svg is not None else f"{'-':>12}"
        print(f"{n:>6} {len(arg.elements):>9} {t_build:8.3f} {t_yaml:7.3f} {t_dot:10.3f} {layout}")
    print()
    print(f"{'records':>8} {'MiB':>6} {'bundle s':>9} {'verify s':>9}")
    for n in sizes:
        with tempfile.TemporaryDirectory() as d:
            ws = Path(d)
            (ws / "contracts").mkdir()
            (ws / "contracts" / "plan.yaml").write_text("contracts: [contracts/s.rcl]\n")
            (ws / "contracts" / "s.rcl").write_text("\n")
            (ws / "reports").mkdir()
            (ws / "reports" / "assurance.json").write_text(json.dumps({"summary": {"status": "pending", "headline": ""}}))
            ev = ws / "artifacts" / "evidence"
            ev.mkdir(parents=True)
            for i in range(n * 12):  # sealed as rclverify writes them: the bundle packs only intact records
                rec: dict[str, Any] = {"log": f"{i}" * 4096}
                rec[SEAL] = seal_of(rec)
                (ev / f"o{i}.json").write_text(json.dumps(rec))
            size = sum(p.stat().st_size for p in ws.rglob("*") if p.is_file()) / 2**20
            out = ws.parent / (ws.name + ".tar.gz")
            tools = {"rclverify": "bench"}
            t_b, _ = cpu(lambda: write_bundle(ws, load_plan(ws), out, tools=tools))
            t_v, _ = cpu(lambda: verify_bundle(out))
            out.unlink()
            print(f"{n * 12:>8} {size:6.1f} {t_b:9.3f} {t_v:9.3f}")


if __name__ == "__main__":
    main()
