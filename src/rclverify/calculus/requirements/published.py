"""Published values in the composed transition system.

docs/semantics.md, "Temporal requirements": the temporal checker reads the
stream model every monitor reads.  A topic holds no value until its first
message, so in the transition system of :mod:`.transition`:

* every node that answers has a flag ``Node.published``: false at step 0
  unless the node answers there or declares ``initially(...)`` (a value from
  the start), and once true it stays true (outputs persist, rule R3);
* every input fed by another node of the cone has a flag
  ``Consumer.heard.x``: false at step 0 (the producer published nothing
  before the run) and, at each later step, whether the producer had
  published at the step before (the connection carries the previous
  element);
* a node answers only when every fed input its contract reads has been
  heard (its question exists): ``answers -> ready``; its progress
  (``progress(...)`` and fairness) is owed only then;
* every input a ``first(...)`` of the statement or the cone's contracts
  reads has a flag ``Consumer.first.x`` (docs/semantics.md, "The first
  published value"): for an input another node of the cone feeds, false at
  step 0 and, at each later step, whether the input is heard now and was
  not at the step before (the producer's first published value arrives);
  for an input of the environment, which gives a value at every step, true
  at step 0 only;
* a requirement's state formula is evaluated only on published values: the
  flags of the outputs and fed inputs it reads (:meth:`Publication.defined`)
  guard it, as ``defined -> F`` under ``always`` and ``defined and F``
  under ``eventually`` and ``next``.

Without this a consumer's input before its producer's first answer was any
value of its type "from before the run", and ``always Motor.out.w <= 1.5``
of a correct chain was refuted at step 0 on a value no node published.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Iterable, Mapping, Sequence

import z3

from rclverify.semantics.connectives import conj, disj

State = Any


@dataclass
class Publication:
    """The flags of one composed system.

    ``published`` node -> its flag's variable name; ``heard`` consumer input
    (``C.in.x``) -> its flag's name; ``producer`` consumer input -> producer
    node; ``fed`` node -> the heard flags of the fed inputs its contract
    reads; ``initial`` the nodes that declare ``initially``; ``first`` consumer
    input -> its ``first(...)`` flag's name (only the inputs a ``first``
    reads)."""

    published: dict[str, str] = field(default_factory=dict)
    heard: dict[str, str] = field(default_factory=dict)
    producer: dict[str, str] = field(default_factory=dict)
    fed: dict[str, list[str]] = field(default_factory=dict)
    initial: frozenset[str] = frozenset()
    first: dict[str, str] = field(default_factory=dict)

    def variables(self) -> Iterable[tuple[str, tuple[str, str, str]]]:
        """``(flag name, (node, "run", what))`` for every flag."""
        for n, name in self.published.items():
            yield name, (n, "run", "published")
        for c, name in self.heard.items():
            node, _, var = c.split(".", 2)
            yield name, (node, "run", f"heard.{var}")
        for c, name in self.first.items():
            node, _, var = c.split(".", 2)
            yield name, (node, "run", f"first.{var}")

    def ready(self, n: str, s: State) -> z3.BoolRef:
        """Every fed input node ``n`` reads has been heard in state ``s``."""
        flags = [s[f] for f in self.fed.get(n, ())]
        return conj(*flags) if flags else z3.BoolVal(True)

    def init(self, s: State, answers: Callable[[str, State], z3.BoolRef]) -> z3.BoolRef:
        """Step 0: published iff the node answers there or declares ``initially``; nothing heard."""
        parts = [s[f] == (z3.BoolVal(True) if n in self.initial else answers(n, s))
                 for n, f in self.published.items()]
        parts += [z3.Not(s[f]) for f in self.heard.values()]
        parts += [s[f] == z3.BoolVal(c not in self.heard) for c, f in self.first.items()]
        return conj(*parts) if parts else z3.BoolVal(True)

    def trans(self, s: State, t: State, answers: Callable[[str, State], z3.BoolRef]) -> z3.BoolRef:
        """One step: published stays published and becomes so by an answer;
        an input is heard when its producer had published at the step before."""
        parts = [t[f] == disj(s[f], answers(n, t)) for n, f in self.published.items()]
        parts += [t[f] == s[self.published[self.producer[c]]] for c, f in self.heard.items()]
        parts += [t[f] == (conj(s[self.published[self.producer[c]]], z3.Not(s[self.heard[c]])) if c in self.heard
                           else z3.BoolVal(False)) for c, f in self.first.items()]
        return conj(*parts) if parts else z3.BoolVal(True)

    def defined(self, mentions: Iterable[tuple[str, str, str]], s: State) -> z3.BoolRef:
        """The values a statement mentions (``(node, "in"|"out"|"state", var)``)
        all published in ``s``: each output's node has published, each fed input
        has been heard; environment inputs and state variables always have one."""
        flags = self.flags_of(mentions)
        return conj(*[s[f] for f in flags]) if flags else z3.BoolVal(True)

    def silent(self) -> list[str]:
        """The answering nodes that publish on no run, in :attr:`published`'s order.

        A node publishes at some step only if it declares ``initially`` or
        answers, and it answers only once every fed input it reads was heard,
        that is once each producer of those inputs had published (module
        docstring).  The nodes that can publish are the least set holding
        every node with ``initially`` or with no fed input it reads, and
        every node whose fed inputs' producers are all in it; the rest never
        publish, whatever the contracts say (each has a silent producer, so
        following producers ends in a loop of nodes each waiting on another
        and none declaring an initial value).  The set is decided on the
        connections alone: a node outside it may still never publish (its
        assumption never holding), which only a query over the runs shows."""
        by_flag = {f: self.producer[c] for c, f in self.heard.items()}
        can = {n for n in self.published if n in self.initial or not self.fed.get(n)}
        grew = True
        while grew:
            more = {n for n in self.published if n not in can and all(by_flag[f] in can for f in self.fed.get(n, ()))}
            can |= more
            grew = bool(more)
        return [n for n in self.published if n not in can]

    def flags_of(self, mentions: Iterable[tuple[str, str, str]]) -> list[str]:
        """The flag names :meth:`defined` reads, for a trace's confirmation."""
        out: list[str] = []
        for n, kind, var in mentions:
            name = (self.published.get(n) if kind == "out" else
                    self.heard.get(f"{n}.in.{var}") if kind == "in" else None)
            if name is not None and name not in out:
                out.append(name)
        return out


