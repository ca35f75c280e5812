"""The interface packages of a system: ``.msg``, ``.srv`` and ``.action`` from the contracts.

Every ROS type a contract names in ``topics(...)``, ``services(...)`` or
``actions(...)`` (docs/rcl-language.md) whose package is not a standard one
(:data:`.typemap.STANDARD_PACKAGES`) is defined here: a message type gets one
field per contract variable that ``matches`` it (the union over all nodes),
a service its request and response variables, an action its goal, result and
feedback variables (the ``.action`` order; the contract writes goal,
feedback, result).  Units of measure are comments in REP 103 style
(``# [m/s]``); one interface carries each quantity in one unit (:func:`check_units`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

from rclverify.lang import ast
from rclverify.lang.errors import RclError, error
from rclverify.lang.types import Checked, CheckedNode, Type
from rclverify.lang.units import Unit
from rclverify.targets import names
from rclverify.targets.typemap import STANDARD_PACKAGES, Section, TypeMapper


@dataclass
class Interface:
    """One interface file: ``kind`` ``msg``/``srv``/``action``, its sections in file order."""

    pkg: str
    name: str
    kind: str
    sections: list[Section]
    users: set[str] = field(default_factory=set)
    #: per field the declared units of measure of the variables it carries, where declared
    units: list[tuple[str, Unit, ast.Loc, str]] = field(default_factory=list)
    #: per (section, field name) the RCL variable it carries, where and whose it is, its type (one per field)
    carriers: dict[tuple[int, str], tuple[str, ast.Loc, str, Type]] = field(default_factory=dict)
    #: the contract entry that first names the interface
    loc: ast.Loc = field(default_factory=ast.Loc)

    @property
    def path(self) -> str:
        """Path inside the package: ``msg/Name.msg``."""
        return f"{self.kind}/{self.name}.{self.kind}"

    @property
    def ros_name(self) -> str:
        """``pkg/msg/Name`` (the full interface name rosbags and rosidl use)."""
        return f"{self.pkg}/{self.kind}/{self.name}"


@dataclass
class InterfacePackage:
    """A generated interface package: its interfaces and the packages they depend on."""

    name: str
    interfaces: dict[str, Interface] = field(default_factory=dict)
    mapper: TypeMapper | None = None

    def all_interfaces(self) -> list[Interface]:
        """Declared interfaces, then the nested messages the mapping made (sorted by path)."""
        out = dict(self.interfaces)
        assert self.mapper is not None
        for n, s in self.mapper.nested.items():
            out.setdefault(f"msg/{n}", Interface(self.name, n, "msg", [s]))
        return sorted(out.values(), key=lambda i: i.path)

    def depends(self) -> list[str]:
        """Other packages whose types the fields use (``std_msgs`` for ``{}``)."""
        deps = {f.ros_type.split("/")[0] for i in self.all_interfaces() for s in i.sections for f in s.fields
                if "/" in f.ros_type}
        return sorted(deps - {self.name})


def split_type(ros_type: str) -> tuple[str, str]:
    """``pkg/Name`` or ``pkg/msg/Name`` -> ``(pkg, Name)``."""
    parts = ros_type.split("/")
    return parts[0], parts[-1]


def is_standard(ros_type: str) -> bool:
    """The type belongs to a package every ROS 2 distribution ships."""
    return split_type(ros_type)[0] in STANDARD_PACKAGES


def _unit(node: CheckedNode, prefix: str, var: str) -> str:
    """The field's comment head: its unit (``[m/s]``) and, for an input, the bounds the node's
    assumption puts on it by top-level conjuncts (``assumed 0 <= charge <= 100``)."""
    u = node.unit_of(prefix, var)
    parts = [str(u)] if u is not None else []
    if prefix == "in":
        from rclverify.backends.property_tests.strategies import assumption_bounds  # deferred: optional or conditional (inside a block)
        bd = assumption_bounds(node).get(var)
        if bd is not None and (bd.lo is not None or bd.hi is not None):
            lo = f"{bd.lo} {'<' if bd.lo_strict else '<='} " if bd.lo is not None else ""
            hi = f" {'<' if bd.hi_strict else '<='} {bd.hi}" if bd.hi is not None else ""
            parts.append(f"{node.name} assumes {lo}{names.field_name(var)}{hi}")
    return "; ".join(parts)


def _add_var(pkgs: dict[str, InterfacePackage], pkg: str, iface: Interface, section: Section, node: CheckedNode,
             prefix: str, var: str) -> None:
    table = node.inputs if prefix == "in" else node.outputs
    decls = node.node.inputs if prefix == "in" else node.node.outputs
    decl = next((d for d in decls if d.name == var), None)
    texpr = decl.type if decl is not None else None
    u = node.unit_of(prefix, var)
    fname, who = names.field_name(var), f"{node.name}'s {prefix}.{var}"
    loc = decl.loc if decl is not None else node.node.loc
    part = next(i for i, s in enumerate(iface.sections) if s is section)
    first = iface.carriers.setdefault((part, fname), (var, loc, who, table[var]))
    if first[0] != var:
        raise RclError([error(loc, f"{iface.ros_name}: {who} and {first[2]} ({first[1]}) would both be field {fname} "
                                   f"(docs/generate.md, \"Names\"): rename one of them", "generate-names")])
    if first[3] != table[var]:
        raise RclError([error(loc, f"{iface.ros_name}: field {fname} would carry {who} of type {table[var]} and "
                                   f"{first[2]} ({first[1]}) of type {first[3]}: one field, one type "
                                   f"(docs/generate.md, \"Names\"): rename one of them or give them one type",
                              "generate-names")])
    if u is not None and decl is not None:
        iface.units.append((fname, u, decl.unit.loc if decl.unit is not None else decl.loc,
                            f"{node.name}'s {prefix}.{var}"))
    mapper = pkgs[pkg].mapper
    assert mapper is not None
    mapper.loc, mapper.who = loc, who
    mapper.field(section, var, table[var], texpr, _unit(node, prefix, var))


def interface_packages(checked: Checked) -> dict[str, InterfacePackage]:
    """The interface packages the contracts of ``checked`` need, by package name.

    Returns ``{pkg: InterfacePackage}``; standard packages are absent.  A variable without a
    ``matches`` clause adds no field.  Raises ``ValueError`` for an RCL type with no ROS field."""
    pkgs: dict[str, InterfacePackage] = {}

    def package(name: str) -> InterfacePackage:
        if name not in pkgs:
            pkgs[name] = InterfacePackage(name, mapper=TypeMapper(name))
        return pkgs[name]

    for cn in checked.nodes.values():
        for t in cn.node.topics:
            if is_standard(t.msg_type):
                continue
            pkg, name = split_type(t.msg_type)
            ip = package(pkg)
            iface = ip.interfaces.setdefault(f"msg/{name}", Interface(pkg, name, "msg", [Section()], loc=t.loc))
            iface.users.add(cn.name)
            if t.match is not None and t.match.prefix in ("in", "out"):
                _add_var(pkgs, pkg, iface, iface.sections[0], cn, t.match.prefix, t.match.name)
        for link in cn.node.links:
            if is_standard(link.ros_type):
                continue
            pkg, name = split_type(link.ros_type)
            ip = package(pkg)
            kind = "srv" if link.kind == "service" else "action"
            n_sections = 2 if kind == "srv" else 3
            iface = ip.interfaces.setdefault(f"{kind}/{name}",
                                             Interface(pkg, name, kind, [Section() for _ in range(n_sections)],
                                                       loc=link.loc))
            iface.users.add(cn.name)
            # contract order: request, response / goal, feedback, result; file order: goal, result, feedback
            order = (0, 1) if kind == "srv" else (0, 2, 1)
            for part, where in zip(link.parts, order):
                if part.prefix in ("in", "out"):
                    _add_var(pkgs, pkg, iface, iface.sections[where], cn, part.prefix, part.name)
    check_units(pkgs)
    _check_nested(pkgs)
    return pkgs


def _check_nested(pkgs: dict[str, InterfacePackage]) -> None:
    """Refuse a nested message the type mapping makes under the name of an interface a contract
    declares (``pkg/PairItem`` on a topic, and a variable whose ``seq(seq(...))`` needs
    ``PairItem``): one file, two definitions.  Located at the contract entry naming the interface."""
    diags = []
    for pkg in pkgs.values():
        assert pkg.mapper is not None
        for n, (t, who) in sorted(pkg.mapper.made.items()):
            declared = pkg.interfaces.get(f"msg/{n}")
            if declared is not None:
                diags.append(error(declared.loc, f"{pkg.name}/msg/{n} is declared here and is also the nested message "
                                                 f"the type mapping makes for RCL type {t} of {who} (docs/generate.md, "
                                                 f"\"Type mapping\"): rename the interface", "generate-names"))
    if diags:
        raise RclError(diags)


def check_units(pkgs: dict[str, InterfacePackage]) -> None:
    """Refuse an interface whose fields would carry one quantity in two units: two declared
    units of one dimension (``[m]`` and ``[mm]``, ``[rad]`` and ``[deg]``) that differ in scale,
    whether on one field (two nodes reading it differently) or on two fields of the same
    ``.msg``/``.srv``/``.action``.  A ROS interface's fields are read by whoever uses it, with
    the units its comments give (REP 103: SI units throughout); two scales of one quantity in one
    definition is the mix-up a reader makes.  Raises :class:`RclError` with one located error per
    clash, at the later declaration's unit, naming the earlier one."""
    diags = []
    for pkg in pkgs.values():
        for iface in pkg.interfaces.values():
            first: dict[tuple[int, ...], tuple[str, Unit, ast.Loc, str]] = {}
            for fname, u, loc, who in iface.units:
                seen = first.setdefault(u.dims, (fname, u, loc, who))
                if seen[1] != u:
                    diags.append(error(loc, f"{iface.ros_name}: field {fname} would carry {who} in {u}, and field "
                                            f"{seen[0]} the same quantity in {seen[1]} ({seen[3]}, {seen[2]}): "
                                            f"one unit per quantity in one interface (convert one of them)",
                                       "generate-units"))
    if diags:
        raise RclError(diags)
