"""FRET's past-time formalisation of a requirement read and stated in RCL with state variables.

FRET formalises each requirement in past-time metric LTL (the export's
``semantics.ptExpanded``): a finite run satisfies the requirement when the
formula holds at its last step.  For the scopes and timings that
:mod:`.translate` does not write by hand, the statement is that formula
itself: every past-time operator is a state variable of the component's
node, named ``fret_<reqid>_pt<k>``, which keeps the operator's value at the
step before (identical subformulas share one), and the statement is
``always F`` with ``F`` written over them:

====================  ==========================================================
FRET                  RCL (``v`` the operator's state variable)
====================  ==========================================================
``Y a``               ``state.v``; ``v``: ``a`` at the step before, FALSE at the first
``Z a``               ``state.v``; as ``Y``, TRUE at the first
``O a`` / ``H a``     ``(a or state.v)`` / ``(a and state.v)``; ``v``: ``O a`` / ``H a``
                      at the step before (FALSE / TRUE at the first)
``a S b``             ``(b or (a and state.v))``; ``v``: ``a S b`` at the step before
``O[0,n] a``          ``(a or state.d <= n)``; ``d``: the steps since ``a`` last held
                      before this one, n + 1 when longer
``O[m,n] a``          ``Y`` taken ``m`` times of ``O[0,n-m] a`` (``O[=n]``: ``[n,n]``,
                      ``O[<n]``: ``[0,n-1]``, ``O[<=n]``: ``[0,n]``; ``O[<0]`` is FALSE)
``H[m,n] a``          ``not O[m,n] (not a)``
====================  ==========================================================

``always F`` has FRET's reading on every finite run exactly when ``F`` is
*prefix-closed* (holding at the end of a run, it holds at the end of each of
the run's prefixes): its verdict is false exactly when ``F`` fails at some
step.  :data:`CLOSED` names the timings for which FRET's formalisation is
prefix-closed, by scope (tests/model/test_fret_differential.py checks each
on random traces against FRET's formulas).  A top-level conjunct ``H a`` is
written ``a`` (``always`` already reads every step).  A window looking back
more than :data:`MAX_SHIFT` steps is refused: it needs a state variable per
step.  Whatever else raises :class:`~.fretish.Refusal`.
"""
from __future__ import annotations

import re
from typing import Callable

from rclverify.model.plan.fret.fretish import _TOKEN, Expr, Refusal, Writer, _Parser

#: The timings whose FRET formalisation is prefix-closed: for the scopes null, in, notin, before and after
#: (``ORDINARY``) and for the scopes onlyIn, onlyBefore and onlyAfter (``ONLY``; there FRET reads the
#: timing of the response's complement outside the interval: always and never become liveness).
ORDINARY = ("immediately", "next", "within", "for", "after", "until", "before", "always", "never")
ONLY = ("immediately", "next", "within", "for", "after", "until", "before", "eventually", "null")
ONLY_SCOPES = ("onlyIn", "onlyBefore", "onlyAfter")
SCOPES = ("null", "in", "notin", "before", "after") + ONLY_SCOPES
CLOSED = {s: ONLY if s in ONLY_SCOPES else ORDINARY for s in SCOPES}
#: The longest look-back of a window ``O[m,n]`` (``m`` steps: ``m`` state variables).
MAX_SHIFT = 32

_WINDOW = re.compile(r"\s*([OH]\[(?:\d+(?:\+\d+)?,\d+(?:\+\d+)?|<=\d+(?:\+\d+)?|<\d+(?:\+\d+)?|=\d+(?:\+\d+)?)\])")
_PAST = ("Y", "Z", "O", "H")


def not_closed(scope: str, timing: str) -> tuple[str, str]:
    """The reason and the fix of a (``scope``, ``timing``) whose FRET formalisation is not prefix-closed."""
    if timing == "finally":
        return ("the timing finally asks the response at the last step of the scope's interval, and of an interval "
                "still open at the end of a run at the run's last step, which no RCL statement names",
                "give the response a timing rclverify translates (immediately, next, within, for, after, until, "
                "before, always, never)")
    if scope in ONLY_SCOPES:
        return (f"with the scope {scope}, FRET reads the timing {timing} as the response's complement eventually "
                "holding in each interval outside the scope, a liveness requirement per interval that RCL's decided "
                "forms do not state", "write it with the scope in, notin, before or after, or bound it (within N ticks)")
    return (f"with the scope {scope}, FRET's timing {timing} asks the response before the scope's interval ends, a "
            "liveness requirement per interval that RCL's decided forms do not state (eventually is stated from the "
            "start of a run only)", "bound it: within N ticks")


def _tokens(text: str) -> list[str]:
    out: list[str] = []
    pos, text = 0, text.rstrip()
    while pos < len(text):
        m = _WINDOW.match(text, pos) or _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            raise Refusal(f"FRET's formalisation has a character rclverify does not read at {text[pos:pos + 10]!r}",
                          "let FRET formalise the requirement again and export it")
        out.append(m.group(1) if m.re is _WINDOW else m.group(m.lastgroup or "op"))
        pos = m.end()
    return out


