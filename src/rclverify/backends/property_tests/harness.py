"""The Hypothesis run of one guarantee of a node against a Python implementation.

Shared by the backend (:mod:`.backend`) and the pytest files it writes under
``artifacts/property_tests/<Node>/``, so that both check exactly the same
thing (docs/property-tests.md).

Per example: inputs are drawn (:mod:`.strategies`) and kept only when the
node's assumption holds on them (a filter, so Hypothesis's
``filter_too_much`` health check watches the rejection rate); the
implementation is called with one keyword argument per input; its outputs
must be a mapping with exactly the node's output names, each value of its
RCL type (:func:`rclverify.semantics.values.conforms`); then every top-level conjunct
of the guarantee is checked on the inputs and outputs as the implementation
computed them (:func:`rclverify.semantics.floatsem.judge`: exact arithmetic by
direct evaluation, Z3 only where it cannot decide, then the IEEE-754 double
arithmetic a Python implementation computes in, as the monitors judge a
recorded run; docs/property-tests.md, "Numbers as the implementation
computes them").  A violation is shrunk by Hypothesis; Z3's ``unknown``
counts as inconclusive, never as passed.  The reported counterexample is
confirmed by Z3 (:func:`rclverify.semantics.concrete.check_concrete`): the facts
hold on its inputs and its outputs violate the conjunct.
"""
from __future__ import annotations

import inspect
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping

import z3

from rclverify.backends.property_tests.hypothesis_lib import (FailedHealthCheck, HealthCheck, Phase, Unsatisfiable,
                                                             Verbosity, given, hypothesis, settings, st)

from rclverify.semantics.concrete import check_concrete
from rclverify.semantics.decide import decide
from rclverify.semantics.floatsem import judge
from rclverify.semantics.encode import EncodingError
from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked, CheckedNode
from rclverify.semantics.values import conforms, render
from rclverify.backends.property_tests.seeding import Seeder, split_facts
from rclverify.backends.property_tests.coverage import Coverage
from rclverify.backends.property_tests.constants import boundary_constants, constant_values
from rclverify.backends.property_tests.strategies import assumption_bounds, conjuncts, input_space
from rclverify.backends.property_tests.thresholds import drawn_thresholds, solved_thresholds
from rclverify.backends.property_tests.config import Config, ConfigError, load_implementation, read_config
from rclverify.backends.property_tests.closure import resolve_closure
from rclverify.backends.property_tests.first_calls import judge_first
from rclverify.backends.property_tests.importpath import on_harness_path
from rclverify.backends.monitors.widths import at_carried_widths
from rclverify.backends.property_tests.at_width import carried_in, input_strategies
from rclverify.semantics.widths import Carried, carried_fault, edges_at_width, narrow
from rclverify.traces.typed_text import render_as
from rclverify.backends.property_tests.local_constants import no_local_constants
from rclverify.backends.property_tests.outcome import Counts, Outcome

# The plan entry's reading lives in .config and the outcome's records in .outcome; their names stay importable
# from here (the backend, replay, the tests and the benchmark import them with the run).
__all__ = ["Config", "ConfigError", "Counts", "GuaranteeRun", "Outcome", "load_implementation", "read_config",
           "run_guarantee", "versions"]


class _Violation(AssertionError):
    pass


def _source(loc: ast.Loc) -> str:
    return f"{loc.file}:{loc.line}:{loc.col}"


def _assumption_text(node: CheckedNode) -> str:
    return " and ".join(f"{expr_to_rcl(c.formula)} ({_source(c.loc)})" for c in node.node.assumes) or "TRUE"


