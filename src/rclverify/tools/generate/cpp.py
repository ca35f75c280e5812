"""``--lang cpp``: one rclcpp (ament_cmake) package per node, with its contract checks as a
ROS-free C++17 header (docs/generate.md, "C++ nodes").

Per node ``<pkg>``: ``src/<pkg>_node.cpp`` (every end of the contract with its name, type and
QoS; generated), ``include/<pkg>/contract_checks.hpp`` (the checks, :mod:`rclverify.targets.cpp.expr`;
generated), ``include/<pkg>/contract_driver.hpp`` and ``test/contract_driver.cpp`` (a driver
reading steps and printing verdicts; generated), ``include/<pkg>/logic.hpp`` and
``src/logic.cpp`` (the node's logic, created once), ``CMakeLists.txt`` and ``package.xml``.
The contracts package style follows ROS 2's ros-safety/contracts_lite (paper line 338); the
rclcpp API the node uses is ROS 2's (``create_publisher``, ``create_subscription``,
``create_service``, ``create_client``, ``rclcpp_action::create_server``/``create_client``).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Mapping

from rclverify.semantics.floatsem import Tolerance
from rclverify.lang.printer import expr_to_rcl
from rclverify.semantics.candidate_points import MAX_CANDIDATE_STEPS
from rclverify.lang.types import Checked, CheckedNode, DataT, EnumT, FuncT
from rclverify.targets.cpp.common import Untranslatable, enum_const
from rclverify.targets.cpp.expr import CppTranslator, cpp_type
from rclverify.targets.cpp.values import data_types, parse_code, table_parse, term_fields
from rclverify.tools.generate.nodes import NodePackage
from rclverify.targets import names
from rclverify.targets.typemap import camel, snake
from rclverify.traces.mapping import TopicRule
from rclverify.tools.generate.shapes import CppTolerance, EndContext, EndRead, EndWrite, NodeContext, TermContext
from rclverify.tools.generate.wiring import wires


@dataclass
class CField:
    """A struct field: RCL ``var`` of ``side`` (``in``/``out``), its C++ ``field`` and ``cpp`` type."""

    side: str
    var: str
    field: str
    cpp: str
    rcl: str
    t: Any = None

    @property
    def show(self) -> str:
        """A C++ expression printing the value (as ``values_json`` renders it)."""
        ref = f"{self.side}.{self.field}"
        if self.cpp == "bool":
            return f'({ref} ? "TRUE" : "FALSE")'
        if isinstance(self.t, EnumT):
            return f"static_cast<int>({ref})"
        if isinstance(self.t, FuncT):
            return f"rclverify_rt::show_table({ref})"
        if isinstance(self.t, DataT):
            return f"show_{snake(self.t.name)}({ref})"
        return ref

    @property
    def fill(self) -> str:
        """C++ statements setting the field from the driver's text ``v``."""
        if isinstance(self.t, FuncT):
            return table_parse(self.t, f"{self.side}.{self.field}")
        if isinstance(self.t, DataT):
            return f"{self.side}.{self.field} = {parse_code(self.t, 'v')};"
        return f"{self.side}.{self.field} = {self.parse};"

    @property
    def parse(self) -> str:
        """A C++ expression reading the value from the driver's text ``v``."""
        if self.cpp == "bool":
            return '(v == "1" || v == "TRUE" || v == "true")'
        if isinstance(self.t, EnumT):
            return f"parse_{snake(self.t.name)}(v)"
        if self.cpp == "double":
            return "std::strtod(v.c_str(), nullptr)"
        if self.cpp == "std::int64_t":
            return "static_cast<std::int64_t>(std::strtoll(v.c_str(), nullptr, 10))"
        return "static_cast<std::uint64_t>(std::strtoull(v.c_str(), nullptr, 10))"


@dataclass
class Clause:
    """One assumption or guarantee: its check function ``fn``, the double and tolerance readings
    as C++ (``""`` with ``why`` when untranslated)."""

    kind: str
    index: int
    rcl: str
    fn: str
    double: str = ""
    tolerance: str = ""
    why: str = ""
    #: why the translated check may answer undecided besides a division by zero (a quantifier)
    notes: list[str] = field(default_factory=list)

    @property
    def title(self) -> str:
        return f"{'assumption' if self.kind == 'assume' else 'guarantee'} {self.index}"

    @property
    def reason(self) -> str:
        """The inconclusive verdict's reason, a C++ string literal's contents."""
        extra = [f"a candidate point out of range or more than {MAX_CANDIDATE_STEPS} candidate evaluations"] \
            if "candidate_step" in self.double else []
        r = f"not translated to C++: {self.why}" if self.why else "; ".join(self.notes + ["division by zero"] + extra)
        return r.replace("\\", "\\\\").replace('"', '\\"')


