"""Gwendolen's reasoning cycle on an explicit, hashable agent state.

Dennis's operational semantics of Gwendolen as AJPF's AIL implements it
(Dennis and Farwer 2008; the MCAPL manual's Gwendolen chapter), one
*agent step* per reasoning cycle; docs/model-checking.md gives each rule and
its source.  The stages, as AIL names them:

A  goals believed achieved are dropped (with their subgoals); an intention
   is selected: the first of the queue (round robin: the one that ran goes
   to the back, behind the intentions created meanwhile);
B  if its top event has no plan yet, the applicable plans are generated:
   trigger unifies with the event, the guard holds against the beliefs
   (and reasoning rules) and goals under that unifier;
C  the first applicable plan in program order is applied (its body, under
   the first answer of the guard, replaces the event's empty row); with no
   applicable plan the event is dropped (a goal too: it fails silently);
D  the top deed of the intention is executed -- one deed per cycle;
E  perception: the environment's percepts become belief additions and
   deletions, each an event in a new intention.

Stage E runs only after the environment reacted to an action (the percepts
change nowhere else); :func:`environment_steps` gives the environment's
choices with the perception each one causes.
"""
from __future__ import annotations

import bisect
from dataclasses import dataclass, replace
from typing import Iterable, Iterator, NamedTuple

from rclverify.backends.model_checking.ajpf import psl
from rclverify.backends.model_checking.environment import Environment
from rclverify.backends.model_checking.gwendolen import MAX_TERM_DEPTH, Deed, Plan, Program, Term, as_psl, located
from rclverify.backends.model_checking.identifiers import ALTERNATE, FRESH, fresh_identifier, numbers
from rclverify.backends.model_checking.unify import Beliefs, BoundReached, Subst, ground, substitute, term_depth, unify


class TermSet(tuple[psl.Term, ...]):
    """Ground terms sorted by text, without repeats: a belief base or a set of
    percepts.  Its frozenset is built once, from its parent's when it is one
    term more or less (CPython keeps each element's hash in the set, so that
    costs one term's hash), and its hash is the frozenset's: a state's hash
    does not walk the terms again."""

    def __new__(cls, items: Iterable[psl.Term] = (), frozen: frozenset[psl.Term] | None = None) -> "TermSet":
        self = super().__new__(cls, items)
        self.__dict__["_f"] = frozen
        return self

    def __hash__(self) -> int:
        return hash(self.frozen())

    def __eq__(self, other: object) -> bool:
        return isinstance(other, TermSet) and self.frozen() == other.frozen()

    def __ne__(self, other: object) -> bool:
        return not self == other

    def frozen(self) -> frozenset[psl.Term]:
        f = self.__dict__["_f"]
        if f is None:
            f = self.__dict__["_f"] = frozenset(self)
        return f  # type: ignore[no-any-return]

    def adding(self, term: psl.Term) -> "TermSet":
        """This set with ``term`` (the same object if it is in already)."""
        if term in self.frozen():
            return self
        items = list(self)
        bisect.insort(items, term, key=psl.term_text)
        return TermSet(items, self.frozen() | {term})

    def removing(self, terms: Iterable[psl.Term]) -> "TermSet":
        """This set without ``terms`` (the same object if none is in it)."""
        gone = {t for t in terms if t in self.frozen()}
        return TermSet((t for t in self if t not in gone), self.frozen() - gone) if gone else self


EMPTY = TermSet()


def _sorted(terms: Iterable[psl.Term]) -> TermSet:
    return TermSet(sorted(set(terms), key=psl.term_text))


@dataclass(frozen=True)
class Event:
    """``+b`` / ``-b`` (``goal_type`` None) or ``+!g [type]`` / ``-!g [type]``; the term is ground."""

    sign: str
    term: psl.Term
    goal_type: str | None = None

    def text(self) -> str:
        t = psl.term_text(self.term)
        return f"{self.sign}!{t} [{self.goal_type}]" if self.goal_type else f"{self.sign}{t}"


@dataclass(frozen=True)
class Frame:
    """One row of an intention: the event, and the deeds still to do for it
    (``None``: no plan chosen yet); ``line`` the line of the plan applied."""

    event: Event
    deeds: tuple[Deed, ...] | None = None
    line: int | None = None


