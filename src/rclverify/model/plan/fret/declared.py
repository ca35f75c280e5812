"""What the plan declares for a FRET export that the export does not carry.

The plan's ``fret:`` section (docs/requirements.md, "Requirements from
FRET") may add two things a FRET project leaves to its Simulink or Lustre
model:

``variables: {NAME: input | output}``
    the idType of a variable the export declares without one (or does not
    declare): ``input`` places it as ``in.NAME`` of the component's node,
    ``output`` as ``out.NAME``, checked against the contracts' ports as a
    FRET ``Input``/``Output`` is.  A variable without an idType that the
    plan does not declare stays refused, naming this key.
``functions: {NAME: {args: [a, b, ...], rcl: TERM}}``
    a model function the requirements call (FRET's export carries only its
    name: ``det_3x3(...)``) defined as an RCL term over its parameters
    (``a * e - b * d``; the parameters are the only names it may read).  A
    call ``NAME(x, y, ...)`` with as many arguments is the term with each
    parameter replaced by its argument, bracketed; another count of
    arguments, or a body that does not parse or reads another name, is a
    refusal at the requirement with the reason.

RCL's own ``sqrt``, ``sin``, ``cos``, ``abs`` and FRET's built-ins are
translated before a declared function is looked up, so a declaration never
changes their meaning.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from rclverify.model.plan.document import Fret
from rclverify.model.plan.fret.refusal import Refusal

#: the plan's word for a variable's place -> FRET's idType
ID_TYPES = {"input": "Input", "output": "Output"}


@dataclass(frozen=True)
class DeclaredFunction:
    """One ``fret: functions:`` entry: ``name``, its parameters ``params``
    and its RCL term ``rcl`` over them."""

    name: str
    params: tuple[str, ...]
    rcl: str

    def call(self, args: list[str]) -> str:
        """The RCL text of ``name(args...)`` (each argument RCL text), bracketed.
        Raises :class:`~.fretish.Refusal` for another number of arguments or a
        body that does not parse or reads a name that is no parameter."""
        if len(args) != len(self.params):
            raise Refusal(f"it calls {self.name} with {len(args)} arguments, but the plan's fret: functions: defines "
                          f"{self.name}({', '.join(self.params)}) with {len(self.params)}",
                          f"call {self.name} with {len(self.params)} arguments in FRET, or define it to match")
        from rclverify.lang.errors import RclError  # deferred: start-up (only a plan that defines functions)
        from rclverify.lang.parser import parse_formula  # deferred: start-up, as above
        from rclverify.lang.walk import free_names  # deferred: start-up, as above
        try:
            body = parse_formula(self.rcl, f"fret: functions: {self.name}")
        except RclError as exc:
            raise Refusal(f"the plan's definition of {self.name} does not parse ({exc.diagnostics[0].message})",
                          "write it as an RCL term over its parameters") from None
        other = sorted(free_names(body, type_names=False) - set(self.params))
        if other:
            raise Refusal(f"the plan's definition of {self.name} reads {', '.join(other)}, which is no parameter",
                          f"define {self.name} over its parameters {', '.join(self.params)} only")
        place = dict(zip(self.params, args))
        # whole names only, never a dotted part (in.x), each parameter once: a parameter's argument is not read again
        text = re.sub(r"(?<![\w.])[A-Za-z_]\w*(?![\w(])", lambda m: f"({place[m.group(0)]})" if m.group(0) in place
                      else m.group(0), self.rcl)
        return f"({text})"


def functions_of(spec: Fret) -> dict[str, DeclaredFunction]:
    """The ``functions`` entries of a plan's ``fret:`` section (its typed value)."""
    return {k: DeclaredFunction(k, v.args, v.rcl) for k, v in spec.functions.items()}


def variables_of(spec: Fret) -> dict[str, str]:
    """The ``variables`` entries of a plan's ``fret:`` section as FRET idTypes (``Input``, ``Output``)."""
    return {k: ID_TYPES[v] for k, v in spec.variables.items()}


__all__ = ["DeclaredFunction", "ID_TYPES", "functions_of", "variables_of"]