@dataclass
class Checks:
    """What ``contract_checks.hpp`` of a node holds."""

    node: str
    namespace: str
    contract_file: str
    guard: str
    inputs: list[CField] = field(default_factory=list)
    outputs: list[CField] = field(default_factory=list)
    skipped_in: list[str] = field(default_factory=list)
    skipped_out: list[str] = field(default_factory=list)
    enums: list[Any] = field(default_factory=list)
    #: the constructor sets held as ``Term<Name>`` (:func:`.cpp_values.term_fields`)
    terms: list[TermContext] = field(default_factory=list)
    clauses: list[Clause] = field(default_factory=list)
    tolerance: CppTolerance | None = None
    tolerance_text: str = ""
    #: per guarantee (1-based, index 0 unused): the input of ``triggered by in.x``, "" none
    triggers: list[str] = field(default_factory=list)


@dataclass
class _Enum:
    name: str
    fn: str
    values: list[tuple[str, str]]


def _one_line(text: str) -> str:
    return re.sub(r"\s+", " ", text).strip()


def checks_of(checked: Checked, cn: CheckedNode, namespace: str, tolerance: Tolerance | None = None,
              widths: Mapping[str, str] | None = None) -> Checks:
    """The checks of node ``cn``: struct fields for every input and output a C++ field can hold,
    every clause translated (:class:`rclverify.targets.cpp.expr.CppTranslator`; an untranslatable clause keeps
    its reason), the enumerations they use.  ``tolerance``: the monitors' declared one; ``widths``
    (``"in.x"`` -> ``float32``/``float64``): the widths of the fields the variables travel in, at which
    the comparisons are read (docs/semantics.md, "Widths")."""
    c = Checks(cn.name, namespace, cn.node.loc.file, f"{namespace.upper()}__CONTRACT_CHECKS_HPP_")
    enums: dict[str, EnumT] = {}
    for side, table, skipped, into in (("in", cn.inputs, c.skipped_in, c.inputs),
                                       ("out", cn.outputs, c.skipped_out, c.outputs)):
        for var, t in table.items():
            ct = cpp_type(t)
            if ct is None:
                skipped.append(f"{side}.{var} ({t})")
                continue
            if isinstance(t, EnumT):
                enums[t.name] = t
            into.append(CField(side, var, names.field_name(var), ct, str(t), t))
    for t in checked.env.enum_values.values():
        enums.setdefault(t.name, t)
    c.enums = [_Enum(t.name, snake(t.name), [(v, enum_const(t, v)) for v in t.values])
               for t in sorted(enums.values(), key=lambda t: t.name)]
    c.terms = [{**term_fields(t), "fn": snake(t.name),
                "parse": [(k["name"], len(k["args"]), k["fn"],
                           [parse_code(a, f"q_a[{j}]") for j, a in enumerate(dict(t.ctors)[k["name"]])])
                          for k in term_fields(t)["ctors"]]} for t in data_types(checked)]
    c.triggers = [""] + [f"in.{g.trigger.name}" if g.trigger is not None else "" for g in cn.node.guarantees]
    dbl = CppTranslator(checked, cn, "double", widths)
    tol = CppTranslator(checked, cn, "tolerance", widths)
    if tolerance:
        c.tolerance = {"abs": repr(float(tolerance.abs)), "rel": repr(float(tolerance.rel)), "ulps": tolerance.ulps}
        c.tolerance_text = tolerance.text()
    for kind, clauses in (("assume", cn.node.assumes), ("guarantee", cn.node.guarantees)):
        for k, cl in enumerate(clauses, 1):
            fn = f"{'assumption' if kind == 'assume' else 'guarantee'}_{k}"
            cc = Clause(kind, k, _one_line(expr_to_rcl(cl.formula)), fn)
            try:
                dbl.notes = []
                cc.double = dbl.translate(cl.formula)
                cc.notes = sorted(set(dbl.notes))
                if tolerance:
                    cc.tolerance = tol.translate(cl.formula)
            except Untranslatable as exc:
                cc.double, cc.tolerance, cc.why = "", "", str(exc)
            c.clauses.append(cc)
    return c


