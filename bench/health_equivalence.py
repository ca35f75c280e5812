"""The health stage's findings, byte for byte, and its CPU seconds, per workspace.

Runs the contract health checks of every node (what ``stage_health`` of
``app/pipeline.py`` runs: a fresh Z3 world, ``check_node`` with the plan's
facts and instances, the replacement's refinement finding) on the bundled
case study, each workspace of ``examples/`` and a synthetic system written
by ``bench/pipeline_scale.py`` (``--synthetic N``, default 1000 nodes), and
records each finding as the stage seals it (its JSON without
``duration_s``, the solver's wall time, plus the text of its SMT-LIB2
scripts) with the CPU seconds of each node.  Each tree runs in a process
of its own::

    python3 bench/health_equivalence.py --dump OUT.json           # this tree's findings and CPU
    python3 bench/health_equivalence.py --compare OLD_SRC         # OLD_SRC's and this tree's, diffed
    python3 bench/health_equivalence.py --compare OLD_SRC --repeat 3   # alternately, the least CPU of each
    python3 bench/health_equivalence.py --against SAVED.json      # this tree's against a saved dump
    python3 bench/health_equivalence.py --smoke                   # one example and 3 nodes, both in this tree

``--compare`` and ``--against`` print the CPU seconds of the health stage
per workspace (the case study's Agent on its own line) before and after,
and every finding that differs; the exit status is 1 when one does.  A
check the wall-clock safety net cut (a loaded machine:
``semantics/wallclock.py``) is counted and reported, since its finding is
``inconclusive`` by the load, not by the code.  CPU seconds are
``time.process_time`` of this process (Z3 runs in it).
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Sequence

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(Path(__file__).resolve().parent))

#: The workspaces of the repository (the case study is the root).
WORKSPACES = ["."] + sorted(p.parent.parent.relative_to(REPO).as_posix()
                            for p in (REPO / "examples").glob("*/contracts/plan.yaml"))


def node_findings(ws: Any, node: str) -> list[dict[str, Any]]:
    """``node``'s findings as ``stage_health`` records them, ``duration_s``
    left out and the scripts' text in their place."""
    from rclverify.app.pipeline import health_findings
    out = []
    for f in health_findings(ws, node):
        j = f.to_json()
        j.pop("duration_s")
        j["smt2"], j["witness_smt2"] = f.smt2, f.witness_smt2
        out.append(j)
    return out


def dump_workspace(root: Path) -> dict[str, Any]:
    """``{"nodes": {node: {"cpu_s", "findings"}}, "cuts"}`` of the workspace at ``root``."""
    from rclverify.semantics import wallclock
    from rclverify.stages.workspace import Workspace
    ws = Workspace(root)
    nodes: dict[str, Any] = {}
    cuts = wallclock.cuts()
    for n in ws.checked.nodes:
        t0 = time.process_time()
        found = node_findings(ws, n)
        nodes[n] = {"cpu_s": round(time.process_time() - t0, 3), "findings": found}
    return {"nodes": nodes, "cuts": wallclock.cuts() - cuts}


def dump(workspaces: Sequence[str], synthetic: int) -> dict[str, Any]:
    """Every workspace's :func:`dump_workspace`, the synthetic system's under ``synthetic-N``."""
    out = {w: dump_workspace(REPO / w) for w in workspaces}
    if synthetic:
        from pipeline_scale import generate
        with tempfile.TemporaryDirectory() as tmp:
            root = Path(tmp) / "ws"
            generate(root, synthetic, property_tests=False)
            out[f"synthetic-{synthetic}"] = dump_workspace(root)
    return out


def run_dump(src: str, out: Path, workspaces: Sequence[str], synthetic: int) -> dict[str, Any]:
    """:func:`dump` with the package of ``src`` in a process of its own; returns what it wrote."""
    env = {**os.environ, "PYTHONPATH": src}
    cmd = [sys.executable, str(Path(__file__).resolve()), "--dump", str(out), "--synthetic", str(synthetic),
           "--workspaces", *workspaces]
    subprocess.run(cmd, env=env, check=True, cwd=REPO)
    got: dict[str, Any] = json.loads(out.read_text())
    return got


#: The names Z3's printer gives shared subterms (``$x15330``, ``?x63``): they follow the term ids of the Z3
#: context, that is everything the process asked Z3 before (docs/architecture.md), not the query.
LET_NAME = re.compile(r"[$?]x[0-9]+")


def let_normal(text: str) -> str:
    """``text`` (an SMT-LIB2 script) with each ``let`` name renamed by the order it first occurs in:
    two scripts equal under this are the same query, written with other names for its shared subterms."""
    names: dict[str, str] = {}
    return LET_NAME.sub(lambda m: names.setdefault(m.group(0), f"{m.group(0)[0]}x{len(names) + 1}"), text)


def renamed(old: dict[str, Any], new: dict[str, Any]) -> list[str]:
    """The SMT-LIB2 scripts (``workspace node finding``) that differ only in their ``let`` names."""
    out = []
    for w in sorted(set(old) & set(new)):
        for n, rec in new[w]["nodes"].items():
            for x, y in zip(old[w]["nodes"].get(n, {"findings": []})["findings"], rec["findings"]):
                out += [f"{w} {n} {y['id']} {k}" for k in ("smt2", "witness_smt2")
                        if x.get(k) != y.get(k) and let_normal(x.get(k) or "") == let_normal(y.get(k) or "")]
    return out