class _PtParser(_Parser):
    """FRETish extended with FRET's past-time operators: prefix ``Y Z O H`` and the windows ``O[..]``/``H[..]``,
    and ``S`` binding tighter than ``&``."""

    levels = _Parser.levels + (("S",),)

    def unary(self) -> Expr:
        t = self.peek()
        if t in _PAST or t is not None and t[:2] in ("O[", "H["):
            self.take()
            return ("past", t, self.unary())
        return super().unary()


def parse_pt(text: str) -> Expr:
    """The tree of FRET's past-time formula ``text`` (past-time nodes ``("past", op, e)`` and ``("bin", "S",
    a, b)`` beside :func:`.fretish.parse`'s).  Raises :class:`Refusal`."""
    p = _PtParser(text, _tokens(text))
    e = p.level(0)
    if p.peek() is not None:
        raise Refusal(f"FRET's formalisation does not parse (unexpected {p.peek()!r})",
                      "let FRET formalise the requirement again and export it")
    return e


def _window(op: str) -> tuple[int, int]:
    """``O[..]``'s steps back ``(m, n)``: ``[m,n]``, ``[=n]`` is ``(n, n)``, ``[<n]`` ``(0, n - 1)``,
    ``[<=n]`` ``(0, n)``."""
    w = re.sub(r"(\d+)\+(\d+)", lambda m: str(int(m.group(1)) + int(m.group(2))), op[2:-1])
    if "," in w:
        lo, hi = (int(x) for x in w.split(","))
        return lo, hi
    if w.startswith("<="):
        return 0, int(w[2:])
    if w.startswith("<"):
        return 0, int(w[1:]) - 1
    return int(w[1:]), int(w[1:])


class PastTime:
    """The ``temporal`` callback of a :class:`~.fretish.Writer`: each past-time node as a state variable made
    by ``add(role, type, init, next)`` (``@`` its next value, ``$`` its current one; returns its name) of
    ``node``, one per distinct subformula."""

    def __init__(self, add: Callable[[str, str, str, str], str], node: str) -> None:
        self.add, self.node = add, node
        self.writer: Writer | None = None
        self.made: dict[Expr, str] = {}
        self.count = 0

    def _var(self, key: Expr, type_name: str, init: str, nxt: str) -> str:
        if key not in self.made:
            self.count += 1
            self.made[key] = self.add(f"pt{self.count}", type_name, init, nxt)
        return self.made[key]

    def _ref(self, name: str, local: bool) -> str:
        return f"state.{name}" if local else f"{self.node}.state.{name}"

    def __call__(self, e: Expr, local: bool) -> str:
        w = self.writer
        assert w is not None
        if e[0] == "bin":  # a S b
            a, b = e[2], e[3]
            la, lb = w.rcl(a, True), w.rcl(b, True)  # type: ignore[arg-type]
            v = self._var(e, "BOOL", "FALSE", f"@ <=> ({lb} or ({la} and $))")
            return f"({w.rcl(b, local)} or ({w.rcl(a, local)} and {self._ref(v, local)}))"  # type: ignore[arg-type]
        op, a = str(e[1]), e[2]
        assert isinstance(a, tuple)
        if op in _PAST:
            la = w.rcl(a, True)
            init = "FALSE" if op in ("Y", "O") else "TRUE"
            nxt = {"Y": f"@ <=> {la}", "Z": f"@ <=> {la}", "O": f"@ <=> ($ or {la})", "H": f"@ <=> ($ and {la})"}[op]
            ref = self._ref(self._var(e, "BOOL", init, nxt), local)
            return ref if op in ("Y", "Z") else f"({w.rcl(a, local)} {'or' if op == 'O' else 'and'} {ref})"
        lo, hi = _window(op)
        if op[0] == "H":
            return w.rcl(("not", ("past", f"O[{lo},{hi}]", ("not", a))), local)
        if hi < lo:
            return "FALSE"
        if lo > MAX_SHIFT:
            raise Refusal(f"FRET's formalisation looks back {lo} steps (O[{lo},{hi}]), one state variable a step",
                          f"shorten the duration to at most {MAX_SHIFT} steps")
        if lo > 0:
            tree: Expr = ("past", f"O[0,{hi - lo}]", a)
            for _ in range(lo):
                tree = ("past", "Y", tree)
            return w.rcl(tree, local)
        if hi == 0:
            return w.rcl(a, local)
        p = w.rcl(a, True)
        d = self._var(("past", f"O[0,{hi}]", a), "NATURAL", str(hi + 1),
                      f"({p} and @ == 1) or ((not {p}) and $ <= {hi} and @ == $ + 1) or ((not {p}) and $ > {hi} "
                      "and @ == $)")
        return f"({w.rcl(a, local)} or {self._ref(d, local)} <= {hi})"


def statement(pt: Expr, w: Writer) -> str:
    """``always F`` of FRET's formula ``pt`` (module docstring), written by ``w`` (its ``temporal`` a
    :class:`PastTime`); a top-level conjunct ``H a`` is written ``a``."""
    conj: list[Expr] = []

    def split(e: Expr) -> None:
        if e[0] == "bin" and e[1] == "&":
            split(e[2])  # type: ignore[arg-type]
            split(e[3])  # type: ignore[arg-type]
        elif e[0] == "past" and e[1] == "H":
            split(e[2])  # type: ignore[arg-type]
        else:
            conj.append(e)
    split(pt)
    return "always (" + " and ".join(w.rcl(c) for c in conj) + ")"
