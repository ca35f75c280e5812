"""The assignment a refuted Hoare triple blames: the statement
whose value breaks the post-condition.

A triple refuted with a counterexample has Z3's initial values of the
program's variables.  The program is run on them, exactly (rational
arithmetic, as the verification conditions read it), and the last
assignment executed to each output variable is recorded with its line.
When the run ends with the final values Z3 reported for those outputs, the
culprit of an output the violated conjunct reads is that assignment
(``joint := 6`` in the branch taken), not a comparison line the run passed
through.  A run that cannot be made (an ``extern`` function applied, a
variable read before it has a value, a loop longer than
:data:`MAX_STEPS`, a division by zero) or that ends elsewhere than Z3 said
names nothing: the diagnosis then falls back to the compared constants
(:mod:`.culprit_lines`).
"""
from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Any, Mapping

from rclverify.semantics.operators import OPERATORS, UNARY, Undecided
from rclverify.backends.hoare.lang import Assign, Binary, BoolConst, If, Name, Num, Old, Program, Skip, Unary, While

#: Most statements executed in one run (a loop that runs longer names nothing).
MAX_STEPS = 100_000


class _CannotRun(ValueError):
    """The run cannot be made on the counterexample's values (module docstring)."""


@dataclass(frozen=True)
class Culprit:
    """The last assignment to ``variable`` in the run: its line, its text and the value it gave."""

    variable: str
    line: int
    text: str
    value: Any


def _number(text: str) -> Fraction:
    return Fraction(text)


def _value(v: Any) -> Any:
    if isinstance(v, bool):
        return v
    if isinstance(v, (int, float, Fraction)):
        return Fraction(v)
    if isinstance(v, str):
        s = v.strip()
        if s in ("true", "false", "True", "False", "TRUE", "FALSE"):
            return s.lower() == "true"
        try:
            return Fraction(s)
        except ValueError:
            raise _CannotRun(f"value {v!r}") from None
    raise _CannotRun(f"value {v!r}")


def _eval(e: Any, env: Mapping[str, object], start: Mapping[str, object]) -> Any:
    if isinstance(e, Num):
        return _number(e.text)
    if isinstance(e, BoolConst):
        return e.value
    if isinstance(e, (Name, Old)):
        table = env if isinstance(e, Name) else start
        if e.name not in table:
            raise _CannotRun(f"{e.name} has no value")
        return table[e.name]
    if isinstance(e, Unary):
        return UNARY[e.op].exact(_eval(e.operand, env, start))
    if isinstance(e, Binary):  # the exact meaning of the semantics table; connectives as the logic
        a = _eval(e.left, env, start)  # reads them: both sides defined
        b = _eval(e.right, env, start)
        try:
            return OPERATORS[e.op].exact(a, b)
        except Undecided as exc:  # a zero divisor
            raise _CannotRun(str(exc)) from None
    raise _CannotRun(f"{type(e).__name__} cannot be evaluated")  # an extern function applied


def run(program: Program, initial: Mapping[str, object]) -> tuple[dict[str, object], dict[str, Assign]]:
    """``(final values, last assignment per variable)`` of ``program`` run
    from ``initial`` (variable -> value: numbers, numeric strings or
    booleans).  Raises ``ValueError`` when the run cannot be made (module
    docstring)."""
    env = {k: _value(v) for k, v in initial.items()}
    start = dict(env)
    last: dict[str, Assign] = {}
    steps = [0]

    def block(stmts: Any) -> None:
        for s in stmts:
            steps[0] += 1
            if steps[0] > MAX_STEPS:
                raise _CannotRun("too many steps")
            if isinstance(s, Assign):
                env[s.target] = _eval(s.value, env, start)
                last[s.target] = s
            elif isinstance(s, If):
                block(s.then_ if _eval(s.cond, env, start) else s.else_)
            elif isinstance(s, While):
                while _eval(s.cond, env, start):
                    block(s.body)
                    steps[0] += 1
                    if steps[0] > MAX_STEPS:
                        raise _CannotRun("too many steps")
            elif not isinstance(s, Skip):
                raise _CannotRun(f"{type(s).__name__}")
    try:
        block(program.body)
    except _CannotRun as exc:
        raise ValueError(str(exc)) from None
    return env, last


def breaking_assignments(program: Program, counterexample: Mapping[str, object], outputs: Mapping[str, str],
                         source: str) -> list[Culprit]:
    """The last assignment to each output variable the run on
    ``counterexample`` executes (module docstring).  ``counterexample``:
    the Hoare backend's (``"x"`` an initial value, ``"x (final)"`` a final
    one, ``"in.v"``/``"out.v"`` the RCL names); ``outputs``: RCL output
    name -> program variable (the plan's binding, ``{"out.joint": "joint"}``);
    ``source``: the program's text, for each assignment's text.  ``[]`` when
    the run cannot be made or ends with other final values than Z3's."""
    initial = {k: v for k, v in counterexample.items() if "(final)" not in k and "." not in k and "(" not in k}
    try:
        final, last = run(program, initial)
    except ValueError:
        return []
    lines = source.splitlines()
    out: list[Culprit] = []
    for _, var in sorted(outputs.items()):
        said = counterexample.get(f"{var} (final)")
        a = last.get(var)
        if a is None or said is None:
            continue
        try:
            if _value(said) != final[var]:
                return []  # not the run Z3 showed: name nothing
        except ValueError:
            return []
        text = lines[a.loc.line - 1].strip() if 0 < a.loc.line <= len(lines) else f"{var} := ..."
        out.append(Culprit(var, a.loc.line, text.rstrip(";").strip(), said))
    return out