Intention = tuple[Frame, ...]  # bottom .. top


@dataclass(frozen=True)
class AgentState:
    """Everything that decides the future: the canonical, hashable state.

    ``beliefs`` and ``perceived`` (what the agent last perceived) and
    ``percepts`` (the environment's current ones) are sorted by text;
    ``intentions`` the queue, first to run first; ``reactions`` the
    identifier of the environment's last reaction when identifiers
    alternate (0 before the first, then 1, 2, 1, 2 ...; always 0 with fresh
    identifiers: see :mod:`.identifiers`); ``pending`` the action it must
    react to next.
    """

    beliefs: TermSet
    intentions: tuple[Intention, ...] = ()
    last_action: psl.Term | None = None
    perceived: TermSet = EMPTY
    percepts: TermSet = EMPTY
    reactions: int = 0
    pending: psl.Term | None = None


class Step(NamedTuple):
    """One transition: what happened, the source line, the stage, the new state."""

    label: str
    line: int | None
    stage: str
    state: AgentState


def initial_state(program: Program, env: Environment) -> AgentState:
    """Initial beliefs, one intention per initial goal (in order), the initial percepts perceived."""
    intents = tuple((Frame(Event("+", as_psl(g), t)),) for g, t in program.goals)
    state = AgentState(_sorted(as_psl(b) for b in program.beliefs), intents)
    return perceive(state, _sorted(env.initial))


def goals(state: AgentState) -> list[psl.Term]:
    """The agent's goals: the goal events of every intention's rows."""
    return [f.event.term for i in state.intentions for f in i if f.event.goal_type and f.event.sign == "+"]


