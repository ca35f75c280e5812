"""Discharging a Hoare triple's verification conditions with Z3.

Each VC ``hyps => goal`` (:class:`rclverify.backends.hoare.wp.VC`) is
checked by asking Z3 whether ``hyps and not goal`` is satisfiable, with a
timeout (shared/DESIGN.md, "Solver answers"): unsat -> the VC is valid;
sat -> it is refuted; unknown (or timeout) -> nothing is concluded.  A
triple is ``discharged`` only when every VC is valid, ``failed`` when a
refuted VC comes with a run of the program that breaks the triple
(:func:`check_all`: a loop's VC is refuted in a state no run need reach, so
its model is no counterexample), ``inconclusive`` otherwise.

A counterexample of the triple's own VC (``main``) names concrete values of
the program's initial variables and of the uninterpreted function
applications the VC mentions, and then *runs the program* on them (the model
interprets the externs) to show the final values, e.g.
``{"i": 0, "radiation_at(i)": 15, "output (final)": "orange"}``.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Mapping, Sequence

import z3

from rclverify.semantics import mathfacts
from rclverify.semantics.query import query_solver, solver_session
from rclverify.backends.hoare import lang
from rclverify.backends.hoare.outline import z3_text
from rclverify.backends.hoare.program_model import ProgramModel, iter_terms
from rclverify.backends.hoare.wp import VC

#: Statement executions allowed when replaying a counterexample (loops).
MAX_STEPS = 100_000


@dataclass(frozen=True)
class VCResult:
    """Z3's answer for one VC: ``status`` ``valid``/``invalid``/``unknown``;
    ``model`` (invalid only); ``reason`` (unknown only); ``smt2`` the query."""

    vc: VC
    status: str
    smt2: str
    model: z3.ModelRef | None = None
    reason: str = ""
    hyps: tuple[z3.BoolRef, ...] = ()


@dataclass(frozen=True)
class TripleResult:
    """All VCs of a triple checked.

    ``status``          ``discharged``/``failed``/``inconclusive``;
    ``results``         per VC, ``main`` first;
    ``failed``          the refuted VC whose run breaks the triple, a definedness VC
                        (:mod:`.defined`) first (``failed`` only);
    ``counterexample``  JSON-serialisable name -> value (``failed`` only);
    ``notes``           what the values are (``failed``), or why each refuted VC
                        shows no run (``inconclusive``).
    """

    status: str
    results: tuple[VCResult, ...]
    failed: VCResult | None = None
    counterexample: dict[str, object] | None = None
    notes: tuple[str, ...] = field(default=())


def json_value(v: z3.ExprRef) -> Any:
    """A model value as JSON: int, float (exact decimals), ``"p/q"``, bool or RCL text."""
    if z3.is_int_value(v):
        return v.as_long()
    if z3.is_rational_value(v):
        fr = Fraction(v.numerator_as_long(), v.denominator_as_long())
        if fr.denominator == 1:
            return fr.numerator
        dec = float(fr)
        return dec if Fraction(dec) == fr else f"{fr.numerator}/{fr.denominator}"
    if z3.is_algebraic_value(v):
        return str(v.as_decimal(6))
    if z3.is_true(v):
        return True
    if z3.is_false(v):
        return False
    return z3_text(v)


def _smt2(s: z3.Solver, title: str) -> str:
    """The query text of solver ``s``, which holds the query's formulas and has
    not been checked yet (its options, e.g. the budget, are not part of the text)."""
    # Solver.sexpr() names shared subterms a!1, a!2 ... in order (to_smt2()
    # uses internal ids, which differ between processes): deterministic text.
    return f"; {title}\n" + str(s.sexpr()) + "(check-sat)\n"


def check_vc(vc: VC, background: Sequence[z3.BoolRef], m: ProgramModel, timeout_ms: int) -> VCResult:
    """Check one VC under ``background`` facts (typing axioms ...).

    The program's own range facts (NATURAL variables, externs with a NATURAL
    result) for the symbols the VC mentions are added.  ``timeout_ms`` in
    milliseconds.  Never raises for an unknown answer.
    """
    core = [*vc.hyps, vc.goal]
    hyps = (*vc.hyps, *background, *m.typing_facts(core))
    formulas = [*hyps, z3.Not(vc.goal)]
    with query_solver(timeout_ms) as s:
        s.add(*formulas, *mathfacts.facts(formulas))  # sqrt/sin/cos: true facts of the unknown functions
        text = _smt2(s, f"{vc.id}: {vc.label}; unsat means the condition holds")
        r = s.check()
        if r == z3.unsat:
            return VCResult(vc, "valid", text, hyps=hyps)
        if r == z3.sat and mathfacts.transcendental(formulas):  # a model of sin/cos counts once Python's math agrees
            why = mathfacts.unconfirmed(formulas, s.model())
            if why is not None:
                return VCResult(vc, "unknown", text, reason=why, hyps=hyps)
        if r == z3.sat:
            return VCResult(vc, "invalid", text, model=s.model(), hyps=hyps)
        return VCResult(vc, "unknown", text, reason=s.reason_unknown(), hyps=hyps)


class _Replay:
    """Runs the program concretely under a model (externs as the model interprets them), from
    ``init`` (variable -> value; default: the model's values of the variables' constants)."""

    def __init__(self, m: ProgramModel, model: z3.ModelRef, init: Mapping[str, z3.ExprRef] | None = None) -> None:
        self.m, self.model = m, model
        self.init = dict(init) if init is not None else {
            n: model.eval(c, model_completion=True) for n, c in m.consts.items()}
        self.state = dict(self.init)
        self.steps = 0

    def eval(self, e: lang.Expr) -> z3.ExprRef:
        t = self.m.term(e)
        subs = [(self.m.consts[n], v) for n, v in self.state.items()]
        subs += [(self.m.olds[n], v) for n, v in self.init.items()]
        return self.model.eval(z3.substitute(t, *subs), model_completion=True)

    def run(self, body: tuple[lang.Stmt, ...]) -> bool:
        for s in body:
            self.steps += 1
            if self.steps > MAX_STEPS:
                return False
            if isinstance(s, lang.Assign):
                self.state[s.target] = self.model.eval(self.m.value_for(s.target, self.eval(s.value)),
                                                       model_completion=True)
            elif isinstance(s, lang.If):
                if not self.run(s.then_ if z3.is_true(self.eval(s.cond)) else s.else_):
                    return False
            elif isinstance(s, lang.While):
                while z3.is_true(self.eval(s.cond)):
                    if not self.run(s.body):
                        return False
                    self.steps += 1
                    if self.steps > MAX_STEPS:
                        return False
        return True


def _assigned(body: tuple[lang.Stmt, ...]) -> list[str]:
    out: list[str] = []
    for s in body:
        names = ([s.target] if isinstance(s, lang.Assign) else
                 _assigned(s.then_) + _assigned(s.else_) if isinstance(s, lang.If) else
                 _assigned(s.body) if isinstance(s, lang.While) else [])
        out.extend(n for n in names if n not in out)
    return out


def counterexample(res: VCResult, m: ProgramModel, observe: Mapping[str, z3.ExprRef] | None = None,
                   observe_final: Mapping[str, str] | None = None,
                   names: Mapping[str, str] | None = None) -> tuple[dict[str, object], list[str]]:
    """Concrete values behind a refuted VC.

    Returns ``(values, notes)``: ``values`` maps the program variables the VC
    mentions and the extern applications in it (``radiation_at(i)``) to their
    values; ``observe`` adds named initial-state terms (``in.r``), and the
    VC's other free symbols are added under their ``names`` (``in.command``);
    for the
    ``main`` VC (any VC of the initial state but a division of the program's
    own, :mod:`.defined`, whose run stops there) the program is replayed and ``"<x> (final)"`` gives each
    assigned variable's final value, ``observe_final`` names some of them
    again (``out.radiationStatus`` -> ``output``).  ``notes`` explain what the
    state is.
    """
    assert res.model is not None
    model = res.model
    formulas = [*res.vc.hyps, res.vc.goal]
    out: dict[str, object] = {}
    for n in m.variables_in(formulas):
        out[n] = json_value(model.eval(m.consts[n], model_completion=True))
    for n in m.olds_in(formulas):
        out[f"old({n})"] = json_value(model.eval(m.olds[n], model_completion=True))
    for app in m.extern_applications(formulas):
        out[z3_text(app, names)] = json_value(model.eval(app, model_completion=True))
    for label, term in (observe or {}).items():
        out[label] = json_value(model.eval(term, model_completion=True))
    program_names = {c.decl().name() for c in (*m.consts.values(), *m.olds.values())}
    for t in iter_terms(formulas):  # other free symbols, e.g. the contract's in.command
        if z3.is_const(t) and t.decl().kind() == z3.Z3_OP_UNINTERPRETED and t.decl().name() not in program_names:
            label = (names or {}).get(t.decl().name(), t.decl().name())
            out.setdefault(label, json_value(model.eval(t, model_completion=True)))
    notes: list[str] = []
    if res.vc.id.startswith("defined@") and res.vc.state == "initial":  # the run stops there (.defined)
        notes.append(f"the run divides by zero at {res.vc.loc.file}:{res.vc.loc.line}:{res.vc.loc.col}: it has no "
                     "final state")
    elif res.vc.state == "initial":
        replay = _Replay(m, model)
        if replay.run(m.program.body):
            for n in _assigned(m.program.body):
                out[f"{n} (final)"] = json_value(replay.state[n])
            for label, var in (observe_final or {}).items():
                out[label] = json_value(replay.state[var])
        else:
            notes.append(f"replaying the program on these values did not finish within {MAX_STEPS} steps")
    else:
        notes.append(f"the values are a state at the head of the loop at line {res.vc.loc.line}")
    return out, notes


def _has_loop(body: tuple[lang.Stmt, ...]) -> bool:
    return any(isinstance(s, lang.While) or (isinstance(s, lang.If) and (_has_loop(s.then_) or _has_loop(s.else_)))
               for s in body)


def _exact(res: VCResult, m: ProgramModel) -> bool:
    """Whether a model of ``res``'s refuted VC is itself a run that breaks the triple: a VC of the
    initial state of a program without loops (weakest preconditions are exact there), or a
    definedness VC of the initial state (a division that sees a zero divisor, :mod:`.defined`)."""
    return res.vc.state == "initial" and (res.vc.id.startswith("defined") or not _has_loop(m.program.body))


def breaking_run(res: VCResult, m: ProgramModel, pre: z3.BoolRef, post: z3.BoolRef,
                 background: Sequence[z3.BoolRef] = (), observe: Mapping[str, z3.ExprRef] | None = None,
                 observe_final: Mapping[str, str] | None = None) -> dict[str, object] | str:
    """A run that breaks the triple, from a refuted VC that is not :func:`_exact`, or why none is shown.

    A loop's VCs hold in an arbitrary state at its head (:mod:`.wp`), which no
    run need reach, and the ``main`` VC of a program with loops fails as well
    when an invariant does not hold on entry: such a model is no
    counterexample.  The run tried starts in the model's initial state (its
    values of the variables for a VC of the initial state, of their
    ``old(x)`` for a loop's), must meet ``pre`` and the ``background`` facts
    and the variables' types there, and is replayed to its end; it breaks the
    triple when ``post`` is false in its final state.  Returns the run's
    values (``x``, ``old`` names of ``observe``, ``x (final)``, the
    ``observe_final`` names) or the reason in one sentence."""
    assert res.model is not None
    model = res.model
    source = m.consts if res.vc.state == "initial" else m.olds
    init = {n: model.eval(source[n], model_completion=True) for n in m.consts}

    def at_init(f: z3.ExprRef) -> z3.ExprRef:
        subs = [(m.consts[n], v) for n, v in init.items()] + [(m.olds[n], v) for n, v in init.items()]
        return model.eval(z3.substitute(f, *subs), model_completion=True)

    where = (f"a state at the head of the loop at line {res.vc.loc.line}, which no run need reach"
             if res.vc.state == "loop" else "the initial state of a program with loops")
    typed = m.typing_facts([*m.consts.values()])
    if not all(z3.is_true(at_init(f)) for f in (pre, *background, *typed)):
        return (f"Z3 refutes {res.vc.id} ({res.vc.label}) in {where}; the run from the initial values it gives "
                "does not meet the precondition, so no run breaking the triple was shown")
    replay = _Replay(m, model, init)
    if not replay.run(m.program.body):
        return (f"Z3 refutes {res.vc.id} ({res.vc.label}) in {where}; replaying the program from its initial "
                f"values did not finish within {MAX_STEPS} steps, so no run breaking the triple was shown")
    subs = [(m.consts[n], v) for n, v in replay.state.items()] + [(m.olds[n], v) for n, v in init.items()]
    if z3.is_true(model.eval(z3.substitute(post, *subs), model_completion=True)):
        return (f"Z3 refutes {res.vc.id} ({res.vc.label}) in {where}, but the run from the initial values it "
                "gives meets the postcondition: a loop invariant is too weak, not preserved or not true on "
                "entry, and no run breaking the triple was shown")
    out: dict[str, object] = {n: json_value(v) for n, v in init.items()}
    for label, term in (observe or {}).items():
        out[label] = json_value(at_init(term))
    for n in _assigned(m.program.body):
        out[f"{n} (final)"] = json_value(replay.state[n])
    for label, var in (observe_final or {}).items():
        out[label] = json_value(replay.state[var])
    return out


def check_all(vcs: Sequence[VC], background: Sequence[z3.BoolRef], m: ProgramModel, timeout_ms: int,
              observe: Mapping[str, z3.ExprRef] | None = None, observe_final: Mapping[str, str] | None = None,
              names: Mapping[str, str] | None = None,
              triple: tuple[z3.BoolRef, z3.BoolRef] | None = None) -> TripleResult:
    """Check every VC of a triple (``main`` first) and roll the answers up.

    A refuted VC makes the triple ``failed`` only with a run that breaks it:
    the model itself where it is one (a VC of the initial state of a program
    without loops, a definedness VC of the initial state), else the run
    :func:`breaking_run` replays from the model's initial values against
    ``triple`` (``(pre, post)``; without it none is tried); with none the
    triple is ``inconclusive`` and ``notes`` say why.  The VCs share one
    solver session (:func:`~rclverify.semantics.query.solver_session`): the
    same VCs in the same order wherever the triple is checked (a local run,
    a cluster worker), so the answers and counterexamples are too."""
    with solver_session():
        results = tuple(check_vc(vc, background, m, timeout_ms) for vc in vcs)
    # a definedness VC refuted is the failure reported: what else fails reads an undefined value
    refuted = sorted((r for r in results if r.status == "invalid"), key=lambda r: not r.vc.id.startswith("defined"))
    why: list[str] = []
    for bad in refuted:
        if _exact(bad, m):
            cex, notes = counterexample(bad, m, observe, observe_final, names)
            return TripleResult("failed", results, bad, cex, tuple(notes))
        if triple is None:
            why.append(f"Z3 refutes {bad.vc.id} ({bad.vc.label}), whose model is no run of the program")
            continue
        run = breaking_run(bad, m, triple[0], triple[1], background, observe, observe_final)
        if isinstance(run, dict):
            return TripleResult("failed", results, bad, run, (
                f"{bad.vc.id} is refuted; the run from its model's initial values breaks the triple",))
        why.append(run)
    if why:
        return TripleResult("inconclusive", results, notes=tuple(why))
    if any(r.status == "unknown" for r in results):
        return TripleResult("inconclusive", results)
    return TripleResult("discharged", results)
