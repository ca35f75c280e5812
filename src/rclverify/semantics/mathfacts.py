"""RCL's mathematical functions in Z3: uninterpreted functions, true facts, and
the check of a counterexample that reads them.

Z3 has no sine or cosine, and its square root is no decided term of the
arithmetic it decides.  ``sqrt(t)``, ``sin(t)`` and ``cos(t)``
(docs/semantics.md, "Mathematical functions") are therefore the
uninterpreted functions ``rcl.sqrt``, ``rcl.sin``, ``rcl.cos`` from reals to
reals (:func:`math_function`), and every query that applies them is given
facts the real functions satisfy at every argument, instantiated at each
application ``f(t)`` whose argument has no quantified variable
(:func:`facts`):

* ``sqrt(t) >= 0`` and ``t >= 0 -> sqrt(t) * sqrt(t) == t``: for ``t >= 0``
  these determine the value (the one non-negative root), so a query that
  applies ``sqrt`` only outside quantifiers is decided as for the real
  function; ``t < 0`` is outside ``sqrt``'s domain, a well-definedness
  condition every proof path proves (:mod:`.definedness`);
* ``-1 <= sin(t) <= 1``, ``-1 <= cos(t) <= 1``,
  ``sin(t)^2 + cos(t)^2 == 1``, ``|sin(t)| <= |t|``,
  ``cos(t) >= 1 - t^2 / 2``, ``t == 0 -> sin(t) == 0 and cos(t) == 1``.

Each fact holds for the real functions at every real argument, so a proof
found with them (the negated goal unsatisfiable for every interpretation of
the functions that satisfies the facts) is a proof for the real functions.
A model is not: it may give ``sin`` a value no real sine takes.  A model of
a query that applies ``sin``/``cos`` (or any of the three inside a
quantifier, where no fact is instantiated) is therefore confirmed by
:func:`unconfirmed` before it counts: the model's constants are fixed, each
application's argument is evaluated, each application is replaced by a
variable ranging over Python's ``math`` value of the function at that
argument widened by :data:`TOLERANCE` (relative) plus the same absolute, and
the query's formulas must hold for every such choice.  Python's ``math``
(the C library's) is within an ulp of the real value, far inside the box,
so a confirmed model is a model of the real functions; an unconfirmed one
makes the verdict ``inconclusive`` with the reason, never ``refuted``.
"""
from __future__ import annotations

import math
from typing import Callable, Sequence

import z3

from rclverify.semantics.subterms import subterms

#: the relative (and absolute) half-width of the box around Python's ``math`` value in which a model's
#: violation must persist to be confirmed (:func:`unconfirmed`)
TOLERANCE = 1e-9

#: the resource limit of the confirmation query (Z3 ``rlimit`` steps; about a second on one core)
CONFIRM_RLIMIT = 2_000_000

_FUNCTIONS: dict[str, Callable[[float], float]] = {"sqrt": math.sqrt, "sin": math.sin, "cos": math.cos}


def math_function(op: str, ctx: z3.Context | None = None) -> z3.FuncDeclRef:
    """The uninterpreted Z3 function ``rcl.<op>`` (Real -> Real) of a
    mathematical function ``op`` (``"sqrt"``, ``"sin"``, ``"cos"``)."""
    return z3.Function(f"rcl.{op}", z3.RealSort(ctx), z3.RealSort(ctx))


def _op(e: z3.ExprRef) -> str | None:
    if not z3.is_app(e) or e.num_args() != 1:
        return None
    name = e.decl().name()
    return name[4:] if name.startswith("rcl.") and name[4:] in _FUNCTIONS else None


def applications(formulas: Sequence[z3.ExprRef]) -> tuple[list[z3.ExprRef], bool]:
    """The applications of the three functions in ``formulas`` whose argument
    has no quantified variable (each once, in first-seen order), and whether
    some application has one (a quantifier's body)."""
    seen: set[int] = set()
    out: list[z3.ExprRef] = []
    bound = False
    stack = list(reversed(formulas))
    while stack:
        e = stack.pop()
        k = e.get_id()
        if k in seen:
            continue
        seen.add(k)
        if z3.is_quantifier(e):
            stack.append(e.body())
            continue
        if _op(e) is not None:
            if _has_var(e.arg(0)):
                bound = True
            else:
                out.append(e)
        if z3.is_app(e):
            stack.extend(reversed(e.children()))
    return out, bound


def _has_var(e: z3.ExprRef) -> bool:
    return any(z3.is_var(x) for x in subterms([e]))


