"""The composed system of a requirement's cone as the temporal checks read it
(:class:`ComposedSystem`, built by :func:`.transition.build_system`): its
transition system, variables, premises listed for the record, the nodes'
fairness and progress bounds, the initial values, publication, and the
readings derived from it (every node fair, every node eager, a statement's
symbols at a state, the variables' RCL types).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import z3

from rclverify.semantics.connectives import conj
from rclverify.model.plan.load import Plan
from rclverify.model.plan.state import state_type
from rclverify.lang.types import BOOL, INTEGER, Checked, Type
from rclverify.calculus.requirements.published import Publication
from rclverify.calculus.requirements.temporal import State, TransitionSystem
from rclverify.calculus.requirements.tsys import Fairness, Pred
from rclverify.semantics import wallclock


@dataclass
class ComposedSystem:
    """The transition system of a cone and how to read it.

    ``ts``        the :class:`~.temporal.TransitionSystem` (variables named
                  ``Node.in.x`` / ``Node.out.y`` / ``Node.state.v``);
    ``cone``      the nodes, in source order;
    ``variables`` ``{name: (node, "in"|"out"|"state"|"run", var)}`` (``run``:
                  ``answers``, ``accepts``, ``waiting``);
    ``premises``  what the system is made of, for the record: ``{label,
                  kind, node, index, text, source}`` per guarantee,
                  assumption, fact, initial value, progress and state
                  declaration;
    ``everyone``  fairness for every node that answers (as if each
                  declared ``progress( eventually )``): what the diagnosis
                  of a lasso asks again (:func:`fair_everywhere`);
    ``links``     the connections inside the cone, ``(consumer input,
                  producer output)`` by variable name.
    """

    ts: TransitionSystem
    cone: list[str]
    variables: dict[str, tuple[str, str, str]]
    premises: list[dict[str, Any]] = field(default_factory=list)
    everyone: tuple[Fairness, ...] = ()
    links: list[tuple[str, str]] = field(default_factory=list)
    bounds: dict[str, int | None] = field(default_factory=dict)
    #: per node that declares ``initially``: its outputs' types and initial values over one state
    initial: dict[str, Pred] = field(default_factory=dict)
    #: which values are published at each step (:mod:`.published`; docs/semantics.md)
    pub: Publication = field(default_factory=Publication)

    def initial_values_unsatisfiable(self, timeout_ms: int) -> tuple[list[dict[str, Any]], str]:
        """The premises of the initial values that no output satisfies (a
        node that must then answer at step 0, which would silently remove
        every run whose first input it cannot accept), and the solver's
        reason for any it could not decide (``""``: none)."""
        bad: list[dict[str, Any]] = []
        why = ""
        for n, holds in self.initial.items():
            s = z3.Solver()
            wallclock.limit(s, timeout_ms)  # steps decide, the clock is a net
            s.add(holds(self.ts.state(0, "initially")))
            r = s.check()
            if r == z3.unsat:
                bad += [p for p in self.premises if p["kind"] == "initial value" and p["node"] == n]
            elif r == z3.unknown:
                why = why or f"whether {n}'s initial value can hold ({s.reason_unknown()})"
        return bad, why

    @property
    def eager(self) -> bool:
        """Whether every node that answers declares ``progress( within 0
        steps )`` (then :meth:`synchronous` is the system itself)."""
        return all(self.bounds.get(f.label) == 0 for f in self.everyone)

    def fair_everywhere(self, ts: TransitionSystem) -> TransitionSystem:
        """``ts`` (this system's, possibly restricted further) with every
        node's fairness, declared or not."""
        have = {f.label for f in ts.fairness}
        return TransitionSystem(ts.sorts, ts.init, ts.trans,
                                ts.fairness + tuple(f for f in self.everyone if f.label not in have))

    def synchronous(self, ts: TransitionSystem) -> TransitionSystem:
        """``ts`` in which every node answers at every step its assumption
        holds (as if each declared ``progress( within 0 steps )``): a
        subsystem of :meth:`fair_everywhere`'s, and the reading before
        progress could be declared."""
        def eager(s: State) -> z3.BoolRef:
            return conj(*[z3.Implies(f.enabled(s), f.taken(s)) for f in self.everyone])
        return TransitionSystem(ts.sorts, lambda s: conj(ts.init(s), eager(s)),
                                lambda s, t: conj(ts.trans(s, t), eager(s), eager(t)), ts.fairness)

    def statement_symbols(self, s: State) -> dict[str, z3.ExprRef]:
        """The encoder's symbols of a requirement statement at state ``s``
        (:mod:`rclverify.model.plan.formal` names ``Node.in.x`` an input of its
        pseudo node, so the key is ``"in.Node.in.x"``)."""
        out = {}
        for name, (_, p, _) in self.variables.items():
            out[f"{'out' if p == 'out' else 'in'}.{name}"] = s[name]
        for c, f in self.pub.first.items():  # first(Node.in.x): its flag (.published)
            out[f"first(in.{c})"] = s[f]
        return out



def variable_types(sys: ComposedSystem, checked: Checked, plan: Plan) -> dict[str, Type]:
    """The RCL type of each variable of ``sys`` (``{name: type}``)."""
    out: dict[str, Type] = {}
    declared = {(sv.node, sv.name): sv for sv in plan.states}
    for name, (n, p, v) in sys.variables.items():
        cn = checked.nodes[n]
        if p == "run":
            out[name] = INTEGER if v == "waiting" else BOOL
            continue
        out[name] = state_type(declared[(n, v)], checked) if p == "state" else (cn.inputs if p == "in" else cn.outputs)[v]
    return out
