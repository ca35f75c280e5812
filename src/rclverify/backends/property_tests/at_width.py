"""Strategies for inputs whose field's IDL type is known: drawn as the robot carries them.

Where the workspace's message definitions tell what an input's field carries
(:func:`rclverify.backends.monitors.widths.carried_fields`; docs/semantics.md,
"Widths"), the input is drawn within it (docs/property-tests.md, "Widths"):

* an integer field (``int8`` ... ``uint64``, ``byte``, ``char``): integers
  within the type's range (OMG IDL 4.2, table 7-13; rosidl's type mapping),
  narrowed by the assumption's bounds, always with the range's ends, 0 and
  each constant's neighbours there (:func:`rclverify.semantics.widths.int_edges`),
  also for a ``REAL`` variable read from it (rclpy hands the node an ``int``);
* a ``bool`` field: booleans; a bounded string (``string<=N``) read as an
  enumeration: the enumeration's values the field can carry;
* a floating field: as :meth:`.strategies.InputSpace.real` draws a ``REAL``
  (the harness then narrows each value to the field's width, and the
  thresholds are drawn at that width), a ``float32`` one within binary32's
  finite range;
* a sequence: items each drawn as above within the sequence's bound (the
  assumption's ``forall(q in in.s | lo <= q and q <= hi)``, the plan's
  ``bounds`` of ``in.s``: :func:`.strategies.assumption_bounds`), with its
  ends as edges (a sequence of tuples: one tuple per item, each component
  at its own field's type, unbounded), lengths within the bound: exactly
  ``N`` for a fixed array ``T[N]``, ``m .. N`` for ``T[<=N]`` with ``m``
  and ``N`` items drawn as edges, ``m`` to :data:`.strategies.POOL_SIZE`
  for an unbounded one (``m``: 1 under the assumption's
  ``exists(q in in.s | ...)``, else 0); beyond :data:`MAX_DRAWN_ITEMS`
  items, the rest repeat one drawn item.
"""
from __future__ import annotations

import math
from fractions import Fraction
from pathlib import Path
from typing import Any

from rclverify.backends.property_tests.hypothesis_lib import st
from rclverify.backends.property_tests.strategies import POOL_SIZE, Bound, InputSpace
from rclverify.lang import types as T
from rclverify.lang.types import CheckedNode
from rclverify.semantics.widths import INT_RANGES, Carried, Width, int_edges


#: binary32's largest finite value, (2 - 2**-23) * 2**127.
FLOAT32_MAX = (2 - 2 ** -23) * 2.0 ** 127


def _int_bounds(lo: int, hi: int, bd: Bound | None, natural: bool) -> tuple[int, int]:
    """The range ``lo .. hi`` narrowed by the assumption's bound ``bd`` (and to 0 and above for a NATURAL)."""
    if natural:
        lo = max(lo, 0)
    if bd is not None and bd.lo is not None:
        b = math.ceil(bd.lo)
        lo = max(lo, b + 1 if bd.lo_strict and bd.lo == b else b)
    if bd is not None and bd.hi is not None:
        b = math.floor(bd.hi)
        hi = min(hi, b - 1 if bd.hi_strict and bd.hi == b else b)
    return lo, hi


def scalar_at(space: InputSpace, t: T.Type, bd: Bound | None, w: Width) -> st.SearchStrategy[Any]:
    """A value of RCL type ``t`` as a field of primitive type ``w`` carries it (module docstring)."""
    if w.idl in INT_RANGES and isinstance(t, T.Scalar) and t.name in ("REAL", "INTEGER", "NATURAL"):
        lo, hi = _int_bounds(*INT_RANGES[w.idl], bd, t.name == "NATURAL")
        if lo > hi:
            return st.nothing()
        edges = sorted({v for v in (*int_edges(space.constants, w.idl), lo, hi) if lo <= v <= hi})
        return st.one_of(st.sampled_from(edges), st.integers(min_value=lo, max_value=hi))
    if w.idl == "float32" and isinstance(t, T.Scalar) and t.name == "REAL":
        top = Fraction(FLOAT32_MAX)  # a larger double would reach the node as an infinity: no RCL number
        inner = Bound(bd.lo if bd else None, bd.hi if bd else None, bool(bd and bd.lo_strict),
                      bool(bd and bd.hi_strict))
        inner.lower(-top, False)
        inner.upper(top, False)
        return space.real(inner)
    if isinstance(t, T.EnumT) and w.bound:
        fits = [v for v in t.values if len(v) <= w.bound and (bd is None or bd.enum is None or v in bd.enum)]
        return st.sampled_from(fits) if fits else st.nothing()
    return space.value(t, bd)


#: At most this many items of a sequence are drawn one by one; a longer one repeats its last drawn item
#: (Hypothesis holds about 8 KB of choices per example: 1000 floats do not fit).
MAX_DRAWN_ITEMS = 64


