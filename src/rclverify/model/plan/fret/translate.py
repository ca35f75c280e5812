"""One FRET requirement translated to an RCL temporal statement and the state variables it needs.

FRET gives each requirement a scope, a condition and a timing (FRET's
field guide; the requirement's ``semantics``: ``scope.type``,
``condition``, ``timing``).  Each combination below is translated to one
of the decided shapes of :func:`rclverify.model.plan.temporal.shape`, its
reading on finite traces equal to FRET's past-time formalisation
(``ptExpanded``: a trace satisfies the requirement when the formula holds
at its last step; tests/model/test_fret_differential.py compares the two on
random traces).  ``P`` is the condition, ``Q`` the response, ``S`` the
stop condition, ``N`` the duration in steps, ``M`` the mode; ``prev``,
``since``, ``on`` and ``t`` are state variables of the component's node,
named ``fret_<reqid>_<role>``:

==============================  ================================================  ==========================
scope, condition, timing        RCL                                               state
==============================  ================================================  ==========================
null, null, always / never      ``always Q`` / ``always not Q``
null, null, immediately         ``eventually[<= 0] Q`` (Q at the first step)
null, null, next                ``next Q`` (Q at the second step)
null, null, eventually (none)   ``eventually Q``
null, null, within N            ``eventually[<= N] Q``
null, null, for N               ``always (state.t <= N -> Q)``                    ``t``: the step, capped at N + 1
null, null, until S             ``always ((not S and not state.stopped) -> Q)``   ``stopped``: S held before
null, null, before S            ``always (S -> state.held)``                      ``held``: Q held before
null, C, immediately            ``always (T -> Q)``                               (``prev``)
null, C, next                   ``always (T -> next Q)``                          (``prev``)
null, C, within N               ``always (T -> eventually[<= N] Q)``              (``prev``)
null, C, eventually (none)      ``always (T -> eventually Q)``                    (``prev``)
null, C, for N                  ``always ((T or state.ago <= N) -> Q)``           (``prev``), ``ago``: steps
                                                                                  since T, capped at N + 1
null, C, always / never         ``always ((P or state.since) -> Q)`` / ``not Q``  ``since``: P held before
null, C, until S                ``always ((not S and (T or state.on)) -> Q)``     (``prev``), ``on``
in M, null, always / never      ``always (M -> Q)`` / ``always (M -> (not Q))``
in M, null, immediately         ``always ((M and not state.prev) -> Q)``          ``prev`` of M
==============================  ================================================  ==========================

C is a condition: FRET's ``regular`` ("upon", "when", "if": the trigger
``T`` is ``P and not state.prev``, P becoming true or true at the first
step, ``prev`` holding P of the step before) or ``holding``/``noTrigger``
("whenever": ``T`` is P, no ``prev``).  ``on`` holds "a trigger came and S
has not held since" of the step before.  FRET's functions inside P, Q, S
and M are :mod:`.fretish`'s (``preBool`` and the other ``pre`` functions,
``persisted`` and ``occurred``, each a state variable
``fret_<reqid>_<function><k>``).  A window cut short by the end of a
finite run is FRET's "need not hold": ``next`` and ``eventually[<= N]``
are not violated by a trace that ends first.  One difference is named: an
unbounded ``eventually`` on a finite trace that ends before its response is
FRET's false (``O Q`` at the end) and rclverify's ``currently_false`` (a
longer run may reach it); over infinite runs, what rclverify proves, both
are FRET's ``F Q`` (``ftInfAUExpanded``).  A combination not in the table is
stated from the export's own past-time formalisation when it is prefix-closed
(:mod:`.pasttime`: the other scopes, the timings after and before, a
trigger inside a mode); whatever else raises :class:`~.fretish.Refusal`
naming it.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Callable, Mapping, Sequence

from rclverify.model.plan.fret.declared import DeclaredFunction
from rclverify.model.plan.fret.export import FretSemantics
from rclverify.model.plan.fret.fretish import Expr, Refusal, Writer, parse
from rclverify.model.plan.fret.pasttime import CLOSED, PastTime, not_closed, parse_pt, statement

#: The timings translated for each (scope, condition) (module table).
_CONDITIONED = ("immediately", "next", "within", "for", "eventually", "null", "always", "never", "until")
SUPPORTED = {
    ("null", "null"): ("always", "never", "immediately", "next", "within", "for", "eventually", "null", "until",
                       "before"),
    ("null", "holding"): _CONDITIONED, ("null", "noTrigger"): _CONDITIONED, ("null", "regular"): _CONDITIONED,
    ("in", "null"): ("always", "never", "immediately"),
}
_UNITS = re.compile(r"\b(?:within|for|after|before)\s+(\d+(?:\.\d+)?)\s*([A-Za-z]+)")


@dataclass(frozen=True)
class NewState:
    """A state variable the statement reads: ``name`` of ``type_name``,
    ``init``/``next`` RCL formulas over ``state.v``/``next.v``/``in.x``/``out.y``."""

    name: str
    type_name: str
    init: str
    next: str


@dataclass
class Translation:
    """A requirement's RCL ``formal`` and the ``states`` it declares on ``node``."""

    formal: str
    node: str
    states: list[NewState] = field(default_factory=list)


