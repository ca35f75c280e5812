"""A visitor and a transformer over the RCL abstract syntax (:mod:`rclverify.lang.ast`).

Every consumer of RCL formulas (evaluators, encoders, code generators,
backends' translations) dispatches on the class of a node.  Instead of a
chain of ``isinstance`` tests, a :class:`Visitor` subclass names one method
per node class, ``visit_<Class>`` (``visit_Var``, ``visit_Binary``, ...), and
:meth:`Visitor.visit` finds it through a table built once per subclass (one
dictionary look-up per node).  The design follows the visitors of lark and
pySMT: the tree is plain data, the operations live in the visitors.

* A node class without a method of its own goes to :meth:`Visitor.generic_visit`,
  which visits the node's children (:func:`children`) and hands their
  results to :meth:`Visitor.combine`; the default ``combine`` raises
  :class:`MissingVisit`, so a construct a visitor was never taught is an
  error naming the class, never a silent default.
* A value that is not an RCL node raises :class:`UnknownNode` (a
  ``TypeError``).
* A :class:`Transformer` rebuilds a tree bottom-up: a node without a method
  of its own is rebuilt from its transformed fields, and comes back as the
  very same object when none of them changed (so caches keyed on node
  identity keep working).

Extra positional arguments of :meth:`Visitor.visit` (an environment, the
bound variables) are passed through to the method unchanged.
"""
from __future__ import annotations

import dataclasses
from typing import Any, Callable, ClassVar, Generic, Iterator, TypeVar

from rclverify.lang import ast, exprs, typeexpr
from rclverify.lang import walk

T = TypeVar("T")

#: Every class of the RCL abstract syntax (a frozen dataclass of
#: :mod:`rclverify.lang.typeexpr`, the types, :mod:`rclverify.lang.exprs`,
#: the expressions, or :mod:`rclverify.lang.ast`, the declarations), in the
#: order the modules define them.
NODE_CLASSES: tuple[type, ...] = tuple(
    c for m in (typeexpr, exprs, ast) for c in vars(m).values()
    if isinstance(c, type) and dataclasses.is_dataclass(c) and c.__module__ == m.__name__)

#: The expression classes (the members of :data:`rclverify.lang.ast.Expr`).
EXPR_CLASSES: frozenset[type] = frozenset(ast.Expr.__args__)  # type: ignore[attr-defined]

#: node class -> the name of its visitor method (``visit_<Class>``)
METHOD_NAMES: dict[type, str] = {c: "visit_" + c.__name__ for c in NODE_CLASSES}

#: fields that never hold a node (skipped by :func:`children` and the transformer)
_PLAIN = frozenset({"loc", "name_locs"})
_FIELDS: dict[type, tuple[str, ...]] = {
    c: tuple(f.name for f in dataclasses.fields(c) if f.name not in _PLAIN) for c in NODE_CLASSES}


class UnknownNode(TypeError):
    """:meth:`Visitor.visit` was given a value that is not an RCL node (the message names its class)."""


class MissingVisit(LookupError):
    """A visitor met a node class it has no ``visit_<Class>`` method for and
    does not combine children's results (the message names both): a
    construct the visitor was never taught, an error in the visitor, never
    a silent default."""


def _is_node(value: Any) -> bool:
    return type(value) in METHOD_NAMES


def children(node: Any) -> Iterator[Any]:
    """The direct sub-nodes of ``node``, in field order.

    For an expression these are :func:`rclverify.lang.walk.children` (the
    subexpressions; a quantifier domain written as a type is not one); for
    any other node (a type, a binding, a declaration, a clause) every node
    held in its fields, directly or in a tuple."""
    if type(node) in EXPR_CLASSES:
        yield from walk.children(node)
        return
    for name in _FIELDS[type(node)]:
        value = getattr(node, name)
        if _is_node(value):
            yield value
        elif isinstance(value, tuple):
            yield from (v for v in value if _is_node(v))


class Visitor(Generic[T]):
    """Dispatch on the class of an RCL node (module docstring).

    Subclass and define ``visit_<Class>(self, node, *args) -> T`` for the
    node classes you handle; :meth:`visit` calls it.  The dispatch table is
    built once per subclass, when the class is created."""

    _dispatch: ClassVar[dict[type, Callable[..., Any]]] = {}

    def __init_subclass__(cls, **kwargs: Any) -> None:
        super().__init_subclass__(**kwargs)
        generic = getattr(cls, "generic_visit")
        cls._dispatch = {c: getattr(cls, name, generic) for c, name in METHOD_NAMES.items()}

    def visit(self, node: Any, *args: Any) -> T:
        """The result of this visitor's method for ``node``'s class.

        Raises :class:`UnknownNode` when ``node`` is not an RCL node."""
        method = self._dispatch.get(type(node))
        if method is None:
            raise UnknownNode(f"{type(self).__name__} cannot visit a {type(node).__name__}: "
                              f"not a node of the RCL syntax")
        result: T = method(self, node, *args)
        return result

    def generic_visit(self, node: Any, *args: Any) -> T:
        """The default for a node class without a method: its children
        visited in order (:func:`children`), their results combined."""
        return self.combine(node, [self.visit(c, *args) for c in children(node)])

    def combine(self, node: Any, results: list[T]) -> T:
        """The result for ``node`` from its children's results; by default
        raises :class:`MissingVisit` (no construct is handled by accident)."""
        raise MissingVisit(f"{type(self).__name__} has no {METHOD_NAMES[type(node)]} for "
                           f"{type(node).__name__} at {getattr(node, 'loc', ast.NOLOC)}")


class Transformer(Visitor[Any]):
    """A visitor returning a new tree: ``visit_<Class>`` methods return the
    node that replaces the one given; every other node is rebuilt from its
    transformed fields (:meth:`generic_visit`), the same object when
    nothing below it changed."""

    def generic_visit(self, node: Any, *args: Any) -> Any:
        changes: dict[str, object] = {}
        for name in _FIELDS[type(node)]:
            value = getattr(node, name)
            if _is_node(value):
                new = self.visit(value, *args)
            elif isinstance(value, tuple) and any(_is_node(v) for v in value):
                new = tuple(self.visit(v, *args) if _is_node(v) else v for v in value)
                if all(a is b for a, b in zip(new, value)):
                    new = value
            else:
                continue
            if new is not value:
                changes[name] = new
        return dataclasses.replace(node, **changes) if changes else node


Visitor._dispatch = {c: Visitor.generic_visit for c in METHOD_NAMES}


__all__ = ["EXPR_CLASSES", "METHOD_NAMES", "NODE_CLASSES", "MissingVisit", "Transformer", "UnknownNode",
           "Visitor", "children"]