class Cycle:
    """The reasoning cycle of one program under one environment.

    ``identifiers`` is how reactions get their identifiers
    (:data:`.identifiers.ALTERNATE` or :data:`.identifiers.FRESH`);
    ``avoid`` the numbers a fresh identifier must differ from besides the
    state's (the program's, the environment's and the properties')."""

    def __init__(self, program: Program, env: Environment, identifiers: str = ALTERNATE,
                 avoid: frozenset[float] = frozenset()) -> None:
        self.program = program
        self.env = env
        self.src = program.source
        self.identifiers = identifiers
        self.avoid = avoid

    def beliefs(self, state: AgentState) -> Beliefs:
        return Beliefs(state.beliefs, self.program.rules, self.src)

    # -- successors ---------------------------------------------------------
    def successors(self, state: AgentState) -> list[Step]:
        """The transitions out of ``state``: the environment's choices when it
        must react, else the one agent step (none when the agent has nothing
        to do: a final state)."""
        if state.pending is not None:
            if self.identifiers == FRESH:
                return environment_steps(self.env, state, fresh_identifier(state_numbers(state) | self.avoid))
            return environment_steps(self.env, state)
        step = self.drop_achieved(state)
        if step is not None:
            return [step]
        if not state.intentions:
            return []
        return [self.agent_step(state)]

    def drop_achieved(self, state: AgentState) -> Step | None:
        """Stage A: drop each achievement goal the agent believes (and every row above it)."""
        bel = self.beliefs(state)
        out: list[Intention] = []
        dropped: list[Frame] = []
        for intent in state.intentions:
            for k, f in enumerate(intent):
                if f.event.sign == "+" and f.event.goal_type == "achieve" and bel.holds(f.event.term):
                    dropped.append(f)
                    intent = self.settle(intent[:k], bel)
                    break
            if intent:
                out.append(intent)
        if not dropped:
            return None
        what = ", ".join(f.event.text() for f in dropped)
        return Step(f"goal achieved, dropped: {what}", dropped[0].line, "A",
                    replace(state, intentions=tuple(out)))

    def agent_step(self, state: AgentState) -> Step:
        """Stages A-D on the first intention of the queue."""
        intent, rest = state.intentions[0], state.intentions[1:]
        top = intent[-1]
        posted: list[Intention] = []
        if top.deeds is None:
            found = self.select_plan(state, top.event)
            if found is None:
                intent = self.settle(intent[:-1], self.beliefs(state))
                kind = "goal" if top.event.goal_type else "event"
                label = f"no applicable plan for {kind} {top.event.text()}: dropped"
                return Step(label, None, "B", replace(state, intentions=_requeue(rest, posted, intent)))
            plan, s = found
            body = tuple(self._ground_deed(d, s) for d in plan.body)
            head = f"plan {self.src}:{plan.line} {top.event.text()}"
            intent = intent[:-1] + (Frame(top.event, body, plan.line),)
            if not body:
                intent = self.settle(intent, self.beliefs(state))
                return Step(f"{head}: empty body", plan.line, "C",
                            replace(state, intentions=_requeue(rest, posted, intent)))
            line = plan.line
        else:
            head = f"plan {self.src}:{top.line} {top.event.text()}"
            line = top.deeds[0].line
        state, intent, what = self.execute(state, intent, posted, rest)
        return Step(f"{head}: deed {what}", line, "D", state)

    def select_plan(self, state: AgentState, event: Event) -> tuple[Plan, Subst] | None:
        """Stages B-C: the first plan in program order whose trigger unifies with
        ``event`` and whose guard holds, with the guard's first answer."""
        bel = self.beliefs(state)
        gs = goals(state)
        for plan in self.program.plans:
            t = plan.trigger
            if t.sign != event.sign or t.goal != (event.goal_type is not None):
                continue
            if t.goal and t.goal_type != event.goal_type:
                continue
            s = unify(t.term, event.term, {})
            if s is None:
                continue
            answer = next(self._guard(plan, 0, s, bel, gs), None)
            if answer is not None:
                return plan, answer
        return None

    def _guard(self, plan: Plan, i: int, s: Subst, bel: Beliefs, gs: list[psl.Term]) -> Iterator[Subst]:
        if i == len(plan.guard):
            yield s
            return
        lit = plan.guard[i]
        if lit.kind == "T":
            answers: Iterable[Subst] = [s]
        elif lit.kind == "B":
            assert lit.term is not None
            answers = bel.solve(lit.term, s)
        else:
            query = lit.term
            assert query is not None
            answers = (s2 for g in gs if (s2 := unify(query, g, s)) is not None)
        if lit.positive:
            for s2 in answers:
                yield from self._guard(plan, i + 1, s2, bel, gs)
        elif next(iter(answers), None) is None:
            yield from self._guard(plan, i + 1, s, bel, gs)

    def _ground_deed(self, deed: Deed, s: Subst) -> Deed:
        if deed.kind == "-b":  # a deletion may keep '_' and unbound variables: it deletes every match
            term = substitute(deed.term, s)
            if term_depth(term) > MAX_TERM_DEPTH:
                raise BoundReached(f"term depth > {MAX_TERM_DEPTH}")
            return replace(deed, term=term)
        return replace(deed, term=ground(deed.term, s, self.src, deed.line, deed.col, f"deed {deed.text()}"))

    # -- stage D ------------------------------------------------------------
    def execute(self, state: AgentState, intent: Intention, posted: list[Intention],
                rest: tuple[Intention, ...]) -> tuple[AgentState, Intention, str]:
        """Execute the top deed of ``intent`` (the selected intention)."""
        top = intent[-1]
        assert top.deeds
        deed, remaining = top.deeds[0], top.deeds[1:]
        intent = intent[:-1] + (replace(top, deeds=remaining),)
        term = as_psl(deed.term)  # ground, but for '_' and unbound variables in a deletion
        beliefs = state.beliefs
        last, pending = state.last_action, None
        if deed.kind == "+b":
            _no_wild(term, deed, self.src)
            if term not in beliefs:
                beliefs = beliefs.adding(term)
                posted.append((Frame(Event("+", term)),))
        elif deed.kind == "-b":
            gone = [b for b in beliefs if unify(term, b, {}) is not None]
            beliefs = beliefs.removing(gone)
            posted.extend((Frame(Event("-", b)),) for b in gone)
        elif deed.kind == "+!":
            _no_wild(term, deed, self.src)
            intent = intent + (Frame(Event("+", term, deed.goal_type)),)
        elif deed.kind == "-!":
            bel = self.beliefs(replace(state, beliefs=beliefs))
            rest = tuple(i for i in (self._drop_goal(i, term, deed.goal_type, bel) for i in rest) if i)
            intent = self._drop_goal(intent, term, deed.goal_type, bel)
            posted.append((Frame(Event("-", term, deed.goal_type)),))
        else:
            _no_wild(term, deed, self.src)
            last = term
            if self.env.reacts_to(term):
                pending = term
        new = replace(state, beliefs=beliefs, last_action=last, pending=pending)
        intent = self.settle(intent, self.beliefs(new))
        return replace(new, intentions=_requeue(rest, posted, intent)), intent, deed.text()

    def _drop_goal(self, intent: Intention, term: Term, goal_type: str | None, bel: Beliefs) -> Intention:
        for k, f in enumerate(intent):
            if f.event.sign == "+" and f.event.goal_type == goal_type and unify(term, f.event.term, {}) is not None:
                return self.settle(intent[:k], bel)
        return intent

    def settle(self, intent: Intention, bel: Beliefs) -> Intention:
        """Pop finished rows: a row with no deeds left is done; a finished
        achievement goal the agent does not believe yet is planned again
        (its row loses its plan), a finished perform goal is dropped."""
        while intent and intent[-1].deeds == ():
            top = intent[-1]
            if top.event.sign == "+" and top.event.goal_type == "achieve" and not bel.holds(top.event.term):
                return intent[:-1] + (Frame(top.event),)
            intent = intent[:-1]
        return intent


