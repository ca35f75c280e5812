"""Rules D1-D3: deadlines chained along a path, decided by Z3
(docs/decisions.md, "Services, actions and deadlines").

A *hop* is one timed guarantee ``G(phi) triggered by in.x within d`` of a
node (D1).  Along a requirement's path ``[A, B, C]`` a *chain* is one hop per
node such that each hop's trigger is fed, in the system model, by an output
its predecessor's formula mentions (D2's side condition (a)).  The chain's
bound is the sum of its deadlines (D2); :func:`decide` asks Z3 whether the
last output can come later than the requirement's ``within`` after the first
trigger (D3): unsat is *proved*, sat *refuted* with the stamps of a late run,
no chain *inconclusive* with the hop where the path breaks.

All times are exact rationals in seconds (:class:`fractions.Fraction`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Mapping, Sequence

import z3

from rclverify.lang import ast
from rclverify.lang.timing import seconds
from rclverify.lang.types import Checked
from rclverify.lang.walk import subexpressions
from rclverify.model.system.model import SystemModel
from rclverify.model.system.services import unserved_parts
from rclverify.records.stage_records import DeadlineCheck

#: Verdicts of an end-to-end deadline, as the requirements' statuses.
PROVED, REFUTED, INCONCLUSIVE = "proved", "refuted", "inconclusive"


@dataclass(frozen=True)
class Hop:
    """Guarantee ``index`` (1-based) of ``node``: ``outputs`` follow an event
    on ``in.trigger`` within ``bound`` seconds."""

    node: str
    index: int
    trigger: str
    outputs: tuple[str, ...]
    bound: Fraction
    loc: ast.Loc

    def label(self) -> str:
        return f"{self.node} guarantee {self.index} (in.{self.trigger} -> {', '.join('out.' + o for o in self.outputs)}" \
               f" within {_show(self.bound)})"


@dataclass(frozen=True)
class DeadlineResult:
    """The decision of one end-to-end deadline.

    ``chain``: the hops used (the tightest chain); ``total``: their sum;
    ``stamps``: for ``refuted``, Z3's model as ``(event, seconds after the
    first trigger)``; ``reason``: one sentence; ``smt2``: the query."""

    requirement: str
    path: tuple[str, ...]
    within: Fraction
    status: str
    reason: str
    chain: tuple[Hop, ...] = ()
    total: Fraction | None = None
    stamps: tuple[tuple[str, Fraction], ...] = ()
    smt2: str = field(default="", compare=False)
    loc: ast.Loc = field(default_factory=ast.Loc, compare=False)
    #: the slowest other path from the first node to the last, when slower than ``path`` (:mod:`.worst_path`)
    worst_path: tuple[str, ...] = ()

    def to_json(self) -> DeadlineCheck:
        """The result as JSON (records/stage_records.py ``DeadlineCheck``): times exact (``within_s``, ``total_s``: a
        fraction of seconds as text, ``"1/5"``) and as the reader writes them
        (``within``, ``total``: ``"200 ms"``); each hop of ``chain`` with its
        guarantee's location (``loc``: ``file:line:col``)."""
        return {"requirement": self.requirement, "path": list(self.path), "within_s": str(self.within),
                "status": self.status, "reason": self.reason,
                "within": _show(self.within),
                "chain": [{"node": h.node, "guarantee": h.index, "trigger": f"in.{h.trigger}",
                           "outputs": [f"out.{o}" for o in h.outputs], "within_s": str(h.bound),
                           "within": _show(h.bound), "loc": f"{h.loc.file}:{h.loc.line}:{h.loc.col}"}
                          for h in self.chain],
                "total_s": None if self.total is None else str(self.total),
                "total": None if self.total is None else _show(self.total),
                "stamps": [{"event": e, "t_s": str(t)} for e, t in self.stamps],
                "worst_path": list(self.worst_path),
                "loc": f"{self.loc.file}:{self.loc.line}:{self.loc.col}"}


def hops(checked: Checked, node: str) -> list[Hop]:
    """The timed guarantees of ``node`` (D1), in source order."""
    out: list[Hop] = []
    for i, cl in enumerate(checked.nodes[node].node.guarantees, 1):
        if cl.trigger is None or cl.deadline is None:
            continue
        bound = seconds(cl.deadline)
        if bound is None:
            continue
        outs = tuple(dict.fromkeys(e.name for e in subexpressions(cl.formula)
                                   if isinstance(e, ast.Var) and e.prefix == "out"))
        out.append(Hop(node, i, cl.trigger.name, outs, bound, cl.loc))
    return out


def chains(checked: Checked, model: SystemModel, path: Sequence[str]) -> tuple[list[tuple[Hop, ...]], str]:
    """Every chain of hops along ``path`` (D2's side condition (a)), and,
    when there is none, the reason naming where the path breaks.

    A chain never goes through a service or action that a node ``calls``
    and no node ``serves`` (:func:`rclverify.model.system.services.unserved_parts`):
    a request to it reaches no one (it feeds no hop, whatever name the
    system model matched it by), a response from it never comes (a hop
    triggered by it never fires), and a chain whose last hop answers with
    such a request ends nowhere.  When only such chains exist, the reason
    names the call."""
    dead = unserved_parts(checked)
    found, why = _chains(checked, model, path, dead)
    if found or not dead:
        return found, why
    through, _ = _chains(checked, model, path, {})
    touched = sorted({dead[k] for c in through for h in c
                      for k in [(h.node, h.trigger), *((h.node, o) for o in h.outputs)] if k in dead})
    if through and touched:
        return [], f"every chain goes through a call nobody answers: {'; '.join(touched)}"
    return found, why