def state_base(reqid: str) -> str:
    """The prefix of the state variables made for requirement ``reqid``: ``fret_`` and its id with every
    character that is not a letter, digit or ``_`` as ``_``."""
    return "fret_" + re.sub(r"[^A-Za-z0-9_]", "_", reqid)


def steps_of(sem: FretSemantics, fulltext: str, step: Fraction | None) -> int:
    """The duration of a ``within``/``for`` timing in steps: ``ticks`` as written; another unit of
    time through ``step`` (the plan's ``fret: step:``, seconds per step), when it divides exactly.
    Raises :class:`Refusal`."""
    raw = _duration(sem)
    try:
        n = Fraction(str(raw))
    except (ValueError, ZeroDivisionError):
        raise Refusal(f"its duration {raw!r} is not a number", "give the timing a number of ticks") from None
    m = _UNITS.search(fulltext)
    unit = m.group(2).lower() if m else "ticks"
    if unit.startswith("tick"):
        count = n
    else:
        from rclverify.lang.timing import parse_duration  # deferred: start-up (only a duration in seconds)
        secs = parse_duration(f"{n} {_UNIT_NAMES.get(unit, unit)}")
        if secs is None:
            raise Refusal(f"its duration is in {unit!r}, not a unit of time rclverify reads",
                          "write the duration in ticks or secs")
        if step is None:
            raise Refusal(f"its duration is {m.group(1) if m else n} {unit}, and the plan declares no step period",
                          "declare the step period in the plan (fret: {step: 100 ms}) or write the duration in ticks")
        count = secs / step
    if count.denominator != 1 or count < 0:
        raise Refusal(f"its duration is not a whole number of steps ({count})",
                      "write a duration that is a whole number of steps")
    return int(count)


_UNIT_NAMES = {"sec": "s", "secs": "s", "second": "s", "seconds": "s", "msec": "ms", "msecs": "ms",
               "millisecond": "ms", "milliseconds": "ms", "min": "min", "mins": "min", "minute": "min",
               "minutes": "min", "hour": "h", "hours": "h", "usec": "us", "usecs": "us"}


#: The step counter of a Lustre table (:mod:`.lustre`): the steps since the first, stopping at a bound.
_STEP_BOUND = "\x01bound\x01"
_STEP = f"($ < {_STEP_BOUND} and @ == $ + 1) or ($ >= {_STEP_BOUND} and @ == $)"


class _States:
    """The state variables of one requirement, made as the writer asks."""

    def __init__(self, base: str) -> None:
        self.base = base
        self.made: list[NewState] = []
        #: The last step a Lustre table of the requirement tells apart (its step counter stops there).
        self.bound = 0
        #: the plan's ``fret: functions:`` (:mod:`.declared`), by name
        self.functions: Mapping[str, DeclaredFunction] = {}
        #: the node's inputs another node publishes (:func:`translate`)
        self.fed: tuple[str, ...] = ()

    def finish(self, t: Translation) -> Translation:
        """``t`` with its step counter (if a Lustre table made one) stopping at :attr:`bound`."""
        t.states = [NewState(x.name, x.type_name, x.init, x.next.replace(_STEP_BOUND, str(self.bound)))
                    for x in t.states]
        return t

    def add(self, role: str, type_name: str, init: str, nxt: str) -> str:
        """Declare ``fret_<reqid>_<role>``; in ``nxt`` ``@`` is its next value, ``$`` its current one."""
        name = f"{self.base}_{role}"
        self.made.append(NewState(name, type_name, f"state.{name} == {init}" if type_name != "BOOL"
                                  else f"state.{name} <=> {init}",
                                  nxt.replace("@", f"next.{name}").replace("$", f"state.{name}")))
        return name


