"""Two contracts made comparable for refinement (:mod:`.refinement`): the
replacement's interface checked against the node's (same inputs and
outputs, of equal types; :func:`check_interface`) and the two specs'
environments merged into one in which both nodes' names resolve
(:func:`merge_envs`).
"""
from __future__ import annotations

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.lang.types import Checked, CheckedNode, Env


def io_loc(node: CheckedNode, prefix: str, name: str) -> ast.Loc:
    """Where input (``prefix`` ``"in"``) or output ``name`` of ``node`` is declared."""
    group = node.node.inputs if prefix == "in" else node.node.outputs
    return next((v.loc for v in group if v.name == name), node.node.loc)


def check_interface(a: CheckedNode, b: CheckedNode, extra_inputs_ok: bool = False) -> None:
    """Raise :class:`RclError` (one diagnostic per difference, located in B,
    or at B's node when B lacks a variable) unless A and B have the same
    inputs and outputs with the same types.  ``extra_inputs_ok``: B may have
    inputs A lacks (their values are constrained by given conditions)."""
    diags: list[Diagnostic] = []
    for prefix, kind, ta, tb in (("in", "input", a.inputs, b.inputs), ("out", "output", a.outputs, b.outputs)):
        for name, t in ta.items():
            if name not in tb:
                diags.append(error(b.node.loc, f"node {b.name} has no {kind} {name!r}, which {a.name} "
                                               f"({io_loc(a, prefix, name)}) has; a replacement needs the same "
                                               f"interface", "E-refines-interface"))
            elif tb[name] != t:
                diags.append(error(io_loc(b, prefix, name), f"{kind} {name!r} has type {tb[name]} here but "
                                                             f"{t} in {a.name} ({io_loc(a, prefix, name)})",
                                   "E-refines-interface"))
        for name in tb:
            if name not in ta and not (prefix == "in" and extra_inputs_ok):
                diags.append(error(io_loc(b, prefix, name), f"{kind} {name!r} of {b.name} is not an {kind} of "
                                                             f"{a.name} ({a.node.loc}); a replacement needs the "
                                                             f"same interface" + ("" if prefix == "out" else
                                                             ", or a condition on the extra input (--assume, or "
                                                             "the plan's environment facts)"),
                                   "E-refines-interface"))
    if diags:
        raise RclError(diags)


def merge_envs(a: Checked, b: Checked) -> Env:
    """One environment for two separately checked systems.

    Context names both declare must mean the same (same type, same constant
    value, same enumeration values and constructors); otherwise an
    :class:`RclError` located at B's declaration is raised.
    """
    diags: list[Diagnostic] = []
    types, consts = dict(a.env.types), dict(a.env.constants)
    enums, ctors = dict(a.env.enum_values), dict(a.env.ctors)
    locs = _decl_locs(b)
    for name, t in b.env.types.items():
        if name in types and types[name] != t:
            diags.append(error(locs.get(name, ast.NOLOC), f"context type {name} is {t} here but "
                                                          f"{types[name]} in the other contract", "E-refines-context"))
        types.setdefault(name, t)
    for name, (t, v) in b.env.constants.items():
        if name in consts and (consts[name][0] != t or consts[name][1] != v):
            diags.append(error(locs.get(name, ast.NOLOC), f"constant {name} differs from the other contract's",
                               "E-refines-context"))
        consts.setdefault(name, (t, v))
    anywhere = next(iter(locs.values()), ast.NOLOC)
    for value, enum in b.env.enum_values.items():
        if value in enums and enums[value] != enum:
            diags.append(error(locs.get(enum.name, anywhere), f"value {value} belongs to {enum} here but to "
                                                              f"{enums[value]} in the other contract",
                               "E-refines-context"))
        enums.setdefault(value, enum)
    for cname, data in b.env.ctors.items():
        if cname in ctors and ctors[cname] != data:
            diags.append(error(locs.get(data.name, anywhere), f"constructor {cname} belongs to {data} here but "
                                                              f"to {ctors[cname]} in the other contract",
                               "E-refines-context"))
        ctors.setdefault(cname, data)
    if diags:
        raise RclError(diags)
    return Env(types, consts, enums, ctors)


def _decl_locs(c: Checked) -> dict[str, ast.Loc]:
    return {d.name: d.loc for s in c.specs for ctx in s.contexts for d in ctx.decls}
