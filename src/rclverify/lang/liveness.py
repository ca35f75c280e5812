"""Type rules of progress, initial values and periodic outputs.

A node may declare, after its clauses (docs/rcl-language.md, "Progress,
initial values and periodic outputs"):

* ``progress( eventually )`` -- the node answers every input its
  assumption accepts, eventually: on an infinite run on which its
  assumption holds at infinitely many steps, it answers at infinitely many
  (strong fairness, the compassion of Manna and Pnueli);
* ``progress( within K steps )`` -- it never lets K + 1 consecutive steps
  pass at which its assumption holds without answering at one of them
  (``within 0 steps``: it answers at every step its assumption holds);
* ``initially( F )`` -- F, a formula over the node's outputs, holds of the
  outputs before the node's first answer;
* ``periodic( out.y, P )`` -- the node refreshes ``out.y`` at least once per
  period ``P``: ``N steps`` (then it is ``progress( within N - 1 steps )``
  for the composed system) or a time (``100 ms``: a rate checked on
  recorded runs, docs/monitors.md).

The rules checked here (each violation a located diagnostic; nothing
raises): at most one ``progress`` per node; a step bound written in the
digits 0-9, at most :data:`MAX_STEPS`, with the word ``steps`` (a unit of
time there is refused with the deadline to write instead); ``initially``
reads no input; ``periodic`` names an output of the node, once, with a
positive period in ``steps`` (at least 1) or a unit of time.  The formula
of ``initially`` is typed by :mod:`rclverify.lang.typecheck` as any clause.

Source of the rules: fairness as in Manna and Pnueli, "The Temporal Logic
of Reactive and Concurrent Systems" (1992), ch. 3; the paper's stream model
(compositional-verification-paper.tex, lines 462-495) fixes what a step is.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Callable

from rclverify.lang import ast
from rclverify.lang.timing import UNITS, _amount
from rclverify.lang.units import dimension_name, lookup
from rclverify.lang.walk import free_names, subexpressions

#: The largest step bound of ``progress( within K steps )`` and ``periodic( out.y, N steps )``:
#: the bound of a requirement's ``eventually[<= N]`` (plan/temporal.MAX_BOUND), for the same reason
#: (the composed system counts the steps in a state variable of that range).
MAX_STEPS = 1000
#: The words a step bound may be written with.
STEP_WORDS = ("steps", "step")

Report = Callable[[ast.Loc, str, str], None]


def _steps(text: str) -> int | None:
    """``text`` as a step count: digits 0-9 only, at most :data:`MAX_STEPS`."""
    if not text or not all("0" <= ch <= "9" for ch in text) or len(text.lstrip("0")) > 4:
        return None
    k = int(text)
    return k if k <= MAX_STEPS else None


def check_node(n: ast.Node, inputs: set[str], outputs: set[str], err: Report) -> bool:
    """Check the ``progress``, ``initially`` and ``periodic`` declarations of
    node ``n`` (module docstring); ``inputs``/``outputs`` the names it
    declares.  Reports through ``err(loc, message, code)``; returns ``True``
    when every rule holds."""
    ok = True
    for k, p in enumerate(n.progress):
        if k:
            err(p.loc, f"node {n.name} declares progress twice (first at {n.progress[0].loc}); one progress(...) "
                "per node", "E-progress")
            ok = False
            continue
        ok = _check_progress(n, p, err) and ok
    for cl in n.initially:
        for e in subexpressions(cl.formula):
            if isinstance(e, ast.Var) and e.prefix == "in":
                err(e.loc, f"initially(...) speaks about the outputs of {n.name} before its first answer; it cannot "
                    f"read input in.{e.name}", "E-initially")
                ok = False
                break
        else:
            bare = sorted(x for x in free_names(cl.formula) if x in inputs and x not in outputs)
            if bare:
                err(cl.loc, f"initially(...) speaks about the outputs of {n.name} before its first answer; it cannot "
                    f"read input {bare[0]}", "E-initially")
                ok = False
    seen: dict[str, ast.Loc] = {}
    for per in n.periodic:
        v = per.output
        if v.prefix == "in" or (v.prefix is None and v.name in inputs and v.name not in outputs):
            err(v.loc, f"periodic(...) names input {_show(v)}; a period is a rate of an output of {n.name} (out.y)",
                "E-periodic")
            ok = False
            continue
        if v.name not in outputs:
            err(v.loc, f"periodic(...) must name an output of node {n.name} (out.y), found {_show(v)}", "E-periodic")
            ok = False
            continue
        if v.name in seen:
            err(per.loc, f"output out.{v.name} of {n.name} has two periods (first at {seen[v.name]})", "E-periodic")
            ok = False
            continue
        seen[v.name] = per.loc
        ok = _check_period(n, per, err) and ok
    return ok


def _check_progress(n: ast.Node, p: ast.Progress, err: Report) -> bool:
    if p.bound is None:
        return True
    if p.unit in UNITS:
        err(p.loc, f"progress is counted in steps of the composed system, not in {p.unit}: write 'within "
            f"{p.bound} steps', or give the guarantee a deadline ('triggered by in.x within {p.bound} {p.unit}')",
            "E-progress")
        return False
    if p.unit not in STEP_WORDS:
        other = lookup(p.unit) if p.unit else None
        what = (f"{p.unit!r} is a unit of {dimension_name(other.dims)}" if other is not None
                else f"found {p.unit!r}" if p.unit else "no unit")
        err(p.loc, f"progress(within {p.bound} ...) counts steps: write 'within {p.bound} steps' ({what})", "E-progress")
        return False
    if _steps(p.bound) is None:
        err(p.loc, f"progress(within K steps): K is written in the digits 0-9 and is at most {MAX_STEPS}, "
            f"found {p.bound}", "E-progress")
        return False
    return True


def _check_period(n: ast.Node, p: ast.Periodic, err: Report) -> bool:
    if p.unit in STEP_WORDS:
        k = _steps(p.amount)
        if k is None or k < 1:
            err(p.loc, f"a period in steps is a whole number from 1 to {MAX_STEPS}, found {p.amount}", "E-periodic")
            return False
        return True
    if p.unit is None:
        err(p.loc, f"period '{p.amount}' has no unit; write e.g. '{p.amount} ms' or '{p.amount} steps' "
            f"(units: {', '.join(UNITS)}, steps)", "E-periodic")
        return False
    if p.unit not in UNITS:
        other = lookup(p.unit)
        what = (f"{p.unit!r} is a unit of {dimension_name(other.dims)}, not of time" if other is not None
                else f"unknown unit {p.unit!r}")
        err(p.loc, f"{what} in period (units: {', '.join(UNITS)}, steps)", "E-periodic")
        return False
    if _amount(p.amount) is None:
        err(p.loc, f"a period must be positive and at most 1e9 {p.unit}", "E-periodic")
        return False
    return True


def step_bound(n: ast.Node) -> int | None:
    """The node's progress bound in steps for the composed system: the least
    of ``progress( within K steps )``'s K and ``periodic( out.y, N steps )``'s
    N - 1; ``None`` when it declares neither (a checked node: the rules above
    hold)."""
    ks: list[int] = []
    for p in n.progress:
        k = _steps(p.bound) if p.bound is not None and p.unit in STEP_WORDS else None
        if k is not None:
            ks.append(k)
    for per in n.periodic:
        k = _steps(per.amount) if per.unit in STEP_WORDS else None
        if k:
            ks.append(k - 1)
    return min(ks) if ks else None


def fair(n: ast.Node) -> bool:
    """Whether node ``n`` declares progress of any kind (``eventually``,
    a step bound or a period in steps): then it answers every accepted input
    eventually, on every infinite run."""
    return bool(n.progress) or step_bound(n) is not None


def period_seconds(p: ast.Periodic) -> Fraction | None:
    """A period in time as seconds (exact); ``None`` for a period in steps
    (or one that does not check)."""
    if p.unit not in UNITS:
        return None
    a = _amount(p.amount)
    return None if a is None else a * UNITS[p.unit]


def progress_words(n: ast.Node) -> str:
    """What node ``n`` declares about its progress, in words: ``"progress(
    within 2 steps )"``, ``"none"``."""
    parts = [f"progress( {'eventually' if p.bound is None else f'within {p.bound} {p.unit}'} )" for p in n.progress]
    parts += [f"periodic( {_show(p.output)}, {p.amount} {p.unit} )" for p in n.periodic]
    return ", ".join(parts) or "none"


def _show(v: ast.Var) -> str:
    return f"{v.prefix}.{v.name}" if v.prefix else v.name