def translate(reqid: str, fulltext: str, sem: FretSemantics, node: str,
              var: Callable[[str, bool], str | Expr], step: Fraction | None = None,
              functions: Mapping[str, DeclaredFunction] | None = None, fed: Sequence[str] = ()) -> Translation:
    """Requirement ``reqid`` (``semantics`` ``sem``, FRET's export fields) as
    an RCL statement over ``node`` (module table).  ``var(name, local)``
    places a variable (:class:`~.fretish.Writer`); ``step`` the plan's
    seconds per step for durations in seconds; ``functions`` the plan's
    ``fret: functions:`` (:mod:`.declared`); ``fed`` the node's inputs
    another node publishes, whose first values are FRET's first time point
    (:func:`_writer`).  Raises :class:`Refusal`."""
    states = _States(state_base(reqid))
    states.functions = functions or {}
    states.fed = tuple(fed)
    t = states.finish(_translate(fulltext, sem, node, var, step, states))
    if any(_LOCAL_FTP in s.init or _LOCAL_FTP in s.next for s in t.states):
        raise Refusal(f"FRET's first time point is read inside a pre on {node}, which another node feeds: its "
                      "state variables step with the system, whose first step is not the node's",
                      "write the -> (or the initial value) outside the pre")
    return t


#: FRET's first time point placed inside a state variable of a node another node feeds (refused, :func:`translate`)
_LOCAL_FTP = "\x00first time point\x00"


def _duration(sem: FretSemantics) -> str | int | float | list[str | int | float] | None:
    """The ``duration`` of ``sem``: its first item when FRET wrote a list."""
    raw = sem.duration
    return raw[0] if isinstance(raw, list) and raw else raw


def _translate(fulltext: str, sem: FretSemantics, node: str, var: Callable[[str, bool], str | Expr],
               step: Fraction | None, states: _States) -> Translation:
    scope = sem.scope.type if sem.scope is not None else "null"
    cond, timing = sem.condition or "null", sem.timing or "null"
    if (sem.response or "satisfaction") != "satisfaction":
        raise Refusal(f"its response is {sem.response!r}", "write the response as 'satisfy'")
    if timing not in SUPPORTED.get((scope, cond), ()):
        return _compiled(scope, timing, fulltext, sem, node, var, step, states)
    w = _writer(var, states, node)

    def field_expr(key: str, *values: str | None) -> Expr:
        """The first of ``values`` written (``key`` the first one's name, for the refusal), parsed."""
        for v in values:
            if v is not None and v.strip():
                return parse(v)
        raise Refusal(f"its semantics has no {key}", "let FRET formalise the requirement again and export it")

    q_tree = field_expr("post_condition", sem.post_condition)
    q = w.rcl(q_tree)
    made = states.made
    if scope == "in":
        mode = sem.scope_mode
        if mode is None or not mode.strip():
            raise Refusal("its scope 'in' names no mode", "name the mode in FRET")
        m = parse(mode)
        if timing == "always":
            return Translation(f"always ({w.rcl(m)} -> {q})", node, made)
        if timing == "never":
            return Translation(f"always ({w.rcl(m)} -> (not {q}))", node, made)
        prev = states.add("prev", "BOOL", "FALSE", f"@ <=> {w.rcl(m, True)}")
        return Translation(f"always (({w.rcl(m)} and not {node}.state.{prev}) -> {q})", node, made)
    if cond == "null":
        return _unconditional(timing, q, q_tree, w, states, node, lambda: steps_of(sem, fulltext, step),
                              lambda: field_expr("stop_condition", sem.stop_condition))
    p_tree = field_expr("regular_condition", sem.regular_condition, sem.pre_condition)
    return _conditioned(cond, timing, p_tree, q, w, states, node, lambda: steps_of(sem, fulltext, step),
                        lambda: field_expr("stop_condition", sem.stop_condition))


