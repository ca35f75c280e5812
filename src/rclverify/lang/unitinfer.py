"""Units inferred through equations and connections (docs/rcl-language.md, "Inferred units").

An output without a declared unit takes the unit its node's contract gives
it, so that the connection it feeds can be checked
(:mod:`rclverify.model.system.units`): the driver's ``out.heading == in.cog``
with ``cog : REAL [deg]`` publishes degrees, whatever the localiser that
reads ``heading : REAL [rad]`` assumes.

The rules (each *source* gives a variable without a declared unit one or
more candidate units):

* an **equation**: a top-level conjunct ``out.x == E`` (or ``E ==
  out.x``) of a guarantee, ``E`` a term whose unit follows from declared
  or inferred units by RCL's unit algebra (:mod:`.unitcheck`: ``+ -`` of
  one unit, ``* /`` multiply and divide, a bare number takes the unit of
  what it is added to).  A conjunct under ``or``, ``->``, ``not`` or a
  quantifier is no source (it need not hold).  A bare factor ``k`` that is
  one of the usual conversions (:func:`~.unitconv.convert_by`: ``3.6`` from
  ``[m/s]`` to ``[km/h]``, ``pi/180`` written as a decimal from ``[deg]``
  to ``[rad]``, ``1000`` from ``[m]`` to ``[mm]``) gives the converted unit,
  the literal reading (the unit of the term it multiplies) kept as the
  ``alternative``;
* a **connection**: an input without a declared unit fed by an output with
  a declared or inferred unit takes that unit (a connection carries the
  number unchanged).

The candidates are propagated to a least fixed point, each variable's
*set* of derivable units growing; a variable is inferred when exactly one
unit is derivable for it.  Two sources that disagree (``out.x == in.a``
and ``out.x == in.b``, one in ``[m]`` and one in ``[mm]``) give two units:
nothing is inferred for that variable, nor through it (when unsure, infer
nothing).  A declared unit is never replaced; inputs are not inferred
backwards from what their producer's consumers declare.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any, Iterable, Mapping

from rclverify.lang import ast
from rclverify.lang.printer import expr_to_rcl
from rclverify.lang.types import Checked
from rclverify.lang.unitconv import convert_by, named
from rclverify.lang.units import Unit
from rclverify.lang.walk import subexpressions

#: ``(node, "in" | "out", variable)``.
Key = tuple[str, str, str]
#: Most propagation rounds (a loop of products could make units without end).
MAX_ROUNDS = 64


@dataclass(frozen=True)
class Inferred:
    """The unit inferred for one variable: ``unit`` (the conversion reading
    first), ``alternative`` (the literal reading of a bare conversion
    factor, else ``None``), ``clause`` (the equation's text, ``""`` for a
    connection), ``loc`` (the equation's location, or the input's
    declaration for a connection), ``guarantee`` (its index, 0 for a
    connection), ``from_key`` (the output a connection reads, else
    ``None``), ``reads`` (the variables the equation reads) and ``firm``:
    false when the unit rests on a reading with an alternative further up
    (``out.x == in.v + 1``, ``in.v`` fed by ``3.6 * in.speed``: kilometres
    per hour or metres per second, the contract does not say), and then
    only the inferred unit's own alternative is known, so no mismatch is
    reported against it (:func:`certain`)."""

    unit: Unit
    alternative: Unit | None
    clause: str
    loc: ast.Loc
    guarantee: int = 0
    from_key: Key | None = None
    firm: bool = True
    reads: tuple[Key, ...] = ()

    def accepts(self, u: Unit) -> bool:
        """Is ``u`` one of the readings (the inferred unit or its alternative)?"""
        return u == self.unit or (self.alternative is not None and u == self.alternative)

    def why(self) -> str:
        """Where the unit comes from, for a message: ``"guarantee 1 `out.heading
        == in.cog` (robot.rcl:9:13)"``."""
        if self.from_key is not None:
            n, p, v = self.from_key
            return f"the connection from {n}.{p}.{v}"
        return f"guarantee {self.guarantee} `{self.clause}` ({self.loc.file}:{self.loc.line}:{self.loc.col})"


@dataclass(frozen=True)
class _Eq:
    key: Key
    rhs: ast.Expr
    node: str
    clause: str
    loc: ast.Loc
    guarantee: int


@dataclass
class Inference:
    """The inferred units of a system: ``inferred`` maps a key to its
    :class:`Inferred`; ``ambiguous`` holds the keys with two or more
    derivable units (nothing inferred)."""

    declared: dict[Key, Unit] = field(default_factory=dict)
    inferred: dict[Key, Inferred] = field(default_factory=dict)
    ambiguous: set[Key] = field(default_factory=set)

    def unit_of(self, node: str, prefix: str, name: str) -> Unit | None:
        """The declared unit, else the inferred one, else ``None``."""
        k = (node, prefix, name)
        if k in self.declared:
            return self.declared[k]
        got = self.inferred.get(k)
        return got.unit if got is not None else None


# -- a term's unit ---------------------------------------------------------------
# A value is ("number", value or None) or ("units", {(unit, bare factor or None)}) or None (unknown).
Value = Any


def _num(e: ast.NumLit) -> Fraction | None:
    try:
        return e.value
    except (ValueError, ZeroDivisionError):
        return None


def _arith(op: str, a: Fraction | None, b: Fraction | None) -> Fraction | None:
    if a is None or b is None:
        return None
    if op == "+":
        return a + b
    if op == "-":
        return a - b
    if op == "*":
        return a * b
    return a / b if b != 0 else None


def _times(f: Fraction | None, g: Fraction | None) -> Fraction | None:
    return None if f is None or g is None else f * g


def resolve(u: Unit, k: Fraction | None) -> tuple[Unit, Unit | None]:
    """``(reading, alternative)`` of a value in ``u`` times the bare factor
    ``k``: the converted unit and ``u`` when ``k`` is a usual conversion,
    else ``(u, None)``."""
    t = convert_by(u, k) if k is not None else None
    return (t, named(u)) if t is not None else (named(u), None)


class _Terms:
    """The unit algebra over sets of candidate units (module docstring)."""

    def __init__(self, checked: Checked, units: Mapping[Key, frozenset[Unit]]) -> None:
        self.checked, self.units = checked, units

    def value(self, e: ast.Expr, node: str, bound: frozenset[str] = frozenset()) -> Value:
        if isinstance(e, ast.NumLit):
            if e.unit is None:
                return ("number", _num(e))
            from rclverify.lang.units import UnitError, parse_unit  # deferred: optional or conditional (inside a block)
            try:
                return ("units", frozenset({(parse_unit(e.unit.text), Fraction(1))}))
            except UnitError:
                return None
        if isinstance(e, ast.Var):
            return self.var(e, node, bound)
        if isinstance(e, ast.Unary) and e.op == "-":
            v = self.value(e.operand, node, bound)
            if v is None:
                return None
            if v[0] == "number":
                return ("number", None if v[1] is None else -v[1])
            return ("units", frozenset((u, None if k is None else -k) for u, k in v[1]))
        if isinstance(e, ast.Binary) and e.op in ("+", "-", "*", "/"):
            a, b = self.value(e.left, node, bound), self.value(e.right, node, bound)
            if a is None or b is None:
                return None
            return self.sum(e.op, a, b) if e.op in ("+", "-") else self.product(e.op, a, b)
        return None

    def var(self, v: ast.Var, node: str, bound: frozenset[str]) -> Value:
        if v.prefix is None and v.name in bound:
            return None
        cn = self.checked.nodes[node]
        prefix = v.prefix or ("in" if v.name in cn.inputs else "out" if v.name in cn.outputs else None)
        if prefix is not None:
            got = self.units.get((node, prefix, v.name), frozenset())
            return ("units", frozenset((u, Fraction(1)) for u in got)) if got else None
        env = self.checked.env
        if v.name in env.units:
            return ("units", frozenset({(env.units[v.name], Fraction(1))}))
        if v.name in env.constants:
            val = env.constants[v.name][1]
            if isinstance(val, ast.NumLit) and val.unit is None:
                return ("number", _num(val))
        return None

    @staticmethod
    def sum(op: str, a: Value, b: Value) -> Value:
        if a[0] == "number" and b[0] == "number":
            return ("number", _arith(op, a[1], b[1]))
        if a[0] == "number" or b[0] == "number":
            units = b[1] if a[0] == "number" else a[1]
            return ("units", frozenset((resolve(u, k)[0], Fraction(1)) for u, k in units))
        left = {resolve(u, k)[0] for u, k in a[1]}
        right = {resolve(u, k)[0] for u, k in b[1]}
        same = frozenset((u, Fraction(1)) for u in left if u in right)  # a mismatch is the checker's error
        return ("units", same) if same else None

    @staticmethod
    def product(op: str, a: Value, b: Value) -> Value:
        if a[0] == "number" and b[0] == "number":
            return ("number", _arith(op, a[1], b[1]))
        if a[0] == "number":
            if op == "*":
                return ("units", frozenset((u, _times(k, a[1])) for u, k in b[1] if u.offset is None))
            inv = frozenset((u.power(-1), None if k in (None, 0) or a[1] is None else a[1] / k)
                            for u, k in b[1] if u.offset is None)
            return ("units", inv) if inv else None
        if b[0] == "number":
            f = b[1] if op == "*" else (None if b[1] in (None, 0) else 1 / b[1])
            got = frozenset((u, _times(k, f)) for u, k in a[1] if u.offset is None)
            return ("units", got) if got else None
        out = frozenset((ua.times(ub) if op == "*" else ua.over(ub),
                         _times(ka, kb) if op == "*" else (None if kb in (None, 0) else _arith("/", ka, kb)))
                        for ua, ka in a[1] for ub, kb in b[1] if ua.offset is None and ub.offset is None)
        return ("units", out) if out else None


def _equations(checked: Checked) -> list[_Eq]:
    """The top-level ``out.x == E`` conjuncts of every guarantee whose
    ``out.x`` declares no unit (module docstring), in source order."""
    out: list[_Eq] = []
    for name, cn in checked.nodes.items():
        for k, g in enumerate(cn.node.guarantees, 1):
            for c in _conjuncts(g.formula):
                if not (isinstance(c, ast.Compare) and c.ops == ("==",)):
                    continue
                for lhs, rhs in (c.operands, c.operands[::-1]):
                    if not isinstance(lhs, ast.Var) or lhs.name not in cn.outputs:
                        continue
                    if lhs.prefix not in ("out", None) or (lhs.prefix is None and lhs.name in cn.inputs):
                        continue
                    if cn.unit_of("out", lhs.name) is None:
                        out.append(_Eq((name, "out", lhs.name), rhs, name, expr_to_rcl(c), c.loc, k))
                        break
    return out


def _conjuncts(e: ast.Expr) -> list[ast.Expr]:
    if isinstance(e, ast.Binary) and e.op == "and":
        return _conjuncts(e.left) + _conjuncts(e.right)
    return [e]


def infer_units(checked: Checked, links: Iterable[Any]) -> Inference:
    """The units of ``checked``'s inputs and outputs (module docstring):
    ``links`` are the system model's connections (objects with
    ``from_node``, ``from_var``, ``to_node``, ``to_var``).  Never raises
    for a contract that type-checked; a term it cannot read gives nothing."""
    inf = Inference()
    for name, cn in checked.nodes.items():
        for qualified, u in cn.units.items():
            prefix, var = qualified.split(".", 1)
            inf.declared[(name, prefix, var)] = u
    eqs = _equations(checked)
    feeds = [((l.from_node, "out", l.from_var), (l.to_node, "in", l.to_var)) for l in links
             if l.from_node in checked.nodes and l.to_node in checked.nodes
             and checked.nodes[l.to_node].unit_of("in", l.to_var) is None]
    derivable: dict[Key, dict[Unit, Inferred]] = {}
    for _ in range(MAX_ROUNDS):
        units = {k: frozenset({u}) for k, u in inf.declared.items()}
        units.update({k: frozenset(v) for k, v in derivable.items()})
        terms = _Terms(checked, units)
        nxt: dict[Key, dict[Unit, Inferred]] = {}
        for eq in eqs:
            v = terms.value(eq.rhs, eq.node)
            if v is None or v[0] != "units":
                continue
            for u, k in sorted(v[1], key=lambda uk: str(uk[0])):
                unit, alt = resolve(u, k)
                nxt.setdefault(eq.key, {}).setdefault(unit, Inferred(unit, alt, eq.clause, eq.loc, eq.guarantee,
                                                                     reads=_reads(eq.rhs, checked, eq.node)))
        for src, dst in feeds:
            for u in sorted(units.get(src, frozenset()), key=str):
                decl = _decl_loc(checked, dst)
                nxt.setdefault(dst, {}).setdefault(u, Inferred(u, None, "", decl, 0, src))
        if {k: set(v) for k, v in nxt.items()} == {k: set(v) for k, v in derivable.items()}:
            break
        derivable = nxt
    else:  # no fixed point in the budget: unsure of everything
        return inf
    for key, cands in derivable.items():
        if len(cands) == 1:
            inf.inferred[key] = next(iter(cands.values()))
        else:
            inf.ambiguous.add(key)
    _settle(inf)
    return inf


def _settle(inf: Inference) -> None:
    """Mark each inference firm or not (:class:`Inferred`), a least fixed
    point (a loop of inferences firm only through a firm source); a
    connection passes its source's alternative on."""
    firm: set[Key] = set()
    changed = True
    while changed:
        changed = False
        for key, got in inf.inferred.items():
            if key in firm:
                continue
            srcs = (got.from_key,) if got.from_key is not None else got.reads
            ok = (got.alternative is None or got.from_key is not None) and all(
                s in inf.declared or s in firm for s in srcs if s is not None)
            if ok:
                firm.add(key)
                changed = True
    for key, got in list(inf.inferred.items()):
        alt = got.alternative
        if got.from_key is not None and got.from_key in inf.inferred:
            alt = inf.inferred[got.from_key].alternative if inf.inferred[got.from_key].unit == got.unit else None
        inf.inferred[key] = Inferred(got.unit, alt, got.clause, got.loc, got.guarantee, got.from_key,
                                     key in firm and alt is None, got.reads)


def certain(got: Inferred | None, u: Unit) -> bool:
    """Does the inference ``got`` rule out the unit ``u`` (a consumer's
    declared one)?  Yes when ``u`` is none of its readings and it is firm
    or its alternative is known; never for ``None`` (nothing inferred)."""
    if got is None or got.accepts(u):
        return False
    return got.firm or got.alternative is not None


def _reads(e: ast.Expr, checked: Checked, node: str) -> tuple[Key, ...]:
    """The inputs and outputs of ``node`` the term ``e`` reads."""
    cn = checked.nodes[node]
    out: list[Key] = []
    for v in subexpressions(e):
        if isinstance(v, ast.Var):
            p = v.prefix or ("in" if v.name in cn.inputs else "out" if v.name in cn.outputs else None)
            if p is not None and (node, p, v.name) not in out:
                out.append((node, p, v.name))
    return tuple(out)


def _decl_loc(checked: Checked, key: Key) -> ast.Loc:
    node, prefix, var = key
    n = checked.nodes[node].node
    for v in (n.inputs if prefix == "in" else n.outputs):
        if v.name == var:
            return v.loc
    return n.loc
