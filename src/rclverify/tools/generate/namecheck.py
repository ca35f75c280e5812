"""Refuse the contracts whose names the generated tree cannot carry (docs/generate.md, "Names").

:mod:`.names` turns every RCL name into a generated one by a fixed rule;
this module checks, before anything is rendered, that the result is a tree
that builds and means what the contracts say:

* a node name, and every fully qualified name the generated node creates
  (its topics, services and actions, its verdict topic and parameter
  services, :func:`.rosnames.graph_names`), follows ROS 2's rules
  (:mod:`.rosnames`: rmw's and rcl's validation: the characters, no leading
  digit, no ``//``, the lengths), located at the RCL name it comes from;
* a non-standard interface package and type named by a contract can be
  generated: the package matches rosidl's package pattern and is no Python or
  C++ keyword (it is ``from pkg.msg import`` and ``pkg::msg::``), the type
  rosidl's message pattern ``^[A-Z][A-Za-z0-9]*$`` (these are wire names:
  renamed they would be other types, so they are refused, not mangled);
* no two RCL names give one generated name where both would be in one scope:
  node packages (with the interface and bringup packages), the ends of a node
  (``pub_foo_bar`` for topics ``fooBar`` and ``foo_bar``), a node's inputs as
  ``step``'s parameters, its inputs and outputs as C++ struct fields, the
  rosidl constants of the enumerations and constructors, and the C++ names of
  the enumeration values, terms and their functions.

Every refusal is a located error (``file:line:col: error: ...`` at the later
name, naming the earlier one), raised together as one :class:`RclError`.
"""
from __future__ import annotations

import re

from rclverify.lang import ast
from rclverify.lang.errors import Diagnostic, RclError, error
from rclverify.lang.types import Checked, CheckedNode, DataT, EnumT
from rclverify.targets import names
from rclverify.tools.generate import rosnames
from rclverify.targets.typemap import STANDARD_PACKAGES
from rclverify.targets.cpp.common import enum_const
from rclverify.targets.cpp.values import term_struct

_MSG = re.compile(r"^[A-Z][A-Za-z0-9]*$")
_PKG = re.compile(r"^(?!.*__)(?!.*_$)[a-z][a-z0-9_]*$")
_CODE = "generate-names"
#: names contract_checks.hpp declares in the node's namespace besides the context's
_HEADER_NAMES = ("Inputs", "Outputs", "Truth", "Owed", "Verdict", "kNode", "kTolerance", "kHasTolerance",
                 "kGuarantees", "kTrigger", "judge", "clause_truths", "verdict_json", "values_json", "drive")


class _Scope:
    """Generated names of one scope: the first RCL name (and place) that took each."""

    def __init__(self, what: str, diags: list[Diagnostic]) -> None:
        self.what, self.diags = what, diags
        self.taken: dict[str, tuple[str, ast.Loc]] = {}

    def claim(self, generated: str, rcl: str, loc: ast.Loc) -> None:
        """``rcl`` (declared at ``loc``) becomes ``generated``; a second RCL name is refused."""
        first = self.taken.setdefault(generated, (rcl, loc))
        if first[0] != rcl:
            self.diags.append(error(loc, f"{rcl} and {first[0]} ({first[1]}) would both be {self.what} {generated} "
                                         f"(docs/generate.md, \"Names\"): rename one of them", _CODE))


def check_names(checked: Checked, system: str) -> None:
    """Raise :class:`RclError` with every name of ``checked`` the generated tree of system
    ``system`` cannot carry (above); return ``None`` when there is none."""
    diags: list[Diagnostic] = []
    packages = _Scope("the ROS package", diags)
    packages.claim(f"{names.snake(system)}_bringup", f"system {system}", ast.Loc("<command line>", 0, 0))
    for cn in checked.nodes.values():
        node = cn.node
        _graph_names(diags, cn)
        packages.claim(names.package_name(cn.name), f"node {cn.name}", node.loc)
        ends = _Scope(f"node {cn.name}'s end", diags)
        for t in node.topics:
            _interface(diags, packages, t.msg_type, t.loc)
            if t.match is not None and t.match.prefix in ("in", "out"):
                ends.claim(f"{'sub' if t.match.prefix == 'in' else 'pub'}_{names.snake(t.field)}", t.field, t.loc)
        for link in node.links:
            _interface(diags, packages, link.ros_type, link.loc)
            role = f"{link.kind}_{'server' if link.role == 'serves' else 'client'}"
            ends.claim(f"{role}_{names.snake(link.name)}", link.name, link.loc)
        params = _Scope(f"a parameter of {cn.name}'s logic.step,", diags)
        for side, decls in (("in", node.inputs), ("out", node.outputs)):
            fields = _Scope(f"{cn.name}'s C++ {'Inputs' if side == 'in' else 'Outputs'} field", diags)
            for d in decls:
                fields.claim(names.field_name(d.name), f"{side}.{d.name}", d.loc)
                if side == "in":
                    params.claim(names.py_name(d.name), f"in.{d.name}", d.loc)
    _context(checked, diags)
    if diags:
        raise RclError(diags)