def differences(old: dict[str, Any], new: dict[str, Any]) -> list[str]:
    """Each finding (or node, or workspace) that is not the same in ``old`` and ``new``, one line each
    (SMT-LIB2 scripts compared up to their ``let`` names: :func:`renamed` lists those)."""
    diffs = []
    for w in new:  # a saved dump may hold more workspaces than this run asked for
        a, b = old.get(w, {}).get("nodes", {}), new[w]["nodes"]
        if list(a) != list(b):
            diffs.append(f"{w}: nodes differ: {len(a)} nodes {list(a)[:5]}... vs {len(b)} nodes {list(b)[:5]}...")
            continue
        for n in a:
            fa, fb = a[n]["findings"], b[n]["findings"]
            if [f["id"] for f in fa] != [f["id"] for f in fb]:
                diffs.append(f"{w} {n}: findings {[f['id'] for f in fa]} vs {[f['id'] for f in fb]}")
                continue
            for x, y in zip(fa, fb):
                keys = [k for k in sorted(set(x) | set(y)) if x.get(k) != y.get(k) and not (
                    k in ("smt2", "witness_smt2") and let_normal(x.get(k) or "") == let_normal(y.get(k) or ""))]
                if keys:
                    diffs.append(f"{w} {n} {x['id']}: " + "; ".join(
                        f"{k}: {str(x.get(k))[:300]!r} vs {str(y.get(k))[:300]!r}" for k in keys))
    return diffs


def cpu(dump: dict[str, Any], w: str, node: str | None = None) -> float:
    """CPU seconds of workspace ``w``'s health stage in ``dump`` (of ``node`` alone when given)."""
    nodes = dump.get(w, {"nodes": {}})["nodes"]
    return float(sum(x["cpu_s"] for n, x in nodes.items() if node is None or n == node))


def _each(xs: Sequence[float]) -> str:
    """Every run's figure in brackets, when there were several."""
    return f" ({', '.join(f'{x:.2f}' for x in xs)})" if len(xs) > 1 else ""


def cpu_table(olds: Sequence[dict[str, Any]], news: Sequence[dict[str, Any]]) -> str:
    """The health stage's CPU seconds per workspace (and the case study's Agent), old and new: the least
    of the runs (each tree ran as often, alternately), and every run's in brackets."""
    rows = ["| workspace | nodes | old CPU s | new CPU s | new/old | cuts (old, new) |", "| --- | ---: | ---: | ---: | ---: | --- |"]

    def row(name: str, count: int, w: str, node: str | None, cuts: str) -> None:
        a, b = [cpu(d, w, node) for d in olds], [cpu(d, w, node) for d in news]
        rows.append(f"| {name} | {count} | {min(a):.2f}{_each(a)} | {min(b):.2f}{_each(b)} | "
                    f"{min(b) / min(a) if min(a) else 0:.2f} | {cuts} |")
    for w in news[0]:
        cuts = f"{sum(d.get(w, {}).get('cuts', 0) for d in olds)}, {sum(d[w]['cuts'] for d in news)}"
        row(w, len(news[0][w]["nodes"]), w, None, cuts)
        if w == "." and "Agent" in news[0][w]["nodes"]:
            row(". (Agent)", 1, w, "Agent", "")
    return "\n".join(rows)


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dump", help="write this tree's findings and CPU seconds to this JSON file")
    ap.add_argument("--compare", metavar="OLD_SRC", help="an older tree's src/ to run and diff against")
    ap.add_argument("--against", metavar="SAVED", help="a saved --dump to diff this tree against")
    ap.add_argument("--synthetic", type=int, default=1000, help="nodes of the synthetic system (0: none)")
    ap.add_argument("--workspaces", nargs="*", default=WORKSPACES)
    ap.add_argument("--repeat", type=int, default=1, help="run each tree this many times, alternately")
    ap.add_argument("--smoke", action="store_true", help="one small example and a 3-node system, twice in this tree")
    args = ap.parse_args(argv)
    if args.smoke:
        args.workspaces, args.synthetic = ["examples/contracts_first"], 3
    if args.dump:
        Path(args.dump).write_text(json.dumps(dump(args.workspaces, args.synthetic), indent=1))
        return 0
    this = str(REPO / "src")
    olds: list[dict[str, Any]] = []
    news: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(max(1, args.repeat)):
            if args.against:
                olds.append(json.loads(Path(args.against).read_text()))
            else:
                olds.append(run_dump(args.compare or this, Path(tmp) / f"old{k}.json", args.workspaces, args.synthetic))
            news.append(run_dump(this, Path(tmp) / f"new{k}.json", args.workspaces, args.synthetic))
    print(f"health stage, CPU seconds (load {os.getloadavg()[0]:.1f} at the end)")
    print(cpu_table(olds, news))
    old, new = olds[0], news[0]
    diffs = [d for o, n in zip(olds, news) for d in differences(o, n)] + [
        f"run {k + 1} of this tree: {d}" for k, n in enumerate(news[1:]) for d in differences(new, n)]
    count = sum(len(n["findings"]) for w in new.values() for n in w["nodes"].values())
    names = renamed(old, new)
    print(f"{count} findings compared, {len(diffs)} differ; {len(names)} SMT-LIB2 scripts differ in let names only")
    for d in diffs:
        print("  " + d)
    for d in names:
        print("  let names only: " + d)
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main())
