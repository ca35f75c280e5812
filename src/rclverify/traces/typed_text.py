"""A recorded or drawn value printed in RCL syntax with its type known.

:func:`rclverify.semantics.values.render` prints a value without its type,
so a sequence (a Python ``tuple``, docs/values.md) prints like a tuple.
Where the variable's RCL type is known (a monitor's verdict, a property
test's counterexample), :func:`render_as` prints a ``seq(T)`` as RCL's
sequence literal, ``<1.5, 2, 0.25>`` and ``<>``, and a sequence of tuples
as ``<(1, 2), (3, 4)>``, the way Z3's model values already print
(``semantics/modeltext.py``); every other value as ``render`` prints it.
"""
from __future__ import annotations

from typing import Any

from rclverify.lang import types as T
from rclverify.semantics.values import render


def render_as(value: Any, typ: T.Type | None) -> str:
    """``value`` in RCL syntax as a value of ``typ`` (``None``: unknown, as
    :func:`~rclverify.semantics.values.render` prints it): a sequence in
    ``<..>``, a tuple's components and a sequence's items each by their own
    type."""
    if isinstance(typ, T.SeqT) and isinstance(value, (tuple, list)):
        return "<" + ", ".join(render_as(v, typ.elem) for v in value) + ">"
    if isinstance(typ, T.TupleT) and isinstance(value, tuple) and len(value) == len(typ.elems):
        return "(" + ", ".join(render_as(v, t) for v, t in zip(value, typ.elems)) + ")"
    return render(value)


__all__ = ["render_as"]