def _items(item: st.SearchStrategy[Any], k: int) -> st.SearchStrategy[tuple[Any, ...]]:
    """Exactly ``k`` items: each drawn for ``k <= MAX_DRAWN_ITEMS``; else that many drawn and one more
    drawn item repeated up to ``k`` (the length still exactly ``k``: a fixed array ``T[1000]``)."""
    if k <= MAX_DRAWN_ITEMS:
        return st.lists(item, min_size=k, max_size=k).map(tuple)
    head = st.lists(item, min_size=MAX_DRAWN_ITEMS, max_size=MAX_DRAWN_ITEMS)
    return st.tuples(head, item).map(lambda hf: (*hf[0], *(hf[1],) * (k - MAX_DRAWN_ITEMS)))


def carried_value(space: InputSpace, t: T.Type, bd: Bound | None, c: Carried) -> st.SearchStrategy[Any]:
    """A value of RCL type ``t`` (a scalar, a ``seq`` of scalars or of tuples of scalars) as a field
    carrying ``c`` holds it (module docstring); built once per input and reused."""
    key = ("carried", t, id(bd), c)
    if key in space.misc_cache:
        return space.misc_cache[key]  # type: ignore[no-any-return]
    if not c.seq:
        out = scalar_at(space, t, bd, c.items[0])
    elif isinstance(t, T.SeqT):
        elems = t.elem.elems if isinstance(t.elem, T.TupleT) else (t.elem,)
        if isinstance(t.elem, T.TupleT):  # no bound reaches a tuple's components
            item = st.tuples(*[scalar_at(space, e, None, w) for e, w in zip(elems, c.items)])
        else:  # the sequence's bound is its items' (strategies.assumption_bounds, the plan's bounds)
            item = scalar_at(space, t.elem, bd, c.items[0])
        least = bd.min_len if bd is not None else 0
        if c.max_len is None:
            out = st.lists(item, min_size=least, max_size=max(POOL_SIZE, least)).map(tuple)
        elif c.fixed:
            out = _items(item, c.max_len) if c.max_len >= least else st.nothing()
        elif c.max_len < least:
            out = st.nothing()
        else:
            n = c.max_len
            sizes = st.one_of(st.sampled_from(sorted({least, n})), st.integers(least, n))
            out = sizes.flatmap(lambda k: _items(item, k))
    else:
        out = space.value(t, bd)
    space.misc_cache[key] = out
    return out


def carried_in(root: Path, node: CheckedNode, mapping: str | None = None) -> tuple[dict[str, str], dict[str, Carried]]:
    """``(widths, carried)`` of ``node``'s inputs and outputs (``"in.x"`` keys), read with the
    workspace's mapping file ``mapping`` (workspace-relative, the one the plan names:
    :func:`~rclverify.model.plan.mapping_file.plan_mapping`; ``None``: the default path), its
    rules and message folders: the floating widths the contract's constants are compared at
    (:func:`~rclverify.backends.monitors.widths.float_widths`) and what each field carries
    (:func:`~rclverify.backends.monitors.widths.carried_fields`); both ``{}`` when the mapping does
    not load (the monitors backend and the plan's checks report it)."""
    from rclverify.backends.monitors.config import load_mapping  # deferred: start-up (yaml, the mapping)
    from rclverify.backends.monitors.widths import carried_fields, float_widths  # deferred: as above
    try:
        cfg = load_mapping(root, mapping)
    except Exception:  # noqa: BLE001 - the monitors backend reports a mapping that does not load; no width here
        return {}, {}
    dirs = [root / d for d in cfg.msg_dirs]
    fields = carried_fields(node, cfg.rules, dirs)
    return float_widths(node, fields), {k: src.carried for k, src in fields.items()}


def mapping_inputs(root: Path, mapping: str | None = None) -> list[str]:
    """The workspace-relative files what a field carries is read from: the mapping file ``mapping``
    (as :func:`carried_in`) when it exists and the ``.msg`` files under its ``msg_dirs`` (``[]``
    when it does not load)."""
    from rclverify.backends.monitors.config import load_mapping  # deferred: start-up (yaml, the mapping)
    try:
        cfg = load_mapping(root, mapping)
    except Exception:  # noqa: BLE001 - reported by the monitors backend and the plan's checks
        return []
    return [*([cfg.mapping] if cfg.mapping else []), *cfg.msg_files(root)]


def input_strategies(space: InputSpace, carried: dict[str, Carried]) -> dict[str, st.SearchStrategy[Any]]:
    """Input name (no ``in.``) -> its strategy as its field carries it, for the inputs of
    ``space``'s node that ``carried`` (``"in.x"`` keys) covers."""
    out = {}
    for key, c in carried.items():
        name = key.removeprefix("in.")
        if key.startswith("in.") and name in space.node.inputs:
            out[name] = carried_value(space, space.node.inputs[name], space.bounds.get(name), c)
    return out


__all__ = ["carried_in", "carried_value", "input_strategies", "mapping_inputs", "scalar_at"]