@dataclass
class GuaranteeRun:
    """Everything needed to check guarantee ``guarantee`` (1-based) of ``node``."""

    checked: Checked
    node: CheckedNode
    guarantee: int
    cfg: Config
    impl: Any
    facts: tuple[ast.Expr, ...] = ()  # the plan's environment facts of the node (docs/property-tests.md)
    stop_at_failure: bool = True  # False: count violations and go on (benchmarks); no shrinking then
    counts: Counts = field(default_factory=Counts)
    last_failure: dict[str, str] | None = None
    #: the values, outputs and conjunct of ``last_failure`` (for the Z3 confirmation)
    last_values: tuple[dict[str, object], dict[str, object] | None, ast.Expr | None] | None = None
    unknown: set[str] = field(default_factory=set)
    #: the first check that held only in double arithmetic: (conjunct text, rendered values)
    first_double: tuple[str, str] | None = None
    #: the example of the last body run (a function's inputs, a class's steps): replayed for the cause line
    last_example: Any = None
    _used_facts: tuple[ast.Expr, ...] | None = field(default=None, repr=False)
    #: the valid examples' coverage of the assumption's ranges (set up with the strategy)
    coverage: Coverage | None = field(default=None, repr=False)
    #: the width each input and output's field carries ("in.x" -> "float32"; semantics/widths.py): inputs are
    #: passed and outputs judged as they travel, the thresholds drawn as the fields carry them
    widths: Mapping[str, str] = field(default_factory=dict)
    #: what each input and output's field carries ("in.x" -> uint8, float32[<=4], ...): inputs drawn within
    #: it, an output it cannot carry a counterexample (backends/property_tests/at_width.py)
    carried: Mapping[str, Carried] = field(default_factory=dict)
    #: Only whether the guarantee is discharged counts (a candidate repair's check, diagnosis/code_repair_check.py):
    #: a violation ends the run unshrunk, its example neither moved to the boundary nor re-checked by Z3, and the
    #: outcome is ``failed`` (the full run's ``failed``, or ``error`` for a counterexample Z3 does not confirm);
    #: every other outcome, ``discharged`` among them, is the full run's (the same examples are drawn up to the
    #: first violation)
    verdict_only: bool = False

    @property
    def stateful(self) -> bool:
        return inspect.isclass(self.impl)

    def assumption_holds(self, values: Mapping[str, object]) -> bool:
        self.counts.drawn += 1
        for clause in self.node.node.assumes:
            ok, why = decide(clause.formula, self.checked, self.node, values)
            if ok is None:
                self.counts.assumption_unknown += 1
                self.unknown.add(f"assumption: {why}")
            if ok is not True:
                self.counts.rejected += 1
                return False
        for fact in self.used_facts:
            ok, why = decide(fact, self.checked, self.node, values)
            if ok is None:
                self.counts.assumption_unknown += 1
                self.unknown.add(f"fact: {why}")
            if ok is not True:
                self.counts.rejected += 1
                self.counts.rejected_by_facts += 1
                return False
        return True

    @property
    def used_facts(self) -> tuple[ast.Expr, ...]:
        """The facts inputs are drawn under: those naming no output (worked out once:
        the filter asks for them on every drawn example)."""
        if self._used_facts is None:
            self._used_facts = split_facts(self.facts, self.node)[0]
        return self._used_facts

    def facts_text(self) -> str:
        """The facts as RCL text with their plan locations ("" when there are none)."""
        return "; ".join(f"{expr_to_rcl(f)} ({_source(f.loc)})" for f in self.used_facts)

    def strategy(self) -> st.SearchStrategy[Any]:
        seed = None
        if self.used_facts:
            formulas = tuple(c.formula for c in self.node.node.assumes) + self.used_facts
            seed = Seeder(self.checked, self.node, formulas).base()
        # every threshold the contract or the code compares with, drawn with its neighbours (.constants);
        # a named constant bounds an input as a literal does
        named = constant_values(self.checked, self.node)
        constants = boundary_constants(self.checked, self.node, self.impl)
        # and every threshold a comparison puts on an input, however written (in.p / 2 <= 0.1: 0.2), solved on the
        # contract read at the fields' widths, as the monitors judge it (.thresholds)
        solved = solved_thresholds(self.node, self.checked.env.constants, self.used_facts)
        constants = sorted({*constants, *solved})
        for width in sorted(set(self.widths.values())):  # the thresholds as the fields carry them, and their neighbours
            constants = sorted(set(constants) | set(edges_at_width(constants, width)))
        space = input_space(self.node, self.cfg.bounds, seed, constants, named)
        space.thresholds = drawn_thresholds(self.node, solved, space.bounds, self.widths)
        space.carried = input_strategies(space, dict(self.carried))
        self.coverage = Coverage(self.node, space.bounds, assumption_bounds(self.node, named))
        one = space.inputs().filter(self.assumption_holds)
        if self.stateful:
            return st.lists(one, min_size=1, max_size=self.cfg.steps)
        return one

    def _fail(self, inputs: Mapping[str, object], outputs: Mapping[str, object] | None, reason: str,
              conjunct: ast.Expr | None, step: int | None) -> None:
        self.counts.failures += 1
        g = self.node.node.guarantees[self.guarantee - 1]
        cex = {k: render_as(v, self.node.inputs.get(k.removeprefix("in."))) for k, v in sorted(inputs.items())}
        if outputs is not None:
            cex.update({f"out.{k}": render_as(v, self.node.outputs.get(k)) for k, v in sorted(outputs.items())})
        cex["guarantee"] = f"{self.node.name} guarantee {self.guarantee}"
        cex["source"] = _source(conjunct.loc if conjunct is not None else g.loc)
        if conjunct is not None:
            cex["conjunct"] = expr_to_rcl(conjunct)
        if step is not None:
            cex["step"] = str(step)
        if self.used_facts:
            cex["facts"] = f"{self.facts_text()}: all hold on these inputs (checked by Z3)"
        cex["reason"] = reason
        self.last_failure = cex
        self.last_values = (dict(inputs), None if outputs is None else dict(outputs), conjunct)
        if self.stop_at_failure:
            raise _Violation(reason)

    def check_step(self, impl: Callable[..., Any], inputs: Mapping[str, object], step: int | None) -> None:
        """Call the implementation on one input and check its outputs (raises on a violation)."""
        self.counts.steps += 1
        if self.coverage is not None:
            self.coverage.add(inputs)
        widths = self.widths
        if widths:  # each input as its field carries it to the node
            inputs = {k: narrow(v, widths[k]) if k in widths else v for k, v in inputs.items()}
        kwargs = {k.removeprefix("in."): v for k, v in inputs.items()}
        try:
            result = impl(**kwargs)
        except Exception as exc:  # the implementation's own failure
            return self._fail(inputs, None, f"the implementation raised {type(exc).__name__}: {exc}", None, step)
        if not isinstance(result, Mapping):
            return self._fail(inputs, None, f"the implementation returned {result!r}, not a mapping of output "
                              f"name to value", None, step)
        outputs = dict(result)
        names = set(self.node.outputs)
        if set(outputs) != names:
            missing, extra = sorted(names - set(outputs)), sorted(set(outputs) - names)
            return self._fail(inputs, None, "the implementation's outputs do not match the node's: "
                       + "; ".join(p for p in (f"missing {', '.join(missing)}" if missing else "",
                                              f"unexpected {', '.join(map(str, extra))}" if extra else "") if p),
                       None, step)
        for name, t in self.node.outputs.items():
            why = conforms(outputs[name], t)
            if why:
                return self._fail(inputs, None, f"output out.{name} is not a value of its type {t}: {why}", None, step)
            carry = self.carried.get(f"out.{name}")
            why = carried_fault(outputs[name], carry) if carry is not None else None
            if why:  # rclpy's message refuses it, C++ wraps or cuts it: no subscriber reads the computed value
                return self._fail(inputs, outputs, f"output out.{name}: {why}, so the robot cannot publish it",
                                  None, step)
        values = {**inputs, **{f"out.{k}": v for k, v in outputs.items()}}
        if widths:  # each output as its field carries it (the value a subscriber and a monitor read)
            values = {k: narrow(v, widths[k]) if k in widths else v for k, v in values.items()}
        g = self.node.node.guarantees[self.guarantee - 1]
        for c in conjuncts(g.formula):
            judged, firsts = judge_first(c, self.checked, self.node, values, step, judge)  # first(in.x): first_calls.py
            ok, why = judged.truth, judged.reason
            if ok and judged.semantics == "double":
                self.counts.double += 1
                if self.first_double is None:
                    self.first_double = (expr_to_rcl(c), ", ".join(f"{k} = {render(v)}" for k, v in sorted(values.items())))
            if ok is None:
                self.counts.inconclusive += 1
                self.unknown.add(why)
                return
            if not ok:
                return self._fail({**inputs, **firsts}, outputs, f"the outputs violate guarantee {self.guarantee} "
                           f"({expr_to_rcl(c)})", c, step)

    def body(self, example: Any) -> None:
        self.counts.valid += 1
        self.last_example = example
        if self.stateful:
            machine = self.impl()
            for k, inputs in enumerate(example, 1):
                self.check_step(machine.step, inputs, k)
        else:
            self.check_step(self.impl, example, None)

    def settings(self, verbosity: Verbosity = Verbosity.quiet) -> settings:
        # no "explain" phase: it re-runs the shrunk example many times and adds nothing the counterexample does
        # not already say; no "shrink" phase for a verdict only (:attr:`verdict_only`)
        phases = [Phase.explicit, Phase.reuse, Phase.generate, Phase.target, *(() if self.verdict_only else (Phase.shrink,))]
        return settings(max_examples=self.cfg.max_examples, database=None, derandomize=False,
                        deadline=self.cfg.deadline_ms, report_multiple_bugs=False, print_blob=False,
                        verbosity=verbosity, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
                        phases=phases)

    def confirm_with_z3(self) -> str:
        """Re-check the reported counterexample with Z3 alone: every used fact
        holds on its inputs and its outputs violate the conjunct.  Returns ''
        when Z3 confirms it (or answers unknown: then direct evaluation's
        verdict stands), else a message saying where the engines disagree."""
        if self.last_values is None:
            return ""
        inputs, outputs, conjunct = self.last_values
        for fact in self.used_facts:
            ok, _ = check_concrete(fact, self.checked, self.node, inputs)
            if ok is None and self.last_failure is not None:  # say what checked the facts
                self.last_failure["facts"] = (f"{self.facts_text()}: all hold on these inputs (checked by direct "
                                              f"evaluation; Z3 answered unknown)")
            if ok is False:
                return (f"internal: direct evaluation and Z3 disagree on the fact {expr_to_rcl(fact)} "
                        f"for the counterexample {_example_text(self.last_failure or {})}")
        if conjunct is not None and outputs is not None:
            values = {**inputs, **{f"out.{k}": v for k, v in outputs.items()}}
            ok, _ = check_concrete(conjunct, self.checked, self.node, values)
            if ok is True:
                return (f"internal: direct evaluation and Z3 disagree on {expr_to_rcl(conjunct)} "
                        f"for the counterexample {_example_text(self.last_failure or {})}")
        return ""

    def _unconfirmed(self) -> Outcome | None:
        """The ``error`` outcome when Z3 does not confirm the counterexample, else None."""
        try:
            wrong = self.confirm_with_z3()
        except EncodingError as exc:
            return Outcome("error", f"Z3 cannot express the formula: {exc}", self.counts, None, sorted(self.unknown))
        return Outcome("error", wrong, self.counts, None, sorted(self.unknown)) if wrong else None

    def run(self) -> Outcome:
        """Run Hypothesis; never raises for a failing, inconclusive or starved run
        (raises :class:`.seeding.SeedingCut` when the wall clock cut the search for a first example).
        The outcome carries the valid examples' coverage of the assumption's ranges."""
        outcome = self._run()
        if self.coverage is not None:
            outcome.coverage = self.coverage.as_dict()
        return outcome

    def _run(self) -> Outcome:
        test = hypothesis.seed(self.cfg.seed)(self.settings()(given(self.strategy())(self.body)))
        try:
            with no_local_constants():
                test()
        except _Violation:
            assert self.last_failure is not None
            if self.verdict_only:
                return Outcome("failed", f"{self.last_failure['reason']} on the example (not shrunk) "
                               f"{_example_text(self.last_failure)}", self.counts, self.last_failure, sorted(self.unknown))
            from rclverify.backends.property_tests.readable import readable_failure  # the boundary value first, the implementation's line; deferred: optional or conditional (inside a block)
            with no_local_constants():  # it draws neighbour examples as the run drew its own
                moved = readable_failure(self, _Violation)
            unconfirmed = self._unconfirmed()
            if unconfirmed is not None:
                return unconfirmed
            cause = self.last_failure.get("cause")
            return Outcome("failed", f"{self.last_failure['reason']} on the {'example' if moved else 'shrunk example'} "
                           f"{_example_text(self.last_failure)}" + (f" (the implementation line where the failing example goes wrong: {cause})"
                                                                    if cause else ""),
                           self.counts, self.last_failure, sorted(self.unknown))
        except (FailedHealthCheck, Unsatisfiable) as exc:
            kind = "filter_too_much" if isinstance(exc, FailedHealthCheck) else "unsatisfiable"
            facts = f" with the environment facts {self.facts_text()}" if self.used_facts else ""
            msg = (f"the assumption of {self.node.name}, {_assumption_text(self.node)}{facts}, rejected "
                   f"{self.counts.rejected} of {self.counts.drawn} drawn inputs ({kind}): filtering cannot find "
                   f"inputs that satisfy it; give bounds for its inputs in the plan (bounds: {{in.x: [lo, hi]}})")
            return Outcome("error", msg, self.counts, None, sorted(self.unknown), health=kind)
        except EncodingError as exc:
            return Outcome("error", f"Z3 cannot express the formula: {exc}", self.counts, None, sorted(self.unknown))
        if self.counts.failures:  # only without stop_at_failure: the last violation, not shrunk
            assert self.last_failure is not None
            unconfirmed = self._unconfirmed()
            if unconfirmed is not None:
                return unconfirmed
            return Outcome("failed", f"{self.counts.failures} example(s) violate guarantee {self.guarantee}, e.g. "
                           f"{_example_text(self.last_failure)} (not shrunk)", self.counts, self.last_failure,
                           sorted(self.unknown))
        if self.counts.inconclusive:
            return Outcome("inconclusive", f"no violation, but Z3 answered unknown on {self.counts.inconclusive} "
                           f"example(s) ({', '.join(sorted(self.unknown))})", self.counts, None, sorted(self.unknown))
        inexact = ""
        if self.first_double is not None:
            inexact = (f"; {self.counts.double} check(s) held only in the implementation's IEEE-754 double "
                       f"arithmetic, false as exact rationals (first: {self.first_double[0]} with "
                       f"{self.first_double[1]})")
        return Outcome("discharged", f"all {self.counts.valid} valid example(s) met guarantee {self.guarantee}"
                       + inexact, self.counts, None, [])