def _compiled(scope: str, timing: str, fulltext: str, sem: FretSemantics, node: str,
              var: Callable[[str, bool], str | Expr], step: Fraction | None, states: _States) -> Translation:
    """A combination the module table does not write: FRET's own ``ptExpanded`` stated with state variables
    (:mod:`.pasttime`) when it is prefix-closed, else refused with the reason."""
    if scope not in CLOSED:
        raise Refusal(f"its scope {scope} is not one of FRET's scopes rclverify reads",
                      f"write it with one of the scopes {', '.join(CLOSED)}")
    if timing not in CLOSED[scope]:
        raise Refusal(*not_closed(scope, timing))
    pt = sem.ptExpanded
    if pt is None or not pt.strip():
        raise Refusal("its export has no past-time formalisation (semantics.ptExpanded), which rclverify states for "
                      f"the scope {scope} with the timing {timing}", "export the requirement again from FRET")
    raw = _duration(sem)
    if raw not in (None, "") and (m := _UNITS.search(fulltext)) and not m.group(2).lower().startswith("tick"):
        n = steps_of(sem, fulltext, step)
        if Fraction(str(raw)) != n:
            raise Refusal(f"FRET's formalisation counts its duration {raw} {m.group(2)} as {raw} steps, and the plan's "
                          f"step period makes it {n}", "write the duration in ticks")
    w = _writer(var, states, node)
    past = PastTime(states.add, node)
    w.temporal, past.writer = past, w
    return Translation(statement(parse_pt(pt), w), node, states.made)


def _unconditional(timing: str, q: str, q_tree: Expr, w: Writer, states: _States, node: str,
                   steps: Callable[[], int], stop: Callable[[], Expr]) -> Translation:
    """The null condition's timings (module table)."""
    made = states.made
    if timing == "always":
        return Translation(f"always {q}", node, made)
    if timing == "never":
        return Translation(f"always (not {q})", node, made)
    if timing in ("eventually", "null"):  # FRET's default timing is eventually
        return Translation(f"eventually {q}", node, made)
    if timing == "immediately":
        return Translation(f"eventually[<= 0] {q}", node, made)
    if timing == "next":
        return Translation(f"next {q}", node, made)
    if timing in ("until", "before"):
        s_tree = stop()
        s, s_local = w.rcl(s_tree), w.rcl(s_tree, True)
        if timing == "until":  # Q until S first holds (FRET: H (H !S -> Q))
            seen = states.add("stopped", "BOOL", "FALSE", f"@ <=> ($ or {s_local})")
            return Translation(f"always (((not {s}) and not {node}.state.{seen}) -> {q})", node, made)
        held = states.add("held", "BOOL", "FALSE", f"@ <=> ($ or {w.rcl(q_tree, True)})")  # FRET: H (S -> Y O Q)
        return Translation(f"always ({s} -> {node}.state.{held})", node, made)
    n = steps()
    if timing == "within":
        return Translation(f"eventually[<= {n}] {q}", node, made)
    t = states.add("t", "NATURAL", "0", f"($ <= {n} and @ == $ + 1) or ($ > {n} and @ == $)")
    return Translation(f"always ({node}.state.{t} <= {n} -> {q})", node, made)


