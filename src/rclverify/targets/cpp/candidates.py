"""Quantifiers decided at candidate points, as C++17 in the generated check header (docs/generate.md).

The C++ of :func:`rclverify.semantics.candidates.quantify` (the double reading's quantifier with a
``REAL``/``INTEGER``/``NATURAL`` variable over its candidate points): the same slots in binding
order (a finite domain as :mod:`.cpp_quant` loops over it, a candidate variable over
``rclverify_rt::real_points``/``int_points`` of the breakpoints its sources give once the
variables before it are bound), one immediately invoked lambda per level as the Python
recursion, the same short cuts (``forall`` at the first false, ``exists`` at the first true,
``exists_unique`` once two are counted, each point counting the values it stands for), and the
same limit of body evaluations (``rclverify_rt::candidate_step``).  The points are made by the
same arithmetic (midpoint ``p/2 + q/2``, else the next double; ``s - 1``/``s + 1``, else the
next double; floor and ceiling for an integer variable).
"""
from __future__ import annotations

from typing import Any

from rclverify.semantics.candidates import Source
from rclverify.lang import ast
from rclverify.targets.cpp.common import Untranslatable
from rclverify.targets.cpp.values import kind_of, term_struct
from rclverify.targets.names import ctor_field

_NUMERIC = ("int", "double")


def candidate_code(tr: Any, e: ast.Quant, loops: list[tuple[str, str, Any]], cpp_ident: Any,
                   ctypes: dict[str, str]) -> tuple[str, str]:
    """``(code, "bool")`` of quantifier ``e`` whose ``loops`` are ``(name, kind, spec)``: a finite
    slot as :mod:`.cpp_quant` makes it (``("values", [code])``/``("range", lo, hi)``), a candidate
    slot ``(name, "cand:<NUMERIC>", sources)``.  The body is translated with every variable bound."""
    saved = dict(tr.bound)
    try:
        for n, kind, _ in loops:
            tr.bound[n] = (cpp_ident(n), "double" if kind == "cand:REAL" else "int" if kind.startswith("cand:")
                           else kind)
        body, bkind = tr.expr(e.body)
        if bkind != "bool":
            raise Untranslatable(f"a quantifier body of type {bkind}")
        code = f"(rclverify_rt::candidate_step(cand_steps) && ({body}) ? 1 : 0)"
        for n, kind, spec in reversed(loops):
            code = _level(tr, e.kind, n, kind, spec, code, cpp_ident, ctypes)
    finally:
        tr.bound.clear()
        tr.bound.update(saved)
    return f"([&]() -> bool {{ std::int64_t cand_steps = 0; return {code} == 1; }}())", "bool"


def _level(tr: Any, kind_q: str, n: str, kind: str, spec: Any, inner: str, cpp_ident: Any,
           ctypes: dict[str, str]) -> str:
    v = cpp_ident(n)
    if kind_q == "forall":
        step = "if (cand_c == 0) { return 0; }"
    elif kind_q == "exists":
        step = "if (cand_c != 0) { return 1; }"
    else:
        step = ("cand_n = std::min(cand_n + cand_c * cand_m, rclverify_rt::kMany); "
                "if (cand_n >= rclverify_rt::kMany) { return rclverify_rt::kMany; }")
    end = "return 1;" if kind_q == "forall" else "return cand_n;"
    if kind.startswith("cand:"):
        numeric = kind[5:]
        real = numeric == "REAL"
        setup = f"std::vector<{'double' if real else 'std::int64_t'}> cand_bp; " + "".join(
            _push(tr, s, real) for s in spec)
        eq = "true" if all(s.eq for s in spec) else "false"
        points = f"rclverify_rt::real_points(cand_bp, {eq})" if real else \
            f"rclverify_rt::int_points(cand_bp, {'true' if numeric == 'NATURAL' else 'false'}, {eq})"
        ctype = "double" if real else "std::int64_t"
        loop = (f"for (const auto & cand_pt : {points}) {{ const {ctype} {v} = cand_pt.first; const int cand_m = cand_pt.second; "
                f"static_cast<void>({v}); static_cast<void>(cand_m); const int cand_c = {inner}; {step} }}")
    else:
        setup = ""
        ctype = ctypes[kind.split(":")[0]]
        body = f"const int cand_m = 1; static_cast<void>(cand_m); const int cand_c = {inner}; {step}"
        if spec[0] == "range":
            loop = f"for ({ctype} {v} = {spec[1]}; {v} <= {spec[2]}; ++{v}) {{ {body} }}"
        elif spec[1]:
            loop = f"for (const {ctype} {v} : {{{', '.join(spec[1])}}}) {{ static_cast<void>({v}); {body} }}"
        else:
            loop = ""
    return f"[&]() -> int {{ int cand_n = 0; static_cast<void>(cand_n); {setup}{loop} {end} }}()"


def _push(tr: Any, s: Source, real: bool) -> str:
    """C++ statements adding source ``s``'s breakpoints to ``cand_bp``."""
    def push(x: str, kind: str) -> str:
        if kind not in _NUMERIC:
            return ""
        if s.shift:
            x = f"({x}) - {s.shift}" if kind == "int" else f"({x}) - {float(s.shift)!r}"
        return f"cand_bp.push_back(static_cast<double>({x})); " if real else f"rclverify_rt::int_breakpoint(cand_bp, {x}); "

    if s.kind == "keys":
        code, kind = tr.var(s.expr)
        t = _func_type(tr, s.expr)
        return f"for (const auto & cand_row : {code}.rows) {{ {push(f'std::get<{s.pos}>(cand_row.first)', _kind(t.args[s.pos]))}}} "
    if s.kind == "elems":
        if not isinstance(s.expr, ast.SetLit):
            raise Untranslatable("a quantified variable's membership in a set that is not a literal")
        out = ""
        for item in s.expr.items:
            out += push(*tr.expr(item))
        return out
    if s.kind == "values" and not s.table:
        return push(*tr.expr(s.expr))
    if s.kind == "values":
        code, _ = tr.var(s.expr.func)
        rk = _kind(_func_type(tr, s.expr.func).result)
        if rk not in _NUMERIC:
            return ""
        return (f"for (const auto & cand_row : {code}.rows) {{ {push('cand_row.second', rk)}}} "
                + push(f"{code}.otherwise", rk))
    # ctor: a known term; its argument at pos when it is that constructor
    if s.table:
        raise Untranslatable("a constructor term compared with a function's result")
    code, kind = tr.expr(s.expr)
    data = tr.env.ctors.get(s.ctor)
    if data is None or kind != f"term:{data.name}" or term_struct(data) is None:
        return ""
    index = [n for n, _ in data.ctors].index(s.ctor)
    arg = _kind(dict(data.ctors)[s.ctor][s.pos])
    return (f"{{ const auto & cand_t = {code}; if (cand_t.ctor == {index}) {{ "
            f"{push(f'cand_t.{ctor_field(s.ctor, s.pos)}', arg)}}} }} ")


def _func_type(tr: Any, f: ast.Var) -> Any:
    side = tr.node.inputs if (f.prefix == "in" or (f.prefix is None and f.name in tr.node.inputs)) else tr.node.outputs
    return side[f.name]


def _kind(t: Any) -> str:
    return kind_of(t) or "other"


__all__ = ["candidate_code"]
