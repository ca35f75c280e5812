"""A NoDL parameter's declared constraints, and whether a value meets them.

The constraints are the validators NoDL borrows from
``generate_parameter_library`` (its ``parameter.schema.yaml``; the
library's README, "Built-In Validators"): ``bounds`` ``[lo, hi]``
(inclusive), ``lt``, ``gt``, ``lt_eq``, ``gt_eq``, ``one_of``, for a number;
``element_bounds``, ``lower_element_bounds``, ``upper_element_bounds``,
``subset_of``, ``unique`` for an array's elements; ``fixed_size``,
``size_gt``, ``size_lt``, ``not_empty`` for a string's or array's length.
Each may be written with or without ``<>``; a comparison's argument is a
number or a list of one.  Validators named with ``::`` (a package's own
functions) and ``additional_constraints`` are not judged: their meaning is
code rclverify does not have.
"""
from __future__ import annotations

from typing import Any, Callable

#: Each judged validator: (what it says in words, whether ``value`` meets argument ``arg``).
_NUMBER: dict[str, tuple[str, Callable[[Any, Any], bool]]] = {
    "bounds": ("within [{0}, {1}]", lambda v, a: a[0] <= v <= a[1]),
    "lt": ("below {0}", lambda v, a: v < a[0]),
    "gt": ("above {0}", lambda v, a: v > a[0]),
    "lt_eq": ("at most {0}", lambda v, a: v <= a[0]),
    "gt_eq": ("at least {0}", lambda v, a: v >= a[0]),
    "one_of": ("one of {0}", lambda v, a: v in a[0]),
}
_ELEMENTS: dict[str, tuple[str, Callable[[Any, Any], bool]]] = {
    "element_bounds": ("every element within [{0}, {1}]", lambda v, a: all(a[0] <= x <= a[1] for x in v)),
    "lower_element_bounds": ("every element at least {0}", lambda v, a: all(x >= a[0] for x in v)),
    "upper_element_bounds": ("every element at most {0}", lambda v, a: all(x <= a[0] for x in v)),
    "subset_of": ("every element one of {0}", lambda v, a: all(x in a[0] for x in v)),
    "unique": ("no element twice", lambda v, a: len(v) == len({repr(x) for x in v})),
}
_SIZE: dict[str, tuple[str, Callable[[Any, Any], bool]]] = {
    "fixed_size": ("of length {0}", lambda v, a: len(v) == a[0]),
    "size_gt": ("longer than {0}", lambda v, a: len(v) > a[0]),
    "size_lt": ("shorter than {0}", lambda v, a: len(v) < a[0]),
    "not_empty": ("not empty", lambda v, a: len(v) > 0),
}


def _args(arg: Any) -> list[Any]:
    """A validator's argument as a list: a bare number is a list of one, ``null`` an empty one."""
    if arg is None:
        return []
    return list(arg) if isinstance(arg, list) else [arg]


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def broken(validation: tuple[tuple[str, Any], ...], value: Any) -> list[str]:
    """What ``value`` breaks among ``validation`` (validator name -> argument, as the document
    writes it), each in words (``within [0, 1]``); empty when it meets them all or when a
    validator does not apply to a value of its kind (a number's validator to a string)."""
    out: list[str] = []
    for raw_name, raw_arg in validation:
        name = raw_name[:-2] if raw_name.endswith("<>") else raw_name
        arg = _args(raw_arg)
        for table, applies in ((_NUMBER, _is_number(value) or name == "one_of"),
                               (_ELEMENTS, isinstance(value, list)),
                               (_SIZE, isinstance(value, (list, str)))):
            if name in table and applies:
                words, meets = table[name]
                try:
                    ok = meets(value, arg)
                except (TypeError, IndexError):  # an argument of another kind than the value: not judged
                    ok = True
                if not ok:
                    out.append(words.format(*arg) if arg else words)
    return out


__all__ = ["broken"]