def _writer(var: Callable[[str, bool], str | Expr], states: _States, node: str) -> Writer:
    """The :class:`~.fretish.Writer` of one requirement: its ``pre``, ``persisted``/``occurred`` and
    ``FTP`` state variables declared in ``states`` as the expressions ask for them."""

    pending: dict[str, str] = {}
    done: dict[str, str] = {}

    def pre(type_name: str, init: Expr, e: Expr) -> str:
        key = repr((type_name, init, e))
        if key in done:  # the same pre read twice: one state variable
            return done[key]
        if key in pending:  # a pre of the variable being defined: its own value of the step before
            return pending[key]
        mark = pending[key] = f"\x00{len(states.made)}.{len(pending)}\x00"
        init_text = w.rcl(init, True)
        body = w.rcl(("bin", "<=>" if type_name == "BOOL" else "=", ("text", "@"), e), True)  # inner pres first
        del pending[key]
        body = body[1:-1] if body.startswith("(@ ") and body.endswith(")") else body
        name = states.add(f"pre{len(states.made) + 1}", type_name, init_text, body)
        if any(mark in x.next for x in states.made):
            states.made[:] = [NewState(x.name, x.type_name, x.init, x.next.replace(mark, name)) for x in states.made]
        done[key] = name
        return name

    def table(length: int, local: bool) -> str:
        states.bound = max(states.bound, length - 1)
        name = f"{states.base}_step"
        if not any(x.name == name for x in states.made):
            states.add("step", "NATURAL", "0", _STEP)
        return f"state.{name}" if local else f"{node}.state.{name}"

    def count(kind: str, n: int, e: Expr) -> str:
        p = w.rcl(e, True)
        role = f"{kind}{len(states.made) + 1}"
        if kind == "persisted":
            return states.add(role, "NATURAL", "0", f"({p} and $ < {n} and @ == $ + 1) or ({p} and $ >= {n} and "
                                                     f"@ == $) or ((not {p}) and @ == 0)")
        return states.add(role, "NATURAL", str(n + 1), f"({p} and @ == 1) or ((not {p}) and $ <= {n} and "
                                                       f"@ == $ + 1) or ((not {p}) and $ > {n} and @ == $)")

    def placed(name: str, local: bool) -> str | Expr:
        if name != "FTP":
            return var(name, local)
        if states.fed:  # the node's first step is where its inputs first have values (docs/requirements.md)
            if local:  # refused if a state variable's next value reads it (:func:`translate`)
                return _LOCAL_FTP
            return "(" + " or ".join(f"first({node}.in.{x})" for x in states.fed) + ")"
        ftp = next((x.name for x in states.made if x.name == f"{states.base}_ftp"), None) or \
            states.add("ftp", "BOOL", "TRUE", "not @")  # FRET's first time point
        return f"state.{ftp}" if local else f"{node}.state.{ftp}"
    w = Writer(placed, pre, node, count, table=table, functions=states.functions)
    return w


def _conditioned(cond: str, timing: str, p_tree: Expr, q: str, w: Writer, states: _States, node: str,
                 steps: Callable[[], int], stop: Callable[[], Expr]) -> Translation:
    """A condition's timings (module table)."""
    made = states.made
    p, p_local = w.rcl(p_tree), w.rcl(p_tree, True)
    if timing in ("always", "never"):  # from the first step P held on (FRET: H (H !P | Q))
        since = states.add("since", "BOOL", "FALSE", f"@ <=> ($ or {p_local})")
        return Translation(f"always (({p} or {node}.state.{since}) -> {q if timing == 'always' else f'(not {q})'})",
                           node, made)
    trig, trig_local = f"({p})", f"({p_local})"
    if cond == "regular":  # FRET's "upon": P becoming true, or true at the first step
        prev = states.add("prev", "BOOL", "FALSE", f"@ <=> {p_local}")
        trig, trig_local = f"({p} and not {node}.state.{prev})", f"({p_local} and not state.{prev})"
    if timing == "immediately":
        return Translation(f"always ({trig} -> {q})", node, made)
    if timing == "next":
        return Translation(f"always ({trig} -> next {q})", node, made)
    if timing in ("eventually", "null"):
        return Translation(f"always ({trig} -> eventually {q})", node, made)
    if timing in ("within", "for"):
        n = steps()
        if timing == "within":
            return Translation(f"always ({trig} -> eventually[<= {n}] {q})", node, made)
        d = states.add("ago", "NATURAL", str(n + 1), f"({trig_local} and @ == 1) or ((not {trig_local}) and "
                                                     f"$ <= {n} and @ == $ + 1) or ((not {trig_local}) and $ > {n} "
                                                     "and @ == $)")
        return Translation(f"always (({trig} or {node}.state.{d} <= {n}) -> {q})", node, made)
    s_tree = stop()
    s, s_local = w.rcl(s_tree), w.rcl(s_tree, True)
    on = states.add("on", "BOOL", "FALSE", f"@ <=> ((not {s_local}) and ({trig_local} or $))")
    return Translation(f"always (((not {s}) and ({trig} or {node}.state.{on})) -> {q})", node, made)
