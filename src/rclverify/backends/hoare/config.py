"""The ``hoare`` backend's plan entry, checked: :func:`load_program` reads
the node's program (its file parsed and type checked) and the ``binding``
of the node's inputs and outputs to the program's expressions and
variables (:class:`HoareConfig`); errors are :class:`PlanError` located in
the plan or the program.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

from rclverify.model.plan.errors import PlanError
from rclverify.lang import ast
from rclverify.lang.errors import error
from rclverify.lang.types import FuncT, Type, assignable
from rclverify.backends.base import NodeTarget
from rclverify.backends.hoare import lang
from rclverify.backends.hoare.check import ProgramTypes, check_program, expr_type

DEFAULT_TIMEOUT_MS = 10_000
_IO_KEY = re.compile(r"^(in|out)\.([A-Za-z_][A-Za-z0-9_]*'*)$")


@dataclass(frozen=True)
class HoareConfig:
    """A checked plan entry ``{backend: hoare, program, binding, timeout_ms}``.

    ``program``      workspace-relative path of the program;
    ``inputs``       ``in.x`` -> program expression (initial state) or extern name;
    ``outputs``      ``out.x`` -> program variable (final state);
    ``binding_text`` the binding as written, for display;
    ``timeout_ms``   Z3 timeout per verification condition, milliseconds.
    """

    program: str
    inputs: Mapping[str, lang.Expr]
    outputs: Mapping[str, str]
    binding_text: Mapping[str, str]
    timeout_ms: int

    @property
    def stem(self) -> str:
        return Path(self.program).stem


CODE = "E-plan-hoare"


def load_program(target: NodeTarget) -> tuple[HoareConfig, lang.Program, ProgramTypes]:
    """Read the plan entry in ``target.config``, parse and check its program.

    Returns ``(config, program, types)``.  Raises :class:`PlanError` for a bad
    entry (located in the plan) and :class:`RclError` for a bad program
    (located in the program file).
    """
    cfg = target.config  # its keys were checked when the plan was resolved (backends/keys.py)
    prog = cfg.get("program")
    if not isinstance(prog, str) or not prog:
        raise target.config_error("a hoare evidence entry needs 'program: <path of the .imp file>'", code=CODE)
    path = target.root / prog
    if not path.is_file():
        raise target.config_error(f"program file {prog!r} does not exist", "program", code=CODE)
    timeout = cfg.get("timeout_ms", DEFAULT_TIMEOUT_MS)
    if not isinstance(timeout, int) or isinstance(timeout, bool) or timeout <= 0:
        raise target.config_error("timeout_ms must be a positive number of milliseconds", "timeout_ms", code=CODE)
    program = lang.parse_program_file(path, prog)
    types = check_program(program, target.checked.env)
    raw = cfg.get("binding", {}) or {}
    if not isinstance(raw, Mapping):
        raise target.config_error("binding must map RCL names (in.x, out.y) to program expressions", "binding",
                                  code=CODE)
    node = target.node
    inputs: dict[str, lang.Expr] = {}
    outputs: dict[str, str] = {}
    text: dict[str, str] = {}
    for key, value in raw.items():
        m = _IO_KEY.match(str(key))
        if not m:
            raise target.config_error(f"binding key {key!r} must be an RCL input or output name, e.g. in.r or "
                                      "out.status", "binding", key, key=True, code=CODE)
        prefix, name = m.group(1), m.group(2)
        io_t = (node.inputs if prefix == "in" else node.outputs).get(name)
        if io_t is None:
            pool = [f"{prefix}.{n}" for n in (node.inputs if prefix == "in" else node.outputs)]
            raise target.config_error(f"{key} is not an {'input' if prefix == 'in' else 'output'} of {node.name}"
                            + (f"; it has {', '.join(pool)}" if pool else ""), "binding", key, key=True, code=CODE)
        if not isinstance(value, (str, int, float)) or isinstance(value, bool):
            raise target.config_error(f"the binding of {key} must be a program expression (a string)", "binding", key,
                                      code=CODE)
        vtext = str(value)
        at = target.config_loc("binding", key)
        line, col, file = at.line, at.col, at.file
        expr = lang.parse_expression(vtext, file, line, col)
        text[str(key)] = vtext
        if prefix == "in":
            _check_input_binding(str(key), io_t, expr, types, file, line, col)
            inputs[str(key)] = expr
        else:
            outputs[str(key)] = _check_output_binding(str(key), io_t, expr, types, file, line, col)
    return HoareConfig(prog, inputs, outputs, text, timeout), program, types


def _located(file: str, line: int, col: int, msg: str) -> PlanError:
    return PlanError([error(ast.Loc(file, line, col), msg, "E-plan-hoare")])


def _check_input_binding(key: str, io_t: Type, expr: lang.Expr, types: ProgramTypes,
                         file: str, line: int, col: int) -> None:
    if isinstance(io_t, FuncT):
        if isinstance(expr, lang.Name) and types.externs.get(expr.name) == io_t:
            return
        raise _located(file, line, col, f"{key} is a function ({io_t}); bind it to an extern of that type")
    t = expr_type(expr, types)
    if not assignable(t, io_t):
        raise _located(file, line, col, f"{key} is {io_t} but the program expression is {t}")


def _check_output_binding(key: str, io_t: Type, expr: lang.Expr, types: ProgramTypes,
                          file: str, line: int, col: int) -> str:
    if isinstance(io_t, FuncT):
        raise _located(file, line, col, f"{key} is a function ({io_t}); a program variable cannot model it, "
                       "leave it unbound or cover it with another backend")
    if not isinstance(expr, lang.Name) or expr.name not in types.vars:
        raise _located(file, line, col, f"{key} must be bound to a program variable (read in the final state)")
    vt = types.vars[expr.name]
    if not assignable(vt, io_t):
        raise _located(file, line, col, f"{key} is {io_t} but variable {expr.name!r} is {vt}")
    return expr.name
