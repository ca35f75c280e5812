"""What a workspace function returns, read at its call (docs/ros.md, "Reading
real code").

A C++ value ``("ret", callee, unit, args)`` (:mod:`symbols`) is a call of a
function the workspace may define: a free function or template in a header
of any package of the program (``ns::declare_or_get_parameter(node, "p",
default)``), or a method of the caller's own class or of a node it holds,
found in that class or its bases (``node->declare_or_get_parameter("p",
default)`` where the node's base class defines it).  Its value is that of
the callee's ``return`` statements (:func:`sources_cpp` records them per
definition, overloads apart) with the callee's parameters bound to the
call's arguments (missing ones to their defaults).  Of a function's
overloads, those whose parameter count admits the call's arguments are read
(C++ overload resolution also weighs argument types; the scan knows one
case: a string literal does not go to a parameter declared with a type that
is neither a string nor a template parameter, such as a
``ParameterDescriptor``; the other candidates are each read).

A wrapper of ``declare_parameter`` typically returns the parameter on
several paths: its value when it is declared already (no default there),
else what ``declare_parameter(name, default)`` gives.  When every value read
is one and the same ROS parameter, the result is that parameter, with the
one default the paths declare (a path whose value is not read, such as a
local ``rclcpp::Parameter``'s ``get_value<T>()``, is then left out: the
parameter's name is what all paths share).  Otherwise the call's value is
read only when every path returns the same value (never guessed).
"""
from __future__ import annotations

from itertools import product
from typing import TYPE_CHECKING, Any

from rclverify.ros.extract import symbols
from rclverify.ros.extract.link_units import UnitInfo, unit_of

Entry = tuple[int, int, list[Any], list[Any], list[bool]]  # parameters, defaulted ones, defaults, returned
# values, per parameter whether it may take a string literal
MAX_COMBOS = 16


class Returns:
    """The reading of ``("ret", ...)`` values (mixed into the linker)."""

    returns: dict[str, list[Entry]]
    reading: set[tuple[str, int]]  # the definitions whose returns are being read (a recursion reads nothing)
    units: dict[str, UnitInfo]
    fn_tparams: dict[str, list[str]]
    call_targs: list[tuple[str, str | None, str | None, int, list[str]]]

    if TYPE_CHECKING:  # provided by the classes that mix this one in
        def eval(self, v: Any, env: dict[int, Any], fkey: str | None, depth: int = 0) -> list[Any]:
            ...

        def match(self, name: str, caller: str | None) -> str | None:
            ...

        def _callee(self, kind: str, callee: str, unit: str | None) -> tuple[str | None, str | None]:
            ...

    def returned(self, v: Any, env: dict[int, Any], fkey: str | None, depth: int) -> list[Any]:
        """Every value call value ``v`` takes in function ``fkey`` called with ``env``."""
        _k, callee, unit, args = v
        entries = self.return_entries(callee, unit, len(args))
        if not entries:
            return [None]
        vals = [self.eval(a, env, fkey, depth + 1) for a in args]
        out: list[Any] = []
        for combo in list(product(*vals))[:MAX_COMBOS]:  # one call's arguments: its paths read together
            got: list[Any] = []
            for key, entry in entries:
                nparams, _opt, defaults, rets, strings = entry
                if any(x is not None and x[0] == "str" and i < len(strings) and not strings[i]
                       for i, x in enumerate(combo[:nparams])):
                    continue  # a string literal given to a parameter of another type: not this overload
                mark = (key, id(entry))  # one definition (overloads of one arity share a key)
                if mark in self.reading:  # read within its own reading (recursion): not read
                    got.append(None)
                    continue
                cenv = dict(enumerate(combo[:nparams]))
                cenv.update({i: d for i, d in enumerate(defaults) if i >= len(combo) and symbols.is_concrete(d)})
                self.reading.add(mark)
                try:
                    for r in rets:
                        got += self.eval(r, cenv, key, depth + 1) if r is not None else [None]
                finally:
                    self.reading.discard(mark)
            for x in one_value(got) if got else [None]:
                if x not in out:
                    out.append(x)
        return out

    def return_entries(self, callee: str, unit: str | None, nargs: int) -> list[tuple[str, Entry]]:
        """``(function key, definition)`` of each definition a call of ``callee`` with
        ``nargs`` arguments may run (overloads keyed ``f#N`` by their arity too);
        ``[]`` when the workspace defines no such function with a return."""
        key = self._callee("call", callee, unit)[0]
        if key is not None:
            key = key.split("#")[0]
        if key is None or not self._returning(key):
            key = self._method_of(callee, unit)
        if key is None:
            return []
        return [(k, e) for k in sorted(self.returns) if k == key or k.startswith(key + "#")
                for e in self.returns[k] if e[0] - e[1] <= nargs <= e[0]]

    def fn_template_types(self, fkey: str | None, param: str, depth: int = 0) -> list[str]:
        """The type texts template parameter ``param`` of function template ``fkey``
        stands for: the explicit template argument at each call of it
        (``make_sub<pkg::msg::T>(node, topic, cb)``), followed through a caller's
        own template parameter; ``[]`` when none is written (a deduced one is not read)."""
        base = (fkey or "").split("#")[0]
        tps = self.fn_tparams.get(fkey or "", self.fn_tparams.get(base, []))
        if param not in tps or depth > 4:
            return []
        i, out = tps.index(param), []
        for callee, unit, caller, _nargs, targs in self.call_targs:
            key = self._callee("call", callee, unit)[0]
            if key is None or key.split("#")[0] != base or len(targs) <= i:
                continue
            own = caller if caller is not None and targs[i] in self.fn_tparams.get(caller, []) else None
            for x in self.fn_template_types(own, targs[i], depth + 1) if own else [targs[i]]:
                if x not in out:
                    out.append(x)
        return out

    def _returning(self, key: str) -> bool:
        return any(k == key or k.startswith(key + "#") for k in self.returns)

    def _method_of(self, callee: str, unit: str | None) -> str | None:
        """The key of method ``meth`` of ``obj->meth`` / ``this->meth`` / ``meth`` in the
        caller's class ``unit`` or one of its bases (a node's method defined by its base class)."""
        meth = callee.replace("->", ".").rsplit(".", 1)[-1]
        seen: list[str] = []
        todo = [unit] if unit else []
        while todo:
            u = todo.pop(0)
            if u in seen or len(seen) > 16:
                continue
            seen.append(u)
            if self._returning(f"{u}::{meth}"):
                return f"{u}::{meth}"
            todo += [b for b in (self.match(x, u) for x in unit_of(self.units, u).bases) if b]
        return None


def one_value(vals: list[Any]) -> list[Any]:
    """What one call returns, from the values its paths return: one ROS
    parameter when every value read is that parameter (see the module
    docstring); else the one value every path returns; else ``[None]`` (paths
    returning different or unread values: not guessed)."""
    read = [x for x in vals if x is not None]
    keys = {(x[1], x[3]) for x in read if x[0] == "param"}
    if read and len(keys) == 1 and all(x[0] == "param" for x in read):
        defaults = {x[2] for x in read if x[2] is not None}
        name, handle = keys.pop()
        return [("param", name, defaults.pop() if len(defaults) == 1 else None, handle)]
    if read and len(read) == len(vals) and all(x == read[0] for x in read):
        return [read[0]]
    return [None]
