"""ROS 2 names resolved as ``rcl`` resolves them (ROS 2 design, "Topic and Service Names";
rcl's ``validate_topic_name.c``, ``expand_topic_name.c``, ``remap.c``; rmw's ``validate_*.c``).

* A node name is letters, digits and ``_``, not starting with a digit, at most
  :data:`NODE_NAME_MAX` characters (:func:`node_name_problem`).
* A namespace is ``/`` or a fully qualified name of at most
  :data:`NAMESPACE_MAX` characters (:func:`namespace_problem`).
* A fully qualified topic or service name starts with ``/``, holds letters,
  digits, ``_`` and ``/``, no ``//``, no token starting with a digit, no
  trailing ``/`` (``/`` itself is no topic), at most :data:`TOPIC_NAME_MAX`
  characters (:func:`full_name_problem`).
* A name as code writes it (:func:`name_problem`) may also be relative, start
  with ``~`` (then ``~`` alone or ``~/...``) and hold substitutions ``{x}``
  (no nesting, not starting with a digit).
* :func:`expand` is ``rcl_expand_topic_name``: an absolute name without
  substitution stays; ``~`` becomes the node's fully qualified name; ``{node}``
  the node's name, ``{ns}`` and ``{namespace}`` its namespace (any other
  substitution is an error); a name still relative gets the namespace in front.
* :func:`resolve` is ``rcl_node_resolve_name``: the expanded name, then the first
  remap rule (:class:`Remap`, ``[node:]from:=to``) whose node (if it names one) is
  the node and whose ``from``, expanded for the node, is that name, gives its
  ``to`` expanded for the node; the result must be a valid full name.
* :func:`node_fqn` is a node's fully qualified name, namespace and name joined.

Every problem is a :class:`BadName` with the reason in words.  The test
``tests/ros/test_names_rcl.py`` holds these rules against rcl through rclpy.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Sequence

#: rmw's largest node name (``RMW_NODE_NAME_MAX_NAME_LENGTH``), in characters.
NODE_NAME_MAX = 255
#: rmw's largest fully qualified topic or service name (255 less 8 for the middleware's prefix).
TOPIC_NAME_MAX = 255 - 8
#: rmw's largest namespace (``RMW_NAMESPACE_MAX_LENGTH``).
NAMESPACE_MAX = TOPIC_NAME_MAX - 2
#: The substitutions rcl knows, each to what it becomes: the node's name or namespace.
SUBSTITUTIONS = {"{node}": "node", "{ns}": "ns", "{namespace}": "ns"}


class BadName(ValueError):
    """A name rcl refuses; ``str()`` says which name and why."""


def _alnum(c: str) -> bool:
    return c.isascii() and c.isalnum()


def _digit(c: str) -> bool:
    return "0" <= c <= "9"


def node_name_problem(name: str) -> str | None:
    """Why ``name`` is no node name (``rmw_validate_node_name``), or ``None``."""
    if not name:
        return "a node name is not empty"
    bad = next((c for c in name if not (_alnum(c) or c == "_")), None)
    if bad is not None:
        return f"a node name holds letters, digits and '_' only, not {bad!r}"
    if _digit(name[0]):
        return "a node name does not start with a digit"
    if len(name) > NODE_NAME_MAX:
        return f"a node name has at most {NODE_NAME_MAX} characters, not {len(name)}"
    return None


def _full_problem(name: str, what: str, limit: int) -> str | None:
    if not name:
        return f"a {what} is not empty"
    if name[0] != "/":
        return f"a {what} starts with '/'"
    if name[-1] == "/":
        return f"a {what} does not end with '/'"
    bad = next((c for c in name if not (_alnum(c) or c in "_/")), None)
    if bad is not None:
        return f"a {what} holds letters, digits, '_' and '/' only, not {bad!r}"
    if "//" in name:
        return f"a {what} holds no '//'"
    if any(_digit(name[i + 1]) for i in range(len(name) - 1) if name[i] == "/"):
        return f"no token of a {what} starts with a digit"
    if len(name) > limit:
        return f"a {what} has at most {limit} characters, not {len(name)}"
    return None


def full_name_problem(name: str) -> str | None:
    """Why ``name`` is no fully qualified topic or service name (``rmw_validate_full_topic_name``), or ``None``."""
    return _full_problem(name, "fully qualified name", TOPIC_NAME_MAX)


def namespace_problem(ns: str) -> str | None:
    """Why ``ns`` is no node namespace (``rmw_validate_namespace``), or ``None``."""
    if ns == "/":
        return None
    return _full_problem(ns, "namespace", NAMESPACE_MAX)


def name_problem(name: str) -> str | None:
    """Why ``name`` (relative, absolute, ``~``, with substitutions) is no topic or service name as
    code writes it (``rcl_validate_topic_name``), or ``None``."""
    if not name:
        return "a name is not empty"
    if _digit(name[0]):
        return "a name does not start with a digit"
    if name[-1] == "/":
        return "a name does not end with '/'"
    opened = -1
    for i, c in enumerate(name):
        if _alnum(c):
            if _digit(c) and opened >= 0 and i - 1 == opened:
                return "a substitution does not start with a digit"
        elif c == "~":
            if i != 0:
                return "'~' stands only at a name's start"
        elif c == "{":
            if opened >= 0:
                return "a substitution holds no '{'"
            opened = i
        elif c == "}":
            if opened < 0:
                return "a '}' closes no substitution"
            opened = -1
        elif c == "/" and opened >= 0:
            return "a substitution holds letters, digits and '_' only"
        elif c not in "_/":
            return f"a name holds letters, digits, '_', '/', '~', '{{' and '}}' only, not {c!r}"
    if opened >= 0:
        return "a substitution is not closed"
    for i in range(len(name) - 1):
        if name[i] == "/" and _digit(name[i + 1]):
            return "no token of a name starts with a digit"
    if len(name) > 2 and name[0] == "~" and name[1] != "/":
        # rcl checks the character after '~' only in a name of three or more ('~a' passes, '~ab' does not)
        return "'~' is followed by '/'"
    return None


def _check(problem: str | None, what: str) -> None:
    if problem is not None:
        raise BadName(f"{what}: {problem}")


def node_fqn(namespace: str, node: str) -> str:
    """The fully qualified name of node ``node`` in ``namespace`` (``/r1``, ``relay`` -> ``/r1/relay``;
    ``/``, ``relay`` -> ``/relay``).  Raises :class:`BadName` for an invalid name or namespace."""
    _check(node_name_problem(node), f"node name {node!r}")
    _check(namespace_problem(namespace), f"namespace {namespace!r}")
    return f"{'' if namespace == '/' else namespace}/{node}"


def split_fqn(fqn: str) -> tuple[str, str]:
    """A fully qualified node name as ``(namespace, name)``: ``/r1/relay`` -> ``('/r1', 'relay')``."""
    ns, _, base = fqn.rpartition("/")
    return (ns or "/", base)


def expand(name: str, node: str, namespace: str) -> str:
    """``name`` expanded for node ``node`` in ``namespace`` (``rcl_expand_topic_name``: module
    docstring); the result is not validated (``{ns}/x`` in ``/`` is ``//x``).  Raises
    :class:`BadName` for an invalid name, node name or namespace, or an unknown substitution."""
    _check(name_problem(name), f"name {name!r}")
    _check(node_name_problem(node), f"node name {node!r}")
    _check(namespace_problem(namespace), f"namespace {namespace!r}")
    if name[0] == "/" and "{" not in name:
        return name
    out = name
    if out[0] == "~":
        out = f"{namespace}{node}{out[1:]}" if namespace == "/" else f"{namespace}/{node}{out[1:]}"
    while "{" in out:
        sub = out[out.index("{"): out.index("}") + 1]
        if sub not in SUBSTITUTIONS:
            raise BadName(f"name {name!r}: unknown substitution {sub} (rcl knows {{node}}, {{ns}}, {{namespace}})")
        out = out.replace(sub, node if SUBSTITUTIONS[sub] == "node" else namespace)
    if out[0] != "/":
        out = f"{namespace}{out}" if namespace == "/" else f"{namespace}/{out}"
    return out


_TOKEN = r"(?:(?![A-Za-z0-9_]*__)[A-Za-z_][A-Za-z0-9_]*)"
#: A name as a remap rule writes it (rcl's argument lexer): ``/`` or ``~/`` first, then tokens
#: joined by one ``/``, each a letter or ``_`` then letters, digits and ``_``, none holding ``__``.
_RULE_NAME = re.compile(rf"^(?:/|~/)?{_TOKEN}(?:/{_TOKEN})*$")
_RULE_NODE = re.compile(rf"^{_TOKEN}$")
#: The schemes a rule's ``from`` may start with, each the only kind of name the rule applies to.
_SCHEMES = {"rostopic://": "topic", "rosservice://": "service"}


@dataclass(frozen=True)
class Remap:
    """One remap rule ``[node:][rostopic://|rosservice://]source:=target`` (ROS 2 design, "Remapping
    Names"; ``__node:=name`` and ``__ns:=/namespace`` rename the node): ``node`` the node it is given
    to (``None``: every node), ``source`` and ``target`` as written, ``kind`` ``topic`` or
    ``service`` when a scheme limits the rule (``None``: both)."""

    source: str
    target: str
    node: str | None = None
    kind: str | None = None

    @classmethod
    def parse(cls, text: str) -> "Remap":
        """The rule ``text``.  Raises :class:`BadName` for a rule rcl's argument parser refuses: no
        ``:=``, a node name or a name outside the rule grammar (:data:`_RULE_NAME`: no
        substitution, no ``__``, no wildcard), an invalid new node name or namespace."""
        left, sep, target = text.partition(":=")
        if not sep or ":=" in target:
            raise BadName(f"remap rule {text!r}: it has the form [node:]from:=to")
        node: str | None = None
        kind: str | None = None
        for prefix, k in _SCHEMES.items():
            at = left.find(prefix)
            if at >= 0:
                if at and left[at - 1] != ":":
                    raise BadName(f"remap rule {text!r}: {prefix} follows 'node:' or starts the rule")
                node, kind, left = (left[: at - 1] if at else None), k, left[at + len(prefix):]
                break
        else:
            head, colon, left = left.rpartition(":")
            node = head if colon else None
        if node is not None and not _RULE_NODE.match(node):
            raise BadName(f"remap rule {text!r}: node name {node!r} is not one a rule can name")
        if left in ("__node", "__name"):
            _check(node_name_problem(target), f"remap rule {text!r}: new node name {target!r}")
            return cls("__node", target, node)
        if left == "__ns":
            _check(namespace_problem(target), f"remap rule {text!r}: new namespace {target!r}")
            return cls("__ns", target, node)
        for side in (left, target):
            if not _RULE_NAME.match(side):
                raise BadName(f"remap rule {text!r}: name {side!r} is not one a rule can write (tokens of "
                              "letters, digits and '_' joined by '/', after '/' or '~/'; no '__', no '{}')")
        return cls(left, target, node, kind)


def node_identity(node: str, namespace: str, remaps: Sequence[Remap] = ()) -> tuple[str, str]:
    """Node ``node`` in ``namespace`` as it runs under ``remaps``: ``(name, namespace)`` after the
    first ``__node`` rule and the first ``__ns`` rule that apply to it (a node-scoped rule names the
    node's name as its code gives it).  Raises :class:`BadName` for an invalid result."""
    name = next((r.target for r in remaps if r.source == "__node" and r.node in (None, node)), node)
    ns = next((r.target for r in remaps if r.source == "__ns" and r.node in (None, node)), namespace)
    node_fqn(ns, name)
    return name, ns


def resolve(name: str, node: str, namespace: str, remaps: Sequence[Remap] = (), kind: str = "topic") -> str:
    """``name`` resolved for node ``node`` in ``namespace`` under ``remaps`` (in order; the node's
    own rules before the global ones, as rcl gives them): ``rcl_node_resolve_name``, module
    docstring.  Returns the fully qualified name; raises :class:`BadName` where rcl refuses."""
    out = expand(name, node, namespace)
    for rule in remaps:
        if rule.source in ("__node", "__ns") or rule.kind not in (None, kind):
            continue
        if rule.node is not None and rule.node != node:
            continue
        if expand(rule.source, node, namespace) == out:
            out = expand(rule.target, node, namespace)
            break
    _check(full_name_problem(out), f"name {name!r} resolves to {out!r}")
    return out


__all__ = ["BadName", "NAMESPACE_MAX", "NODE_NAME_MAX", "Remap", "SUBSTITUTIONS", "TOPIC_NAME_MAX", "expand",
           "full_name_problem", "name_problem", "namespace_problem", "node_fqn", "node_identity", "node_name_problem", "resolve",
           "split_fqn"]