def _chains(checked: Checked, model: SystemModel, path: Sequence[str],
            dead: Mapping[tuple[str, str], str]) -> tuple[list[tuple[Hop, ...]], str]:
    """:func:`chains` with the variables ``dead`` (``(node, var)``) carrying nothing."""
    for n in path:
        if n not in checked.nodes:
            return [], f"node {n!r} of the path has no contract"

    def live(n: str) -> list[Hop]:
        return [h for h in hops(checked, n) if (n, h.trigger) not in dead]

    partial: list[tuple[Hop, ...]] = [(h,) for h in live(path[0])]
    if not partial:
        return [], f"{path[0]} has no guarantee with 'triggered by ... within ...'"
    for prev, n in zip(path, path[1:]):
        fed = {(lk.from_var, lk.to_var) for lk in model.links_into(n)
               if lk.from_node == prev and (prev, lk.from_var) not in dead}
        nxt = [c + (h,) for c in partial for h in live(n) if any((o, h.trigger) in fed for o in c[-1].outputs)]
        if not nxt:
            return [], (f"no timed guarantee of {n} is triggered by an output of {prev}'s timed guarantees "
                        f"({', '.join(sorted({'out.' + o for c in partial for o in c[-1].outputs})) or 'none'})")
        partial = nxt
    ends = [c for c in partial if not any((c[-1].node, o) in dead for o in c[-1].outputs)]
    if not ends:
        return [], f"{path[-1]}'s timed guarantees answer with a call nobody answers"
    return ends, ""


def decide(checked: Checked, model: SystemModel, requirement: str, path: Sequence[str], within: Fraction,
           loc: ast.Loc | None = None) -> DeadlineResult:
    """Rule D3 for one requirement: may the path's last output come later
    than ``within`` seconds after its first trigger?  Z3 decides it for the
    tightest chain (exact real arithmetic)."""
    loc = loc or ast.Loc()
    found, why = chains(checked, model, path)
    if not found:
        return DeadlineResult(requirement, tuple(path), within, INCONCLUSIVE, why, loc=loc)
    chain = min(found, key=lambda c: (sum(h.bound for h in c), [h.index for h in c]))
    total = sum((h.bound for h in chain), Fraction(0))
    ctx = z3.Context()
    t = [z3.Real(f"t{i}", ctx) for i in range(len(chain) + 1)]
    facts = [t[0] == 0]
    for i, h in enumerate(chain):
        facts += [t[i] <= t[i + 1], t[i + 1] - t[i] <= z3.RealVal(str(h.bound), ctx)]
    late = t[-1] - t[0] > z3.RealVal(str(within), ctx)
    s = z3.Solver(ctx=ctx)
    s.add(*facts, late)
    answer = s.check()
    smt2 = s.to_smt2()
    names = " -> ".join(h.label() for h in chain)
    if answer == z3.unsat:
        return DeadlineResult(requirement, tuple(path), within, PROVED,
                              f"the chain {names} sums to {_show(total)} <= {_show(within)}", chain, total,
                              smt2=smt2, loc=loc)
    if answer == z3.sat:
        m = s.model()
        events = [f"{chain[0].node}.in.{chain[0].trigger}"]
        events += [f"{nxt.node}.in.{nxt.trigger}" for nxt in chain[1:]]
        events.append(f"{chain[-1].node}.out.{','.join(chain[-1].outputs)}")
        stamps = tuple((e, Fraction(str(m.eval(ti, model_completion=True).as_fraction())))
                       for e, ti in zip(events, t))
        return DeadlineResult(requirement, tuple(path), within, REFUTED,
                              f"the chain {names} sums to {_show(total)} > {_show(within)}", chain, total, stamps,
                              smt2, loc)
    return DeadlineResult(requirement, tuple(path), within, INCONCLUSIVE, f"Z3 answered {answer}", chain, total,
                          smt2=smt2, loc=loc)


def _show(x: Fraction) -> str:
    """Seconds as the reader writes them: ``0.2 s`` -> ``200 ms``."""
    ms = x * 1000
    if x < 1 and ms.denominator == 1:
        return f"{ms.numerator} ms"
    return f"{float(x):g} s" if x.denominator != 1 else f"{x.numerator} s"


#: Seconds as the reader writes them (the report's name for :func:`_show`).
show_seconds = _show


def decide_plan(plan: Any, checked: Checked, model: SystemModel) -> list[DeadlineResult]:
    """Rule D3 for every ``deadline:`` of the plan's requirements
    (:class:`~rclverify.model.plan.model.DeadlineSpec`), in plan order."""
    return [decide(checked, model, d.requirement, d.path, d.within, d.loc) for d in plan.deadlines]


def show(results: Sequence[DeadlineResult]) -> str:
    """One paragraph per result: ``REQ: proved|refuted|inconclusive``, the
    reason (the chain named) and, when refuted, the late run's stamps."""
    lines: list[str] = []
    for r in results:
        lines.append(f"{r.loc.file}:{r.loc.line}:{r.loc.col}: {r.requirement}: end-to-end deadline "
                     f"{_show(r.within)} along {' -> '.join(r.path)}: {r.status}")
        lines.append(f"  {r.reason}")
        for e, t in r.stamps:
            lines.append(f"  {e} at t0 + {float(t):g} s")
    return "\n".join(lines) + ("\n" if lines else "")
