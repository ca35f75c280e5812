"""Recall by category and precision per tree of ``rclverify ros scan`` on the
issue 65 corpus: published ROS 2 trees counted by hand before their first
scan (``bench/data/ros_heldout4_*.json``), a *train* split looked at while
developing and a *held-out* split that was not.

A truth file is ``ros_heldout.py``'s (repository, branch, commit, ``scan``)
plus ``split`` (``train``, ``heldout``, ``heldout-b``: a second held-out split counted and
measured after the development had ended; ``heldout-c``: a third, counted before round four's
second pass and measured once at its end), ``own`` (the directories whose nodes
are judged) and ``library`` (names of endpoints the client library or a
framework base class makes on every node, such as the lifecycle management
services: neither counted as sites nor judged; a leading ``*`` matches any
node prefix).  A site row is ``[file, line, node, role, resolved name, type,
kind, reach]``: ``kind`` as in ``ros_heldout.py``; ``reach`` ``static`` (the
name and type are written in the node's own code at the call), ``call``
(they reach rclcpp/rclpy across a call: a helper's or base class's
constructor, a free function, a member set in another method) or
``runtime`` (name null: only the running program knows it).

A site is *found* as in ``ros_heldout.py``, or by an edge whose ``via`` is the
site (a helper called at several sites makes it: the edge is at the helper's
creating call and names the call at the site, docs/grounding.md).  Precision:
of the edges of every graph node holding a file under ``own`` (library names
set aside), those a site of the same file (or ``via`` the site), role, name and
type confirms; printed as counted and, where
``ros_heldout4_rejudged.json`` names unconfirmed edges judged real after measuring (the
hand count missed them), also re-judged, labelled so.  Printed per tree and per
split: recall over all sites and per reach, precision, sites missed with and
without a located note (run-time rows apart, with the recall of the other
rows; ``--verbose`` prints each miss's reach and the note at it), and the
scan's wall time.  Aims (issue 65): recall
>= 0.90, static >= 0.98, precision >= 0.98, every miss noted, a 15k-line tree
scanned in < 2 s.  Figures are printed, not asserted.

Usage::

    PYTHONPATH=src python3 bench/ros_heldout4.py --root DIR|--smoke [--split train|heldout|heldout-b|heldout-c] [--verbose]

where ``DIR/NAME`` holds ``git archive COMMIT SCAN... | tar -x`` of the
truth file ``ros_heldout4_NAME.json`` (no upstream code is kept here).
"""
from __future__ import annotations

if __name__ == "__main__":  # run as a script: a Python without the dependencies runs again under .venv/
    import _venv  # noqa: F401

import argparse
import json
import time
from fnmatch import fnmatch
from pathlib import Path
from typing import Any

from rclverify.ros.graph.scan import scan
from rclverify.ros.extract.model import SERVICE_ROLES

ROLES = ("pub", "sub") + tuple(SERVICE_ROLES)
REACH = ("static", "call", "runtime")
DATA = Path(__file__).resolve().parent / "data"
REJUDGED = "ros_heldout4_rejudged.json"  # edges the hand count missed, judged after measuring (not truth)


def load_truth(path: Path) -> dict[str, Any]:
    """The truth file at ``path``, checked: ``ValueError`` naming the row when malformed."""
    truth: dict[str, Any] = json.loads(path.read_text(encoding="utf-8"))
    for key in ("repository", "commit", "scan", "split", "own", "sites"):
        if key not in truth:
            raise ValueError(f"{path.name}: no {key!r}")
    for i, row in enumerate(truth["sites"]):
        if len(row) != 8 or row[3] not in ROLES or row[7] not in REACH or (row[4] is None) != (row[7] == "runtime"):
            raise ValueError(f"{path.name}: site {i} malformed: {row}")
    return truth


def _library(name: str, pats: list[str]) -> bool:
    return any(fnmatch(name, p) for p in pats)


def measure(root: Path, truth: dict[str, Any], verbose: bool = False,
            rejudged: list[list[str]] | None = None) -> dict[str, float]:
    """Counts for the extracted tree ``root``: ``sites``, ``found``, per reach
    ``R``/``found_R``, ``edges``/``right`` (precision), ``rejudged`` (edges not
    confirmed that a row of ``rejudged`` with verdict ``real`` names: this
    tree's rows of ``ros_heldout4_rejudged.json``), ``missed``/``noted``,
    ``seconds`` (the scan's wall time) and ``lines`` (C++/Python lines scanned)."""
    t0 = time.perf_counter()
    g = scan([root / d for d in truth["scan"]], [], base=root).graph
    return judge(g, root, truth, time.perf_counter() - t0, verbose, rejudged)


def _via(e: Any, f: str, line: int) -> bool:
    """Whether edge ``e`` is made by a helper called at ``f:line`` (its ``via``: the call of the
    helper whose argument gives the name, docs/grounding.md)."""
    return e.via is not None and e.via.file == f and e.via.line == line


