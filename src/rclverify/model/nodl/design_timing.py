"""A design's monitoring fields decided against the contracts' deadlines along each chain (docs/nodl.md,
"Autoware System Designer", "Timeouts and rates along a chain").

The designer's monitor watches each trigger of a process: ``timeout: T`` says the trigger comes at
least every ``T`` seconds, ``error_rate: r`` (``warn_rate``) that it comes at ``r`` Hz or more, so no
gap longer than ``1/r`` (the monitor's error, or warning).  The contracts bound the gaps a chain can
leave: an output with ``periodic( out.y, P )`` is refreshed at least every ``P``; an output a guarantee
answers within ``d`` of input ``x`` is at most ``d`` later than the ``x`` it answers, so two answers
are at most ``gap(x) + d`` apart (one answered at once, the next at its deadline); an input's gap is
the smallest of its producers' (the plan's connections, the system model's links); an input with no
producer (from outside), an untimed guarantee or a loop bounds nothing.  :func:`check_timing`
computes the bound of each ``on_input`` (and ``periodic``) trigger that carries a monitoring field,
reading the deadlines and periods from the contracts (so a workspace edited after its import is
checked as it now stands), and decides each field with exact rationals:

* bound <= the field's limit: ``proved`` (printed, no finding);
* bound > limit: ``design-timeout`` / ``design-error-rate`` errors, ``design-warn-rate`` a warning,
  located at the design's field and at each contract clause of the chain (the ``periodic`` and the
  ``within`` that add up to the bound);
* no bound: ``design-undecided``, a warning at the field saying where the chain breaks;
* the design's node or port has no contract node or input: ``design-missing``, an error at the design;
* an input the design wires to nothing and the system model feeds by an equal name (its rule for inputs
  the plan's connections leave out, docs/plan.md): ``design-unwired``, a warning at the design's port and
  the contract's input.
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Sequence

from rclverify.lang import ast
from rclverify.lang.timing import parse_duration, seconds
from rclverify.lang.types import Checked
from rclverify.lang.walk import subexpressions
from rclverify.model.nodl.design import Design
from rclverify.model.nodl.design_write import duration, var_of
from rclverify.model.nodl.findings import Finding
from rclverify.model.system.model import Link

#: The monitoring fields decided, each with its finding code and severity.
FIELDS = {"timeout": ("design-timeout", "error"), "error_rate": ("design-error-rate", "error"),
          "warn_rate": ("design-warn-rate", "warning")}


@dataclass(frozen=True)
class Bound:
    """The longest gap ``seconds`` a chain can leave, and the contract clauses it adds up (``steps``:
    text and location, first to last)."""

    seconds: Fraction
    steps: tuple[tuple[str, ast.Loc], ...]


@dataclass(frozen=True)
class Decided:
    """A monitoring field decided: the node, the trigger (``in.x`` or ``periodic``), the field, its limit
    in seconds, the bound (``None``: undecided, ``why`` says why), the verdict and where the field is written
    in the design (``loc``)."""

    node: str
    trigger: str
    field: str
    limit: Fraction
    bound: Bound | None
    status: str
    why: str = ""
    loc: ast.Loc | None = None


class _Gaps:
    """The gap bounds of a workspace's outputs and inputs (module docstring), memoised, loops cut."""

    def __init__(self, checked: Checked, links: Sequence[Link]) -> None:
        self.checked = checked
        self.producers: dict[tuple[str, str], list[tuple[str, str]]] = {}
        for lk in links:
            self.producers.setdefault((lk.to_node, lk.to_var), []).append((lk.from_node, lk.from_var))
        self.why: dict[tuple[str, str, str], str] = {}

    def out(self, node: str, var: str, seen: frozenset[tuple[str, str]]) -> Bound | None:
        cn = self.checked.nodes[node].node
        best: Bound | None = None
        for p in cn.periodic:
            period = parse_duration(f"{p.amount} {p.unit}") if p.unit != "steps" else None
            if p.output.name == var and period is not None:
                best = _min(best, Bound(period, ((f"{node}: periodic( out.{var}, {p.amount} {p.unit} )", p.loc),)))
        for i, cl in enumerate(cn.guarantees, 1):
            outs = {e.name for e in subexpressions(cl.formula) if isinstance(e, ast.Var) and e.prefix == "out"}
            if var not in outs or cl.trigger is None:
                continue
            d = seconds(cl.deadline) if cl.deadline is not None else None
            if d is None:
                self.why[("out", node, var)] = f"{node} guarantee {i} answers in.{cl.trigger.name} with no deadline"
                continue
            up = self.inp(node, cl.trigger.name, seen)
            if up is not None:
                step = (f"{node} guarantee {i}: within {cl.deadline.amount} {cl.deadline.unit}"  # type: ignore[union-attr]
                        f" of in.{cl.trigger.name}", cl.loc)
                best = _min(best, Bound(up.seconds + d, up.steps + (step,)))
        if best is None and ("out", node, var) not in self.why:
            self.why[("out", node, var)] = f"no periodic or timed guarantee of {node} bounds out.{var}"
        return best

    def inp(self, node: str, var: str, seen: frozenset[tuple[str, str]] = frozenset()) -> Bound | None:
        if (node, var) in seen:
            self.why[("in", node, var)] = f"{node}.in.{var} is on a loop"
            return None
        best: Bound | None = None
        for m, y in self.producers.get((node, var), []):
            best = _min(best, self.out(m, y, seen | {(node, var)}))
        if not self.producers.get((node, var)):
            self.why[("in", node, var)] = f"{node}.in.{var} has no producer (an input from outside)"
        elif best is None:
            self.why[("in", node, var)] = "; ".join(self.why.get(("out", m, y), f"{m}.out.{y} is unbounded")
                                                    for m, y in self.producers[(node, var)])
        return best


