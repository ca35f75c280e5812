"""The fields a contract topic's variables are read from, checked against
the ROS message type (:mod:`.ground`, module docstring's type rules): each
field path must exist in the topic's message, and its ROS type must carry
the RCL variable's type (``ROS-FIELD-MISSING``, ``ROS-FIELD-TYPE``).
Mixed into :class:`~.ground.Grounder`, which provides the attributes
annotated on the class.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping

from rclverify.lang import ast
from rclverify.lang import types as T
from rclverify.ros.extract.interfaces import ABSENT, BASE_TYPES, TypeTable, field_path
from rclverify.ros.extract.model import Src, short_type

_INT = {"int8", "int16", "int32", "int64", "uint8", "uint16", "uint32", "uint64", "byte", "char", "octet"}
_FLOAT = {"float32", "float64"}


def _compatible(ros_t: str, rcl: T.Type) -> bool:
    if isinstance(rcl, T.Scalar):
        if rcl.name == "REAL":
            return ros_t in _FLOAT | _INT
        if rcl.name in ("INTEGER", "NATURAL"):
            return ros_t in _INT
        if rcl.name == "BOOL":
            return ros_t == "bool"
        if rcl.name == "STRING":
            return ros_t in ("string", "wstring")
    return False


def _expected(typ: T.Type) -> list[T.Type | str]:
    """The sequence of RCL types the mapping rules read for a variable ("ctor" for a constructor name)."""
    if isinstance(typ, (T.Scalar, T.EnumT)):
        return [typ]
    if isinstance(typ, T.FuncT):
        res = typ.result
        tail = [] if isinstance(res, T.Scalar) and res.name == "BOOL" else [res]
        return [*typ.args, *tail]
    if isinstance(typ, T.DataT):
        return ["ctor"]
    return []


class FieldGrounding:
    """The field checks of a contract topic (module docstring)."""

    table: TypeTable
    fields: Mapping[str, list[str]]  # topic -> the field paths the plan's mapping reads

    if TYPE_CHECKING:  # provided by the class that mixes this one in
        def add(self, code: str, message: str, rcl: ast.Loc | None, ros: Src | None, node: str = "",
                topic: str = "") -> None:
            ...

    def _fields(self, cn: Any, tp: ast.Topic, var: ast.Var, ctype: str, rcl_loc: ast.Loc) -> None:
        info = self.table.get(ctype)
        assert info is not None
        if info.origin == ABSENT:  # its package's one ROS-INTERFACE-ABSENT warning says what it leaves unchecked
            return
        msg_src = Src(info.file or short_type(ctype), 1)
        typ = cn.io_type(var)
        if typ is None:
            return
        # the contract's own entry (Contract.topic) first: the same topic name may carry
        # another message type in another contract (skeleton.py writes both forms)
        paths = list(self.fields.get(f"{cn.name}.{tp.field}", self.fields.get(tp.field, [])))
        resolved: list[tuple[str, str, bool, Src]] = []
        for p in paths:
            rt, err, arr = field_path(self.table, ctype, p)
            top = p.split(".")[0].split("[")[0]
            fsrc = Src(info.file, info.lines.get(top, 1)) if info.file else msg_src
            if err is not None:
                self.add("ROS-FIELD-MISSING", f"field path '{p}' of topic '{tp.field}' ({short_type(ctype)}): {err}",
                         rcl_loc, msg_src, cn.name, tp.field)
                return
            resolved.append((p, rt or "", arr, fsrc))
        if not paths:
            for fname, _desc in info.fields:
                rt, _err, arr = field_path(self.table, ctype, fname)
                resolved.append((fname, rt or "", arr, Src(info.file, info.lines.get(fname, 1)) if info.file else msg_src))
        want = _expected(typ)
        explicit = bool(paths)
        pool = list(resolved)
        for k, w in enumerate(want):
            if explicit:
                if k >= len(resolved):
                    self.add("ROS-FIELD-TYPE", f"{var.qualified} : {typ} needs {len(want)} field(s) of topic "
                             f"'{tp.field}', its field list gives {len(resolved)}", rcl_loc, msg_src, cn.name, tp.field)
                    return
                cand = [resolved[k]]
            else:
                cand = pool
            hit = self._take(cand, w, ctype)
            if isinstance(hit, str):  # a located mismatch message
                p, rt, arr, fsrc = cand[0]
                self.add("ROS-FIELD-TYPE", f"{var.qualified} : {typ} reads field '{p}' ({rt}{'[]' if arr else ''}) "
                         f"of {short_type(ctype)}: {hit}", rcl_loc, fsrc, cn.name, tp.field)
                return
            if hit is None:
                self.add("ROS-FIELD-TYPE", f"{var.qualified} : {typ} needs a field of type {w if isinstance(w, str) else _ros_for(w)} "
                         f"in {short_type(ctype)}, which has none left", rcl_loc, msg_src, cn.name, tp.field)
                return
            if not explicit:
                pool.remove(hit)

    def _take(self, cand: list[tuple[str, str, bool, Src]], w: Any, ctype: str) -> Any:
        """The first candidate field matching ``w``; ``None`` if none; a message if one explicit field mismatches."""
        for c in cand:
            p, rt, arr, _ = c
            ok, why = self._match(rt, arr, w, ctype, p)
            if ok:
                return c
            if len(cand) == 1:
                return why
        return None

    def _match(self, rt: str, arr: bool, w: Any, ctype: str, path: str) -> tuple[bool, str]:
        if arr:
            return False, "an array field cannot fill a single value; index it (name[0]) or name a nested field"
        if rt not in BASE_TYPES and rt.split("<=")[0] not in BASE_TYPES:
            return False, "a message field; name one of its fields (a nested path)"
        rt = rt.split("<=")[0]
        if w == "ctor":
            return (rt in ("string", "wstring"), "the constructor name is read from a string")
        if isinstance(w, T.EnumT):
            if rt in ("string", "wstring"):
                return True, ""
            if rt in _INT:
                owner = ctype
                if "." in path:
                    owner = field_path(self.table, ctype, path.rsplit(".", 1)[0])[0] or ctype
                oinfo = self.table.get(owner)
                consts = {n.lower() for n, t, _v in (oinfo.consts if oinfo else []) if t == rt}
                if not consts:
                    return False, f"an integer field without constants cannot hold {w.name}'s values"
                # a value qualified with its type where two messages' constants clash (soundValueOn)
                vals = {v.lower()[len(w.name):] if v.lower()[len(w.name):] in consts and
                        v.lower().startswith(w.name.lower()) else v.lower() for v in w.values}
                if vals != consts:
                    miss, extra = sorted(vals - consts), sorted(consts - vals)
                    return False, (f"its {rt} constants ({', '.join(sorted(consts)).upper()}) do not match "
                                   f"{w.name} {{{', '.join(w.values)}}}"
                                   + (f": no constant for {', '.join(miss)}" if miss else "")
                                   + (f"; constants not in the enumeration: {', '.join(extra).upper()}" if extra else ""))
                return True, ""
            return False, f"{rt} cannot hold an enumeration value (a string or integer constants can)"
        if isinstance(w, T.Scalar):
            if _compatible(rt, w):
                return True, ""
            return False, f"{rt} read as {w.name}"
        if isinstance(w, T.EmptyT):
            return False, "the empty type has no values"
        return False, f"no mapping rule reads {w}"


def _ros_for(t: Any) -> str:
    if isinstance(t, T.Scalar):
        return {"REAL": "float32/float64", "INTEGER": "an integer", "NATURAL": "an integer", "BOOL": "bool",
                "STRING": "string"}[t.name]
    return str(t)
