"""The balanced tree of an ``and``/``or`` chain: the parser builds a chain of
n operands as a tree of depth log2(n) (:mod:`rclverify.lang.builder`), and the
printer's round-trip check recognises that shape (:mod:`rclverify.lang.printer`).
"""
from __future__ import annotations

from typing import Any, Callable

from rclverify.lang import ast


def balanced(op: ast.BinaryOp, operands: list[Any], span: Callable[[Any, Any], ast.Loc]) -> Any:
    """The balanced tree of ``op`` over ``operands`` (n >= 1): the first
    ceil(n/2) operands form the left subtree, the rest the right one, so two
    and three operands give the left-nested tree a left-associative grammar
    gives.  ``span(first, last)`` is the location of a subtree.  Also used by
    the printer's round-trip check (printer.py); iterative (no recursion)."""
    if len(operands) == 1:
        return operands[0]
    # Build bottom-up over (lo, hi) ranges with an explicit post-order stack.
    result: dict[tuple[int, int], Any] = {}
    stack: list[tuple[int, int, bool]] = [(0, len(operands), False)]
    while stack:
        lo, hi, ready = stack.pop()
        if hi - lo == 1:
            result[(lo, hi)] = operands[lo]
            continue
        mid = lo + (hi - lo + 1) // 2
        if not ready:
            stack += [(lo, hi, True), (mid, hi, False), (lo, mid, False)]
            continue
        left, right = result.pop((lo, mid)), result.pop((mid, hi))
        result[(lo, hi)] = ast.Binary(op, left, right, span(operands[lo], operands[hi - 1]))
    return result[(0, len(operands))]