def _min(a: Bound | None, b: Bound | None) -> Bound | None:
    if a is None or (b is not None and b.seconds < a.seconds):
        return b
    return a


def _unwired(design: Design, checked: Checked, links: Sequence[Link]) -> list[Finding]:
    """A link the system model found (by equal names or topics) that the design does not wire: a warning at the
    design's port and the contract's input (the model's rule, docs/plan.md ``connections``, is not ROS's)."""
    wired = {(w.reader, var_of(w.reader_port)) for w in design.wires if w.role == "publisher"}
    out = []
    for lk in links:
        node = design.nodes.get(lk.to_node)
        cn = checked.nodes.get(lk.to_node)
        if node is None or cn is None or lk.via == "plan" or (lk.to_node, lk.to_var) in wired:
            continue
        port = next((p for p in node.ports if p.role == "subscriber" and var_of(p.name) == lk.to_var), None)
        iv = next((v for v in cn.node.inputs if v.name == lk.to_var), None)
        locs = tuple(x.loc for x in (port, iv) if x is not None)
        findings_msg = (f"{lk.to_node}.in.{lk.to_var} is wired to nothing in the design, and the system model feeds "
                        f"it from {lk.from_node}.out.{lk.from_var} by equal {lk.via}s; wire it in the design or "
                        "name its producer under the plan's connections")
        out.append(Finding("design-unwired", findings_msg, locs, "warning"))
    return out


def check_timing(design: Design, checked: Checked, links: Sequence[Link]) -> tuple[list[Finding], list[Decided]]:
    """Each monitoring field of ``design``'s ``on_input`` and ``periodic`` triggers decided against the deadlines
    of ``checked`` along ``links`` (module docstring): the findings and every decision, in design order."""
    gaps = _Gaps(checked, links)
    findings: list[Finding] = _unwired(design, checked, links)
    decided: list[Decided] = []
    for node in design.nodes.values():
        cn = checked.nodes.get(node.name)
        for proc in node.processes:
            for t in proc.triggers:
                if not t.fields or t.kind not in ("on_input", "periodic"):
                    continue
                if cn is None or (t.kind == "on_input" and var_of(t.value) not in cn.inputs):
                    what = f"node {node.name}" if cn is None else f"input {var_of(t.value)} of node {node.name}"
                    findings.append(Finding("design-missing", f"the design's {what} has no contract", (t.loc,)))
                    continue
                if t.kind == "on_input":
                    trigger = f"in.{var_of(t.value)}"
                    bound = gaps.inp(node.name, var_of(t.value))
                    why = gaps.why.get(("in", node.name, var_of(t.value)), "")
                else:
                    trigger = f"periodic {t.value} Hz"
                    outs = [o for k, o, _ in proc.outcomes if k == "to_output"]
                    bound = None
                    for o in outs:
                        bound = _min(bound, gaps.out(node.name, var_of(o), frozenset()))
                    why = f"no periodic declaration of {node.name} for the outputs of process {proc.name}"
                for name, value, loc in t.fields:
                    limit = Fraction(str(value)) if name == "timeout" else 1 / Fraction(str(value))
                    code, severity = FIELDS[name]
                    shown = f"{name} {value:g} {'s' if name == 'timeout' else 'Hz'}"
                    where = f"{node.name} process {proc.name}'s {trigger}"
                    if bound is None:
                        decided.append(Decided(node.name, trigger, name, limit, None, "undecided", why, loc))
                        findings.append(Finding("design-undecided", f"{where}: {shown} is not decided: {why}",
                                                (loc,), "warning"))
                    elif bound.seconds <= limit:
                        decided.append(Decided(node.name, trigger, name, limit, bound, "proved", "", loc))
                    else:
                        decided.append(Decided(node.name, trigger, name, limit, bound, "refuted", "", loc))
                        chain = " -> ".join(s for s, _ in bound.steps)
                        findings.append(Finding(code, f"{where}: {shown} cannot be met: the contracts let it wait "
                                                f"{duration(bound.seconds)} > {duration(limit)} ({chain})",
                                                (loc,) + tuple(lc for _, lc in bound.steps), severity))
    return findings, decided


__all__ = ["Bound", "Decided", "FIELDS", "check_timing"]
