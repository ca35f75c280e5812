"""A temporal requirement's verdict in words (SARIF message, terminal).

The record's ``temporal`` field (:mod:`rclverify.calculus.requirements.temporal_check`)
as one sentence per part: how it was decided (method, k, steps checked) and,
for a refuted one, its trace step by step and node by node.
"""
from __future__ import annotations

from typing import Any, Mapping


def temporal_words(t: Mapping[str, Any]) -> str:
    """``t`` (``{status, method, k, bound, loop, detail, trace}``) as text:
    ``"Temporal check: refuted by bmc, 7 steps checked. Trace: step 0: Inc
    (state.n = 0), Fwd (...); step 1: ..."``."""
    head = f"Temporal check: {t.get('status')} by {t.get('method')}"
    if t.get("k"):
        head += f", k = {t['k']}"
    if t.get("bound") is not None:
        head += f", {t['bound']} step{'s' if t['bound'] != 1 else ''} checked"
    if t.get("detail"):
        head += f" ({t['detail']})"
    words = [head + "."]
    if t.get("trace"):
        steps = []
        for st in t.get("shown") or t["trace"]:  # cut to what matters (report/cex_cone.py)
            rows = ", ".join(f"{row['node']} (" + ", ".join(f"{k} = {v}" for k, v in row["values"].items()) + ")"
                             for row in st["nodes"])
            steps.append(f"step {st['step']}: {rows}")
        words.append("Trace: " + "; ".join(steps) + ".")
        if t.get("loop") is not None:
            words.append(f"The last step returns to step {t['loop']}: the run repeats forever.")
    return " ".join(words)