def short_name(name: str) -> str:
    """``name`` as a message shows it: a long one by its first characters and its length."""
    return name if len(name) <= 56 else f"{name[:24]}...{name[-24:]} ({len(name)} characters)"


def _graph_names(diags: list[Diagnostic], cn: CheckedNode) -> None:
    """The ROS names node ``cn``'s generated code creates, each by ROS 2's rules (:mod:`.rosnames`):
    its node name, its private namespace and what is in it, its topics, services and actions; one
    error per RCL name, located where it is declared."""
    node, keep = cn.node, "the monitors and 'ros diff' find it by this name, so it is not renamed: rename it"
    bad_node = rosnames.node_name_problem(cn.name)
    if bad_node:
        diags.append(error(node.loc, f"node name {short_name(cn.name)} cannot be a ROS 2 node name: {bad_node} (rmw); "
                                     f"{keep}", _CODE))
    ends = [("topic", t.field, t.loc) for t in node.topics] + [(lk.kind, lk.name, lk.loc) for lk in node.links]
    private = [(f"/{cn.name}", "namespace", -1)] if not bad_node else []
    said: set[int] = set()
    for fqn, what, i in private + rosnames.graph_names(cn.name, [(k, n) for k, n, _ in ends]):
        if i in said or (i < 0 and bad_node):
            continue
        why = rosnames.namespace_problem(fqn) if what == "namespace" else rosnames.full_name_problem(fqn, what)
        if not why:
            continue
        said.add(i)
        if i < 0:
            diags.append(error(node.loc, f"node name {short_name(cn.name)} gives the {what} {short_name(fqn)}, which "
                                         f"cannot be a ROS 2 {what} name: {why} (rmw; the node's private namespace "
                                         f"holds its verdict topic and the parameter services of every rclpy and "
                                         f"rclcpp node); {keep}", _CODE))
            continue
        kind, name, loc = ends[i]
        gives = "" if fqn == f"/{name}" else f" gives the {what} {short_name(fqn)}, which"
        diags.append(error(loc, f"{kind} name {short_name(name)}{gives} cannot be a ROS 2 {what} name: {why} (rmw); "
                                f"{keep}", _CODE))


def _interface(diags: list[Diagnostic], packages: _Scope, ros_type: str, loc: ast.Loc) -> None:
    """A generated interface's package and type must be names rosidl and both languages accept."""
    parts = ros_type.split("/")
    pkg, name = parts[0], parts[-1]
    if pkg in STANDARD_PACKAGES:
        return
    if not _PKG.match(pkg) or pkg in names.PACKAGE_RESERVED:
        diags.append(error(loc, f"interface package {pkg} of {ros_type} cannot be generated: a package is "
                                f"[a-z][a-z0-9_]* without '__' or a trailing '_' (rosidl, REP 144), no Python or C++ "
                                f"keyword and no Python standard module or ROS package (it is imported as {pkg}.msg "
                                f"and {pkg}::msg); rename it", _CODE))
    if not _MSG.match(name) or name in names.MSG_RESERVED:
        diags.append(error(loc, f"interface {name} of {ros_type} cannot be generated: a message, service or action "
                                f"name is CamelCase, ^[A-Z][A-Za-z0-9]*$ (rosidl), and not None/True/False "
                                f"(a Python class); rename it", _CODE))
    if len(parts) in (2, 3):
        packages.claim(pkg, f"interface package {pkg}", loc)


def _context(checked: Checked, diags: list[Diagnostic]) -> None:
    """The names the context's enumerations and constructor sets give, in the interfaces (rosidl
    constants) and in every node's C++ header (one namespace)."""
    locs = {d.name: d.loc for sp in checked.specs for c in sp.contexts for d in c.decls}
    consts = _Scope("the rosidl constant", diags)
    cpp = _Scope("the C++ name", diags)
    for own in _HEADER_NAMES:
        cpp.claim(own, "the header's own name", ast.Loc("contract_checks.hpp", 0, 0))
    made = [*checked.env.enum_values.values(), *checked.env.ctors.values(), *checked.env.types.values()]
    for t in {t.name: t for t in made if isinstance(t, (EnumT, DataT))}.values():
        loc = locs.get(t.name, ast.Loc())
        if isinstance(t, EnumT):
            for v in t.values:
                consts.claim(names.constant_name(t.name, v), f"{t.name}'s value {v}", loc)
                cpp.claim(enum_const(t, v), f"{t.name}'s value {v}", loc)
            cpp.claim(f"parse_{names.snake(t.name)}", f"enumeration {t.name}", loc)
        elif isinstance(t, DataT):
            ctors = _Scope(f"{t.name}'s constructor constant or function", diags)
            for cname, _ in t.ctors:
                ctors.claim(names.constant_name(cname), cname, loc)
                ctors.claim(f"make_{names.snake(cname)}", cname, loc)
            cpp.claim(term_struct(t) or f"Term{t.name}", f"constructor set {t.name}", loc)
            cpp.claim(f"parse_{names.snake(t.name)}", f"constructor set {t.name}", loc)
            cpp.claim(f"show_{names.snake(t.name)}", f"constructor set {t.name}", loc)


__all__ = ["check_names", "short_name"]