def publication(answering: Sequence[str], links: Sequence[tuple[str, str]], reads: Mapping[str, set[str]],
                initial: Iterable[str]) -> Publication:
    """The flags of a system whose answering nodes are ``answering``,
    connections ``links`` (``(C.in.x, P.out.y)``), ``reads`` node -> the input
    names its contract reads, ``initial`` the nodes with ``initially``."""
    pub = Publication(initial=frozenset(initial))
    for n in answering:
        pub.published[n] = f"{n}.published"
    for c, p in links:
        node, _, var = c.split(".", 2)
        producer = p.split(".", 1)[0]
        if producer not in pub.published:
            continue
        flag = f"{node}.heard.{var}"
        pub.heard[c], pub.producer[c] = flag, producer
        if var in reads.get(node, set()):
            pub.fed.setdefault(node, []).append(flag)
    return pub


def first_inputs(exprs: Iterable[Any], node: str | None = None) -> list[str]:
    """The inputs ``C.in.x`` the ``first(...)`` terms of ``exprs`` read, in
    order: a requirement's ``first(C.in.x)`` names its input whole; a
    contract's ``first(in.x)`` is ``node``'s."""
    from rclverify.lang import ast, walk  # deferred: the flags need the syntax only where a formula is read
    out: dict[str, None] = {}
    for e in exprs:
        for x in walk.subexpressions(e):
            if isinstance(x, ast.First):
                out.setdefault(x.arg.name if node is None else f"{node}.in.{x.arg.name}", None)
    return list(out)


def confirm_flags(trace: Sequence[Mapping[str, Any]], pub: Publication, answers: Callable[[Mapping[str, Any], str], bool]
                  ) -> str | None:
    """The flags of a lasso's trace follow the rules (module docstring), or
    the first step where they do not (one sentence); ``answers(state, n)``
    whether node ``n`` answers in that state."""
    for i, st in enumerate(trace):
        for n, f in pub.published.items():
            want = (n in pub.initial or answers(st, n)) if i == 0 else (trace[i - 1][f] is True or answers(st, n))
            if st.get(f) is not want:
                return f"step {i}: {f} is {st.get(f)}, not {want}"
        for c, f in pub.heard.items():
            want = False if i == 0 else trace[i - 1][pub.published[pub.producer[c]]] is True
            if st.get(f) is not want:
                return f"step {i}: {f} is {st.get(f)}, not {want}"
        for c, f in pub.first.items():
            want = (c not in pub.heard) if i == 0 else (
                c in pub.heard and st.get(pub.heard[c]) is True and trace[i - 1].get(pub.heard[c]) is not True)
            if st.get(f) is not want:
                return f"step {i}: {f} is {st.get(f)}, not {want}"
        for n, flags in pub.fed.items():
            if answers(st, n) and not all(st.get(f) is True for f in flags):
                return f"step {i}: {n} answers before every input it reads was published"
    return None


__all__ = ["Publication", "confirm_flags", "first_inputs", "publication"]
