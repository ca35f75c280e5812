"""Type rules of services, actions, triggers and deadlines.

The rules (docs/rcl-language.md, "Services, actions and deadlines"):

* a link ``pkg/Srv name serves(in.req, out.resp)`` makes the node the
  server: the request must be one of its inputs, the response one of its
  outputs; ``calls(out.req, in.resp)`` makes it a client, the other way
  round.  An action link lists goal, feedback and result: the server reads
  the goal and writes feedback and result, a client the opposite.
* ``triggered by in.x`` names an input of the node (the event the output
  answers); an output there is an error, and so is a guarantee that mentions
  no output (nothing could answer the trigger).
* ``within N unit`` needs a unit of time (``ns``, ``us``, ``ms``, ``s``,
  ``min``, ``h``: the time units of :mod:`rclverify.lang.units`, the same
  symbols and factors a declaration ``t : REAL [ms]`` uses), a positive
  amount, and a trigger to measure from.

Every violation is a located diagnostic (``file:line:col``); nothing here
raises.
"""
from __future__ import annotations

from fractions import Fraction
from typing import Callable

from rclverify.lang import ast
from rclverify.lang.units import TIME_UNITS, dimension_name, lookup
from rclverify.lang.walk import subexpressions

#: Seconds per unit of a deadline: the time units of the unit table
#: (docs/rcl-language.md, "Units of measure").
UNITS: dict[str, Fraction] = dict(TIME_UNITS)

#: Part names of a link, by kind.
PARTS: dict[str, tuple[str, ...]] = {"service": ("request", "response"),
                                     "action": ("goal", "feedback", "result")}

#: Which side each part is on for the server (the client is the mirror image).
_SERVER_SIDE: dict[str, tuple[str, ...]] = {"service": ("in", "out"), "action": ("in", "out", "out")}

Report = Callable[[ast.Loc, str, str], None]


#: The largest amount a deadline may be written with (a hostile ``1e999999999``
#: would otherwise be expanded to an exact integer of a billion digits).
MAX_AMOUNT = 1e9


def _amount(text: str) -> Fraction | None:
    """``text`` as an exact positive number, ``None`` when it is not one or
    exceeds :data:`MAX_AMOUNT`."""
    try:
        f = float(text)
    except ValueError:
        return None
    if not 0 < f <= MAX_AMOUNT:
        return None
    return Fraction(text)


def seconds(d: ast.Deadline) -> Fraction | None:
    """The deadline in seconds (exact), or ``None`` when its unit is missing
    or unknown or its amount not in (0, 1e9].  ``within 200 ms`` -> ``Fraction(1, 5)``."""
    if d.unit is None or d.unit not in UNITS:
        return None
    a = _amount(d.amount)
    return None if a is None else a * UNITS[d.unit]


def parse_duration(text: str) -> Fraction | None:
    """``"500 ms"`` -> ``Fraction(1, 2)``; ``None`` when the number or the
    unit (``ns``, ``us``, ``ms``, ``s``, ``min``, ``h``) is missing or unknown."""
    parts = str(text).split()
    if len(parts) != 2 or parts[1] not in UNITS:
        return None
    value = _amount(parts[0])
    return None if value is None else value * UNITS[parts[1]]


def check_links(n: ast.Node, err: Report) -> bool:
    """Check the service and action links of node ``n``; report each misuse
    through ``err(loc, message, code)``.  Returns ``True`` when all hold."""
    ok = True
    names = {v.name: "in" for v in n.inputs}
    outs = {v.name for v in n.outputs}
    seen: dict[str, ast.Loc] = {}
    for lk in n.links:
        if lk.name in seen:
            err(lk.loc, f"{lk.kind} {lk.name!r} is linked twice in node {n.name} (first at {seen[lk.name]})",
                "E-duplicate")
            ok = False
            continue
        seen[lk.name] = lk.loc
        want = _SERVER_SIDE[lk.kind]
        if lk.role == "calls":
            want = tuple("out" if w == "in" else "in" for w in want)
        for part, var, side in zip(PARTS[lk.kind], lk.parts, want):
            declared = (var.prefix == "in" and var.name in names) or (var.prefix == "out" and var.name in outs)
            if var.prefix is None or not declared:
                err(var.loc, f"the {part} of {lk.kind} {lk.name!r} must be an input or output of node "
                    f"{n.name} (in.x or out.x), found {_show(var)}", "E-link")
                ok = False
            elif var.prefix != side:
                who = "server" if lk.role == "serves" else "client"
                used = "an input" if var.prefix == "in" else "an output"
                err(var.loc, f"{lk.kind} {part} {_show(var)} used as {used} of its own {who} "
                    f"{n.name}: a {who} {'reads' if side == 'in' else 'writes'} the {part}, so it must be "
                    f"{'an input (in.x)' if side == 'in' else 'an output (out.x)'}", "E-link")
                ok = False
    return ok


def check_clause(n: ast.Node, cl: ast.Clause, err: Report) -> bool:
    """Check the trigger and deadline of guarantee ``cl`` of node ``n``."""
    ok = True
    t = cl.trigger
    if t is not None:
        if t.prefix == "out":
            err(t.loc, f"'triggered by' names output {_show(t)}; a guarantee is triggered by an input "
                f"of node {n.name}", "E-trigger")
            ok = False
        elif t.prefix != "in" or t.name not in {v.name for v in n.inputs}:
            err(t.loc, f"'triggered by' must name an input of node {n.name} (in.x), found {_show(t)}",
                "E-trigger")
            ok = False
    if t is not None and not any(isinstance(e, ast.Var) and e.prefix == "out" for e in subexpressions(cl.formula)):
        err(t.loc, f"a guarantee triggered by {_show(t)} must mention an output (out.y): the output is what "
            "answers the trigger", "E-trigger")
        ok = False
    d = cl.deadline
    if d is not None:
        if d.unit is None:
            err(d.loc, f"deadline 'within {d.amount}' has no unit; write e.g. 'within {d.amount} ms' "
                f"(units: {', '.join(UNITS)})", "E-deadline")
            ok = False
        elif d.unit not in UNITS:
            other = lookup(d.unit)
            what = (f"{d.unit!r} is a unit of {dimension_name(other.dims)}, not of time" if other is not None
                    else f"unknown time unit {d.unit!r}")
            err(d.loc, f"{what} in deadline (units: {', '.join(UNITS)})", "E-deadline")
            ok = False
        elif _amount(d.amount) is None:
            err(d.loc, f"a deadline must be positive and at most {MAX_AMOUNT:g} {d.unit}", "E-deadline")
            ok = False
        if t is None:
            err(d.loc, "a deadline needs 'triggered by in.x' before it: the time is measured from that input",
                "E-deadline")
            ok = False
    return ok


def _show(v: ast.Var) -> str:
    return f"{v.prefix}.{v.name}" if v.prefix else v.name