def judge(g: Any, root: Path, truth: dict[str, Any], seconds: float, verbose: bool = False,
          rejudged: list[list[str]] | None = None) -> dict[str, float]:
    """:func:`measure`'s counts for graph ``g``, a scan of ``root`` that took ``seconds``."""
    rejudged = rejudged or []
    own = tuple("" if d in (".", "") else d.rstrip("/") + "/" for d in truth["own"])
    lib = list(truth.get("library", []))
    nodes = [n for n in g.nodes.values() if any(s.startswith(own) for s in n.sources)]
    edges = [(n, r, e) for n in nodes for r in ROLES for e in n.edges_of(r) if not _library(e.topic, lib)]
    c: dict[str, float] = dict.fromkeys(("sites", "found", "edges", "right", "missed", "noted"), 0)
    for k in REACH:
        c[k] = c["found_" + k] = 0
    for site in truth["sites"]:
        f, line, node, role, name, typ, _kind, reach = site
        found = [e for n, r, e in edges if (f in n.sources or e.src.file == f or _via(e, f, line))
                 and (node is None or n.name.split("@")[0] == node)
                 and r == role and e.topic == name and e.msg_type == typ] if name is not None else []
        c["sites"] += 1
        c[reach] += 1
        c["found"] += bool(found)
        c["found_" + reach] += bool(found)
        if not found:
            c["missed"] += 1
            near = [nt for nt in g.notes if nt.src.file == f and line - 3 <= nt.src.line <= line + 3]
            c["noted"] += bool(near)
            c["noted_" + reach] = c.get("noted_" + reach, 0) + bool(near)
            if verbose:
                print(f"    missed{'' if near else ' (no note)'} ({reach} row): {site}")
                for nt in near:  # the note at the row, so that a reader finds why it is missed
                    print(f"      note {nt.src.file}:{nt.src.line}: {nt.message}")
    c["rejudged"] = 0
    for n, r, e in edges:
        ok = any(s[3] == r and s[4] == e.topic and s[5] == e.msg_type and (s[0] == e.src.file or s[0] in n.sources
                                                                                        or _via(e, s[0], s[1]))
                 for s in truth["sites"])
        c["edges"] += 1
        c["right"] += ok
        real = not ok and any(j[1] == n.name.split("@")[0] and j[2] == r and j[3] == e.topic and j[4] == e.msg_type
                              and j[5] == e.src.file and j[6] == "real" for j in rejudged)
        c["rejudged"] += real
        if verbose and not ok:
            print(f"    wrong edge{' (re-judged real)' if real else ''}: {n.name} {r} {e.topic} {e.msg_type} at "
                  f"{e.src.file}:{e.src.line}")
    c["seconds"] = seconds
    c["lines"] = sum(len(p.read_bytes().splitlines()) for d in truth["scan"] for p in (root / d).rglob("*")
                     if p.suffix in (".cpp", ".hpp", ".h", ".cc", ".py") and p.is_file())
    return c


def _ratio(m: float, e: float) -> str:
    return f"{int(m)}/{int(e)} = {m / e:.2f}" if e else "-"


def report(label: str, c: dict[str, float]) -> str:
    """One line of figures for ``label`` from ``measure``'s counts."""
    per = "  ".join(f"{k} {_ratio(c['found_' + k], c[k])}" for k in REACH)
    again = f" (re-judged {_ratio(c['right'] + c['rejudged'], c['edges'])})" if c.get("rejudged") else ""
    rt_missed = c["runtime"] - c["found_runtime"]
    runtime = (f"  missed run-time rows {int(rt_missed)} (noted {int(c.get('noted_runtime', 0))}), other rows "
               f"{_ratio(c['found'] - c['found_runtime'], c['sites'] - c['runtime'])}") if rt_missed else ""
    return (f"{label:<18} recall {_ratio(c['found'], c['sites']):<14} {per}  precision {_ratio(c['right'], c['edges'])}"
            f"{again}  missed {int(c['missed'])} (noted {int(c['noted'])}){runtime}  scan {c['seconds']:.2f} s / "
            f"{int(c['lines'])} lines")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--root", type=Path, help="directory holding one extracted tree per truth file (required "
                                              "unless --smoke)")
    ap.add_argument("--smoke", action="store_true", help="check the truth files; measure only trees present (CI)")
    ap.add_argument("--verbose", action="store_true", help="list every site missed and every wrong edge")
    ap.add_argument("--split", choices=("train", "heldout", "heldout-b", "heldout-c"), help="measure only this split")
    a = ap.parse_args()
    if a.root is None and not a.smoke:
        ap.error("the following arguments are required: --root")
    totals: dict[str, dict[str, float]] = {}
    rejudged = json.loads((DATA / REJUDGED).read_text(encoding="utf-8"))["edges"]
    for path in sorted(DATA.glob("ros_heldout4_*.json")):
        if path.name == REJUDGED:
            continue
        truth = load_truth(path)
        name = path.stem[len("ros_heldout4_"):]
        if a.split and truth["split"] != a.split:
            continue
        print(f"[{truth['split']}] {truth['repository']} @ {truth['commit'][:12]}: {len(truth['sites'])} sites")
        tree = a.root / name if a.root else None
        if tree is None or not tree.is_dir():
            print(f"  skipped: no extraction of it at {tree or '--root'} (git archive {truth['commit'][:12]} {' '.join(truth['scan'])} | tar -x)")
            continue
        c = measure(tree, truth, a.verbose, [j for j in rejudged if j[0] == name])
        print("  " + report(name, c))
        tot = totals.setdefault(truth["split"], {})
        for k, v in c.items():
            tot[k] = tot.get(k, 0) + v
    for split, tot in totals.items():
        print(report(f"total {split}", tot))


if __name__ == "__main__":
    main()
