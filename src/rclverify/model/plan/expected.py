"""Check-time validation of the plan's ``expected`` verdicts.

An evidence entry may state the verdicts it expects (see
:mod:`rclverify.report.expected` for their meaning)::

    expected:
      - {guarantee: 3, instance: "i=12", verdict: failed, reason: "..."}

Called by :func:`rclverify.model.plan.load.resolve`, so ``rclverify check`` and
``doit check`` reject a malformed entry, an unknown verdict or a guarantee
number the node does not have at once, located in the plan
(``contracts/plan.yaml:line:col: error: ...``), instead of the report showing
an "invalid expectation" row after the whole run.
"""
from __future__ import annotations

from typing import Any, Mapping

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, error
from rclverify.lang.types import Checked
from rclverify.model.plan.declarations import DECLARATIONS
from rclverify.model.plan.model import Plan
from rclverify.model.plan.yamlguard import KEY

#: The verdicts an expectation may state (an obligation's decided statuses).
VERDICTS = ("discharged", "failed")
#: The keys an expectation may have; ``guarantee`` and ``verdict`` are required.
KEYS = ("guarantee", "instance", "verdict", "reason")


#: Backends whose obligations cover a node's whole contract (guarantee 0 in
#: the obligation id, ``<Node>.g0.dafny.contract``): their expectations say
#: ``guarantee: 0``.
WHOLE_CONTRACT_BACKENDS = tuple(n for n, d in DECLARATIONS.items() if d.whole_contract)


def _item_problems(item: Any, n_guarantees: int, node: str,
                   backend: str = "") -> list[tuple[tuple[Any, ...], bool, str]]:
    """``(path below the item, at the key?, message)`` for each problem of one expectation."""
    if not isinstance(item, Mapping):
        return [((), False, "an expectation must be a mapping {guarantee: N, verdict: discharged|failed, "
                            "instance?: LABEL, reason?: TEXT}")]
    out: list[tuple[tuple[Any, ...], bool, str]] = []
    for k in item:
        if k not in KEYS:
            out.append(((k,), True, f"unknown key {k!r} in an expectation; allowed keys: {', '.join(KEYS)}"))
    g = item.get("guarantee")
    if "guarantee" not in item:
        out.append(((), False, "an expectation needs 'guarantee' (the guarantee's number, from 1)"))
    elif isinstance(g, bool) or not isinstance(g, int):
        out.append((("guarantee",), False, f"'guarantee' must be a guarantee number, found {g!r}"))
    elif backend in WHOLE_CONTRACT_BACKENDS and g != 0:
        out.append((("guarantee",), False, f"{backend} obligations cover the whole contract of {node}, not one "
                                           "guarantee: write 'guarantee: 0'"))
    elif backend not in WHOLE_CONTRACT_BACKENDS and not 1 <= g <= n_guarantees:
        out.append((("guarantee",), False, f"node {node} has {n_guarantees} guarantee(s); there is no guarantee {g}"))
    v = item.get("verdict")
    if "verdict" not in item:
        out.append(((), False, f"an expectation needs 'verdict' ({' or '.join(VERDICTS)})"))
    elif v not in VERDICTS:
        out.append((("verdict",), False, f"unknown verdict {v!r}; an expected verdict is {' or '.join(VERDICTS)}"))
    for key in ("instance", "reason"):
        if key in item and not isinstance(item[key], str):
            out.append(((key,), False, f"'{key}' must be text, found {item[key]!r}"))
    return out


def check_expected(plan: Plan, checked: Checked) -> list[Diagnostic]:
    """Diagnostics (code ``E-plan-expected``) for every malformed ``expected``
    of ``plan``'s evidence entries; nodes missing from ``checked`` are left
    to :func:`~rclverify.model.plan.load.resolve`'s own message.  Returns ``[]``
    when every expectation is well formed."""
    diags: list[Diagnostic] = []
    for node, entries in plan.evidence.items():
        if node not in checked.nodes:
            continue
        n = len(checked.nodes[node].node.guarantees)
        for e in entries:
            if "expected" not in e.config:
                continue
            base = ("nodes", node, "evidence", e.index, "expected")

            def loc(path: tuple[Any, ...], key: bool, _base: tuple[Any, ...] = base, _e: Any = e) -> ast.Loc:
                full = _base + path
                if key and full + (KEY,) in plan.locs:
                    return plan.locs[full + (KEY,)]
                while full and full not in plan.locs:
                    full = full[:-1]
                return plan.locs.get(full, _e.loc)
            exp = e.config["expected"]
            if isinstance(exp, Mapping):
                items: list[tuple[tuple[Any, ...], Any]] = [((), exp)]
            elif isinstance(exp, list):
                items = [((k,), it) for k, it in enumerate(exp)]
            else:
                diags.append(error(loc((), False), "'expected' must be a list of expectations "
                                                   "{guarantee: N, verdict: discharged|failed}", "E-plan-expected"))
                continue
            for prefix, item in items:
                for path, key, msg in _item_problems(item, n, node, e.backend):
                    diags.append(error(loc(prefix + path, key), f"{e.backend} evidence of {node}: {msg}",
                                       "E-plan-expected"))
    return diags


__all__ = ["KEYS", "VERDICTS", "WHOLE_CONTRACT_BACKENDS", "check_expected"]