def _example_text(cex: Mapping[str, str]) -> str:
    return ", ".join(f"{k} = {v}" for k, v in cex.items() if k.startswith(("in.", "out.", "step")))


def run_guarantee(checked: Checked, node: CheckedNode, guarantee: int, cfg: Config, root: Path,
                  facts: tuple[ast.Expr, ...] = (), impl: Any = None, mapping: str | None = None, *,
                  verdict_only: bool = False) -> Outcome:
    """Run guarantee ``guarantee`` (1-based) of ``node`` on the implementation
    ``impl`` (loaded afresh here when ``None``: :func:`load_implementation`),
    inputs drawn under the assumption and the environment ``facts`` (parsed plan facts)
    at the widths of the fields the mapping file ``mapping`` names (workspace-relative, the
    plan's: :attr:`~rclverify.backends.base.NodeTarget.mapping`; ``None``: the default path;
    :func:`.at_width.carried_in`),
    with the harness's folders first on ``sys.path`` (:func:`.importpath.on_harness_path`).
    ``verdict_only``: only whether it is discharged is asked (:attr:`GuaranteeRun.verdict_only`).

    An import closure (:func:`.closure.resolve_closure`) with an import that
    cannot be followed gives an ``inconclusive`` outcome naming each, with no
    run: code that is not hashed would decide it (docs/property-tests.md,
    "What runs is what is hashed").

    Raises :class:`ConfigError` for an implementation that cannot be loaded.
    """
    unhashed = list(resolve_closure(root, cfg.file).unresolved)
    if unhashed:
        return Outcome("inconclusive", f"{cfg.implementation}: not run, since code it imports would not be hashed "
                       f"with the evidence: {'; '.join(unhashed)}", Counts(), unhashed=unhashed)
    if impl is None:
        impl = load_implementation(root, cfg)
    widths, carried = carried_in(root, node, mapping)
    with on_harness_path(root, cfg.file):
        return GuaranteeRun(checked, at_carried_widths(node, widths, checked.env.constants), guarantee, cfg, impl,
                            facts, widths=widths, carried=carried, verdict_only=verdict_only).run()


def versions() -> str:
    """``hypothesis <v>; z3 <v>`` of this process."""
    return f"hypothesis {hypothesis.__version__}; z3 {z3.get_version_string()}"