def _requeue(rest: tuple[Intention, ...], posted: list[Intention], current: Intention) -> tuple[Intention, ...]:
    """Round robin: the others, then the intentions created in this cycle, then the one that ran."""
    return rest + tuple(posted) + ((current,) if current else ())


def _no_wild(term: Term, deed: Deed, src: str) -> None:
    if _wild(term):
        raise located(src, deed.line, deed.col, f"'_' in deed {deed.text()}: only a belief deletion may use it")


def _wild(t: Term) -> bool:
    return isinstance(t, psl.Wild) or (isinstance(t, psl.Compound) and any(_wild(a) for a in t.args))


def perceive(state: AgentState, percepts: TermSet) -> AgentState:
    """Stage E: percepts gone are deleted from the beliefs (``-p`` events),
    new percepts added (``+p`` events), each event a new intention at the
    back of the queue (deletions first, each group in canonical order)."""
    beliefs = state.beliefs
    new_intents: list[Intention] = []
    gone = [p for p in state.perceived if p not in percepts and p in beliefs]
    beliefs = beliefs.removing(gone)
    new_intents.extend((Frame(Event("-", p)),) for p in gone)
    for p in percepts:
        if p not in state.perceived and p not in beliefs:
            beliefs = beliefs.adding(p)
            new_intents.append((Frame(Event("+", p)),))
    return replace(state, beliefs=beliefs, perceived=percepts, percepts=percepts,
                   intentions=state.intentions + tuple(new_intents))


def state_numbers(state: AgentState) -> set[float]:
    """Every number in ``state``'s terms (beliefs, percepts, intentions, actions)."""
    terms: list[Term | None] = [*state.beliefs, *state.perceived, *state.percepts, state.last_action, state.pending]
    for intent in state.intentions:
        for f in intent:
            terms.append(f.event.term)
            terms.extend(d.term for d in f.deeds or ())
    return numbers(terms)


def environment_steps(env: Environment, state: AgentState, fresh: int | None = None) -> list[Step]:
    """The environment's reaction to ``state.pending``: one step per choice,
    each followed by the agent's perception (stage E).  ``_`` in a percept is
    ``fresh`` when given, else 1 and 2 alternately (:mod:`.identifiers`)."""
    n = fresh if fresh is not None else 2 if state.reactions == 1 else 1
    kept = 0 if fresh is not None else n
    action = psl.term_text(state.pending) if state.pending is not None else "?"
    out = []
    for choice in env.choices(n):
        chosen = _sorted(choice)
        what = ", ".join(psl.term_text(p) for p in chosen) if chosen else "nothing"
        base = replace(state, reactions=kept, pending=None)
        out.append(Step(f"environment after {action}: asserts {what}", None, "env", perceive(base, chosen)))
    return out
