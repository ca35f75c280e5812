"""Reading kept files without running code from them.

The files under ``artifacts/cache/`` are pickles (:mod:`.store`), and a
workspace is often a clone of someone else's repository: a pickle in it
may name any importable callable (``os.system``), which the standard
unpickler would call.  :func:`load` reads a pickle with an unpickler whose
``find_class`` (the only way a pickle reaches a callable: the ``GLOBAL``,
``STACK_GLOBAL``, ``INST`` and extension opcodes) answers only for the
values rclverify keeps (docs/scale.md, "What is kept between runs"):

* a class **defined in an rclverify module** (``cls.__module__`` is the
  module the pickle names, the name has no dots: ``rclverify.cli.commands`` /
  ``os.system`` is refused) that is a **dataclass**, an **enumeration** or
  a **named tuple**: constructing one stores its fields (a
  ``__post_init__`` normalises them) and does nothing else;
* :data:`EXTRA`: ``pathlib``'s path classes, ``set``/``frozenset``/``complex``,
  jinja2's ``Markup`` string, ``rosbags``' ``Nodetype`` enumeration, and ``Fraction`` through a constructor
  that accepts only ``n`` and ``n/d`` with at most 4,300 digits (a
  ``Fraction("1e999999999")`` would compute for hours).

Anything else raises :class:`pickle.UnpicklingError` before it is called;
the readers treat it as a damaged file, a cache miss.  A poisoned file
therefore costs its recomputation, never code execution.  What an allowed
class holds is data: a forged entry can mislead like any edited file of the
workspace (evidence seals are checksums, not signatures: docs/integrity.md).
"""
from __future__ import annotations

import dataclasses
import enum
import importlib
import io
import pathlib
import pickle
import re
from fractions import Fraction
from functools import lru_cache
from typing import Any, BinaryIO, Callable, TypeGuard

_RATIONAL = re.compile(r"-?\d{1,4300}(/\d{1,4300})?")


def _fraction(*args: Any) -> Fraction:
    """``Fraction(*args)`` for what ``Fraction.__reduce__`` writes: the
    numerator and denominator as integers, or (older Pythons) the text
    ``n`` or ``n/d``; raises ``UnpicklingError`` for anything else."""
    if len(args) == 2 and all(type(a) is int for a in args):
        return Fraction(*args)
    if len(args) == 1 and isinstance(args[0], str) and _RATIONAL.fullmatch(args[0]):
        return Fraction(args[0])
    raise pickle.UnpicklingError("a kept Fraction is written as two integers or as n or n/d")


def _nodetype() -> Any:
    try:
        from rosbags.interfaces import Nodetype  # deferred: optional or conditional (inside a block)
    except ImportError:
        return None
    return Nodetype


def _markup() -> Any:
    try:
        from markupsafe import Markup  # deferred: optional or conditional (inside a block)
    except ImportError:  # pragma: no cover - a dependency of jinja2
        return None
    return Markup


#: The classes from outside rclverify that kept values may hold, by
#: ``(module, name)`` as a pickle names them.
EXTRA: dict[tuple[str, str], Callable[[], Any]] = {
    ("pathlib", "PosixPath"): lambda: pathlib.PosixPath,
    ("pathlib", "PurePosixPath"): lambda: pathlib.PurePosixPath,
    ("pathlib", "WindowsPath"): lambda: pathlib.WindowsPath,
    ("pathlib", "PureWindowsPath"): lambda: pathlib.PureWindowsPath,
    ("builtins", "set"): lambda: set,
    ("builtins", "frozenset"): lambda: frozenset,
    ("builtins", "complex"): lambda: complex,
    ("__builtin__", "set"): lambda: set,  # protocols 0-2 name the builtins as Python 2 did
    ("__builtin__", "frozenset"): lambda: frozenset,
    ("__builtin__", "complex"): lambda: complex,
    ("fractions", "Fraction"): lambda: _fraction,
    ("markupsafe", "Markup"): _markup,
    ("rosbags.interfaces", "Nodetype"): _nodetype,  # the kind of a parsed message field (ros-scan)
    ("builtins", "getattr"): lambda: _enum_member,  # an enum member as Python 3.11.0-3.11.3 pickle it
}


def _enum_member(cls: Any, name: Any) -> Any:
    """``cls[name]`` for an enumeration a kept file may name: how Python 3.11.0
    to 3.11.3 pickle an enum member (``getattr(cls, name)``, Debian 12's
    Python; later versions pickle it by value).  Raises
    ``pickle.UnpicklingError`` for anything else, so ``getattr`` reaches no
    other attribute of any object."""
    if not (isinstance(cls, type) and issubclass(cls, enum.Enum) and isinstance(name, str)
            and name in cls.__members__):
        raise pickle.UnpicklingError("getattr in a kept file names no member of an enumeration")
    return cls[name]


def _is_value_class(obj: object) -> TypeGuard[type]:
    return (isinstance(obj, type) and not issubclass(obj, BaseException)
            and (dataclasses.is_dataclass(obj) or issubclass(obj, enum.Enum)
                 or (issubclass(obj, tuple) and hasattr(obj, "_fields"))))


@lru_cache(maxsize=None)
def allowed(module: str, name: str) -> Any | None:
    """The class a kept file may name as ``module``.``name`` (see the module
    docstring), or ``None``.  Imports only rclverify's own modules."""
    extra = EXTRA.get((module, name))
    if extra is not None:
        return extra()
    if not (module.startswith("rclverify.") and name.isidentifier()):
        return None
    if not all(part.isidentifier() and not part.startswith("_") for part in module.split(".")):
        return None  # no private module, no ``__main__`` (importing it would run the command line)
    try:
        mod = importlib.import_module(module)
    except Exception:  # noqa: BLE001 - no such module of the package: not a class it keeps
        return None
    obj = getattr(mod, name, None)
    if not _is_value_class(obj) or obj.__module__ != module or obj.__qualname__ != name:
        return None
    return obj


class SafeUnpickler(pickle.Unpickler):
    """An unpickler that constructs only the classes :func:`allowed` names."""

    def find_class(self, module: str, name: str) -> Any:
        obj = allowed(module, name)
        if obj is None:
            raise pickle.UnpicklingError(f"{module}.{name} is not a value rclverify keeps")
        return obj


def load(fh: BinaryIO) -> Any:
    """The next object of the pickle stream ``fh`` (:class:`SafeUnpickler`).
    Raises ``pickle.UnpicklingError`` for a class rclverify does not keep,
    ``EOFError`` at the end of the stream and whatever a damaged stream
    raises (``ValueError``, ``TypeError``, ...)."""
    return SafeUnpickler(fh).load()


def loads(data: bytes) -> Any:
    """:func:`load` of one pickle held in ``data``."""
    return load(io.BytesIO(data))
