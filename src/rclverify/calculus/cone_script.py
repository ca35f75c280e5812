"""The in-context query as SMT-LIB text (:mod:`.context`): the declarations
of a cone's symbols, flags and premise literals, one script from the
parsed premises and Z3's printing of the rest, and a model of
:mod:`rclverify.targets.smtlib`'s fragment read back from Z3's text (SMT-LIB 2.6,
``define-fun`` of constants) without one Z3 object per value.
"""
from __future__ import annotations

import re
from fractions import Fraction
from typing import Any, Mapping

from rclverify.semantics.values import decimal_text
from rclverify.targets.smtlib import SORTS, quote


def sort_of_symbol(cn: Any, prefix: str, var: str) -> str:
    """The SMT-LIB sort of I/O ``prefix.var`` of checked node ``cn``
    (``KeyError`` outside :mod:`rclverify.targets.smtlib`'s sorts)."""
    t = (cn.inputs if prefix == "in" else cn.outputs)[var]
    return SORTS[t]


def declare(symbols: Mapping[str, str], flags: Any, n_literals: int) -> str:
    """SMT-LIB declarations of the cone's I/O symbols, the assumption flags
    ``A!m`` and the premise literals ``l!k``."""
    out = [f"(declare-fun {quote(n)} () {sort})" for n, sort in symbols.items()]
    out += [f"(declare-fun {quote(f)} () Bool)" for f in flags]
    out += [f"(declare-fun {quote(f'l!{k}')} () Bool)" for k in range(n_literals)]
    return "\n".join(out) + "\n"


def merge(body: str, benchmark: str) -> str:
    """One script: ``body`` (declarations and assertions) and the
    ``benchmark`` Z3 printed for the goal and axioms, whose declarations of
    symbols ``body`` already declares are dropped."""
    declared = {line.split()[1].strip("|") for line in body.splitlines() if line.startswith("(declare-fun ")}
    kept = [line for line in benchmark.splitlines()
            if not ((line.startswith("(declare-fun ") or line.startswith("(declare-const "))
                    and line.split()[1].strip("|") in declared)]
    return body + "\n" + "\n".join(kept) + "\n"


_DEFINE = re.compile(r"\(define-fun (\|[^|]*\||\S+) \(\) (Real|Int|Bool)\s+(.*?)\)\s*(?=\(define-fun |$)", re.S)


def _number(text: str) -> str | None:
    """An SMT-LIB numeral of a model (``5``, ``101.0``, ``(- 5.0)``, ``(/ 1.0 3.0)``,
    ``(- (/ 1.0 2.0))``) as :func:`rclverify.semantics.encode.value_to_rcl` writes it; ``None`` otherwise."""
    t = " ".join(text.split())
    sign = 1
    if t.startswith("(- ") and t.endswith(")"):
        sign, t = -1, t[3:-1].strip()
    try:
        if t.startswith("(/ ") and t.endswith(")"):
            num, den = t[3:-1].split()
            fr = Fraction(num) / Fraction(den)
        else:
            fr = Fraction(t)
    except (ValueError, ZeroDivisionError):
        return None
    fr *= sign
    if fr.denominator == 1:
        return str(fr.numerator)
    dec = float(fr)
    if Fraction(dec) == fr:
        return repr(dec)
    return decimal_text(fr) or f"{fr.numerator}/{fr.denominator}"


def read_model(text: str) -> tuple[dict[str, str], dict[str, bool]] | None:
    """``({symbol: RCL value}, {A!m flag: value})`` from a model of the
    fragment printed by Z3 (``define-fun`` of Real, Int and Bool constants);
    ``None`` when the text holds anything else (the caller renders the
    model object instead)."""
    values: dict[str, str] = {}
    flags: dict[str, bool] = {}
    found = _DEFINE.findall(text)
    if text.count("(define-fun ") != len(found):
        return None
    for name, sort, value in found:
        name = name.strip("|")
        v = " ".join(value.split())
        if sort == "Bool":
            if v not in ("true", "false"):
                return None
            if name.startswith("A!"):
                flags[name] = v == "true"
            elif not name.startswith("l!"):
                values[name] = "TRUE" if v == "true" else "FALSE"
            continue
        num = _number(v)
        if num is None:
            return None
        values[name] = num
    return values, flags