def facts(formulas: Sequence[z3.ExprRef]) -> list[z3.BoolRef]:
    """The facts of the module docstring for each application in
    ``formulas`` (:func:`applications`); ``[]`` when none is applied."""
    out: list[z3.BoolRef] = []
    for app in applications(formulas)[0]:
        op, t = _op(app), app.arg(0)
        ctx = app.ctx
        if op == "sqrt":
            out += [app >= 0, z3.Implies(t >= 0, app * app == t)]
            continue
        s, c = math_function("sin", ctx)(t), math_function("cos", ctx)(t)
        mag = z3.If(t >= 0, t, -t)
        out += [s >= -1, s <= 1, c >= -1, c <= 1, s * s + c * c == 1, s <= mag, s >= -mag, c >= 1 - t * t / 2,
                z3.Implies(t == 0, z3.And(s == 0, c == 1))]
    return out


def applies_math(formulas: Sequence[z3.ExprRef]) -> bool:
    """Whether ``formulas`` apply ``sqrt``, ``sin`` or ``cos`` anywhere (a
    query that does not add :func:`facts` nor confirm its models then reads
    them as unknown functions: its refutation is not a verdict)."""
    apps, bound = applications(formulas)
    return bound or bool(apps)


def transcendental(formulas: Sequence[z3.ExprRef]) -> bool:
    """Whether a model of ``formulas`` must be confirmed (:func:`unconfirmed`):
    they apply ``sin``/``cos``, or one of the three inside a quantifier."""
    apps, bound = applications(formulas)
    return bound or any(_op(a) != "sqrt" for a in apps)


def _value(v: z3.ExprRef) -> float | None:
    if z3.is_rational_value(v):
        return float(v.as_fraction())
    if z3.is_int_value(v):
        return float(v.as_long())
    if z3.is_algebraic_value(v):
        return float(v.approx(20).as_fraction())
    return None


def unconfirmed(formulas: Sequence[z3.BoolRef], model: z3.ModelRef) -> str | None:
    """``None`` when ``model`` (of the conjunction of ``formulas``) is confirmed
    for the real functions (module docstring), else the reason it is not,
    for an ``inconclusive`` verdict.  ``model`` may be of another Z3 context
    than ``formulas`` (a deterministic query's): constants are matched by name."""
    apps, bound = applications(formulas)
    if not bound and all(_op(a) == "sqrt" for a in apps):
        return None
    why = "the solver read sqrt/sin/cos as unknown functions"
    if bound:
        return f"{why} and one is applied inside a quantifier, where its value in the model cannot be checked"
    ctx = formulas[0].ctx if formulas else z3.main_ctx()
    pins: list[z3.BoolRef] = []
    consts: dict[str, z3.ExprRef] = {}
    for f in formulas:
        for c in _constants(f):
            consts.setdefault(c.decl().name(), c)
    values = {d.name(): d for d in model.decls() if d.arity() == 0}
    for name, c in consts.items():
        d = values.get(name)
        if d is not None:
            v = model[d]
            pins.append(c == (v if v.ctx == ctx else v.translate(ctx)))
    ev = z3.Solver(ctx=ctx)
    ev.add(*pins)
    if ev.check() != z3.sat:
        return f"{why}; the model could not be read back"
    fixed = ev.model()
    subst: list[tuple[z3.ExprRef, z3.ExprRef]] = []
    box: list[z3.BoolRef] = []
    for k, app in enumerate(apps):
        if any(_op(x) is not None for x in subterms([app.arg(0)])):
            return f"{why} and one is applied to another's value"
        x = _value(fixed.eval(app.arg(0), model_completion=True))
        op = _op(app)
        if x is None or op is None:
            return f"{why}; an argument's value is not a number"
        y = z3.Real(f"rcl.{op}.value{k}", ctx)
        subst.append((app, y))
        if op == "sqrt" and x < 0:
            continue  # outside the domain: any value (the definedness condition decides)
        try:
            r = _FUNCTIONS[op](x)
        except (ValueError, OverflowError):
            return f"{why}; {op}({x!r}) has no value"
        w = TOLERANCE * (1 + abs(r))
        box += [y >= z3.RealVal(r - w, ctx), y <= z3.RealVal(r + w, ctx)]
    s = z3.Solver(ctx=ctx)
    s.set("rlimit", CONFIRM_RLIMIT)
    s.add(*pins, *box, z3.Not(z3.And(*[z3.substitute(f, *subst) if subst else f for f in formulas])))
    r = s.check()
    if r == z3.unsat:
        return None
    if r == z3.sat:
        return (f"{why}: with Python's math values at the model's arguments (within a relative {TOLERANCE:g}) "
                f"the violation does not hold")
    return f"{why}; confirming the model with Python's math values was undecided ({s.reason_unknown()})"


def _constants(f: z3.ExprRef) -> list[z3.ExprRef]:
    return [x for x in subterms([f])
            if z3.is_app(x) and x.num_args() == 0 and x.decl().kind() == z3.Z3_OP_UNINTERPRETED]


__all__ = ["CONFIRM_RLIMIT", "TOLERANCE", "applications", "applies_math", "facts", "math_function", "transcendental",
           "unconfirmed"]