def _header(ros_type: str, kind: str) -> str:
    """The header rosidl_generator_cpp writes for ``pkg/Name`` (its CamelCase to snake_case rule,
    rosidl_pycommon: ``WayPEntry`` -> ``way_p_entry.hpp``)."""
    pkg, name = ros_type.split("/")[0], ros_type.split("/")[-1]
    lower = re.sub("([a-z0-9])([A-Z])", r"\1_\2", re.sub("(.)([A-Z][a-z]+)", r"\1_\2", name)).lower()
    return f"{pkg}/{kind}/{lower}.hpp"


def _cpp_type(ros_type: str, kind: str) -> str:
    pkg, name = ros_type.split("/")[0], ros_type.split("/")[-1]
    return f"{pkg}::{kind}::{name}"


def node_context(checked: Checked, np: NodePackage, c: Checks, rules: Mapping[str, TopicRule] | None) -> NodeContext:
    """The template context of ``src/<pkg>_node.cpp``: ``ends`` (each end with its C++ type and the
    struct fields it reads into and writes from, by field path), ``headers``, ``deps``."""
    # tables and terms are filled by the driver, not from messages (docs/generate.md)
    held = {f"{f.side}.{f.var}": f.field for f in c.inputs + c.outputs if not isinstance(f.t, (FuncT, DataT))}
    ws = [w for w in wires(np, rules) if w.path and w.var in held]
    ends: list[EndContext] = []
    headers: set[str] = set()
    for e in np.endpoints:
        kind = e.kind
        headers.add(_header(e.ros_type, kind))
        mine = [w for w in ws if w.attr == e.attr]
        reads: list[EndRead] = [{"field": held[w.var], "path": w.path, "part": w.part, "var": w.var}
                                for w in mine if w.side == "in"]
        writes: list[EndWrite] = [{"field": held[w.var], "path": w.path, "part": w.part} for w in mine if w.side == "out"]
        ends.append({"role": e.role, "name": e.name, "var": e.var, "attr": e.attr, "cpp": _cpp_type(e.ros_type, kind),
                     "reads": reads, "writes": writes})
    deps = ["rclcpp"] + (["rclcpp_action"] if np.has("action_server", "action_client") else [])
    deps += sorted(set(np.depends()) | {"std_msgs"})
    return {"ends": ends, "headers": sorted(headers), "deps": deps, "cls": camel(np.ros_name) + "Node"}


def cpp_package(checked: Checked, cn: CheckedNode, np: NodePackage, env: Any, marker: str, once_marker: str,
                qos_depth: int, rules: Mapping[str, TopicRule] | None = None,
                tolerance: Tolerance | None = None,
                widths: Mapping[str, str] | None = None) -> tuple[dict[str, str], dict[str, str]]:
    """The files of node ``np``'s rclcpp package: ``(generated, created_once)``, relative path ->
    text, rendered with jinja2 environment ``env``; ``widths`` as :func:`checks_of` takes them."""
    d = np.package
    c = checks_of(checked, cn, d, tolerance, widths)
    ctx = dict(marker=marker, np=np, c=c, qos_depth=qos_depth, max_candidate_steps=MAX_CANDIDATE_STEPS, guard=c.guard.replace("__CONTRACT_CHECKS_HPP_", ""),
               **node_context(checked, np, c, rules))
    gen = {
        f"{d}/include/{d}/contract_checks.hpp": env.get_template("cpp_checks.hpp.j2").render(ctx),
        f"{d}/include/{d}/contract_driver.hpp": env.get_template("cpp_driver.hpp.j2").render(ctx),
        f"{d}/test/contract_driver.cpp": env.get_template("cpp_driver_main.cpp.j2").render(ctx),
        f"{d}/src/{d}_node.cpp": env.get_template("cpp_node.cpp.j2").render(ctx),
        f"{d}/CMakeLists.txt": env.get_template("cpp_CMakeLists.txt.j2").render(ctx),
        f"{d}/package.xml": env.get_template("cpp_package.xml.j2").render(ctx),
    }
    once_ctx = dict(ctx, marker=once_marker)
    once = {
        f"{d}/include/{d}/logic.hpp": env.get_template("cpp_logic.hpp.j2").render(once_ctx),
        f"{d}/src/logic.cpp": env.get_template("cpp_logic.cpp.j2").render(once_ctx),
    }
    return gen, once


__all__ = ["Checks", "Clause", "checks_of", "cpp_package", "node_context"]
