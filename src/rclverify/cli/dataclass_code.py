"""The methods ``dataclasses`` writes for every class, compiled once and kept between runs (the command's
start-up: docs/monitors.md, "Against its peers").

For each dataclass, ``dataclasses`` writes the source of ``__init__``,
``__repr__``, ``__eq__`` and the rest and runs it with ``exec``: one compile
per method, 699 of them for the modules ``rclverify monitor`` imports, 45 of
its 55 ms in ``dataclasses`` (a fifth of its start-up on a log).  The text
depends only on the class's definition, and compiling the same text with the
same flags gives an equal code object, so :func:`install` puts a function
named ``exec`` in the ``dataclasses`` module (whose ``_create_fn`` calls
``exec`` by that name: Python 3.10 to 3.12) that compiles a text the first
time it meets it, as the builtin would (file name ``"<string>"``, no compiler
flag inherited from the calling module: ``dataclasses`` has no ``__future__``
import, and this module's ``annotations`` would turn the methods'
annotations into strings), keeps the code object under the text and runs it
in the same globals and locals.  Anything but a ``str`` goes to the builtin
unchanged.

The code objects are kept in one file of the user's cache
(:func:`~rclverify.core.cache.keys.user_cache_dir`, ``code/``: not in a
workspace), named for the interpreter's bytecode (its cache tag and magic
number), in ``marshal``'s format: read at the first class, written
atomically at exit when the process compiled a text the file did not hold
(with what it held, unless that passes :data:`MOST` texts: then only the
texts this process used).  A missing, unreadable or damaged file only costs
the compiles.
"""
from __future__ import annotations

import atexit
import builtins
import dataclasses
import marshal
import sys
from pathlib import Path
from types import CodeType
from typing import Any

#: The most texts the file keeps (each class's methods are a few; the modules of every command hold about 2,000).
MOST = 8192

_CODE: dict[str, CodeType] = {}
_USED: set[str] = set()
_STATE = {"loaded": False, "new": False, "installed": False}


def _file() -> Path | None:
    """The cache file for this interpreter's bytecode; ``None`` without a cache folder."""
    from importlib.util import MAGIC_NUMBER  # deferred: start-up (imported where it is used)
    from rclverify.core.cache.keys import user_cache_dir  # deferred: start-up (imported where it is used)
    folder = user_cache_dir("code")
    if folder is None:
        return None
    return folder / f"dataclasses-{sys.implementation.cache_tag}-{MAGIC_NUMBER.hex()}.marshal"


def _load() -> None:
    """The kept code objects into :data:`_CODE` (once; nothing on any fault)."""
    _STATE["loaded"] = True
    try:
        path = _file()
        got = marshal.loads(path.read_bytes()) if path is not None else {}
    except (OSError, EOFError, ValueError, TypeError):
        return
    if type(got) is dict:
        _CODE.update((k, v) for k, v in got.items() if type(k) is str and type(v) is CodeType)


def code_for(text: str) -> CodeType:
    """The code object of ``text`` as ``exec(text)`` compiles it in ``dataclasses``, compiled only on a miss."""
    if not _STATE["loaded"]:
        _load()
    _USED.add(text)
    code = _CODE.get(text)
    if code is None:
        code = _CODE[text] = compile(text, "<string>", "exec", dont_inherit=True)
        _STATE["new"] = True
    return code


def cached_exec(source: Any, globals: dict[str, Any] | None = None, locals: Any = None, /) -> None:
    """``exec`` for ``dataclasses`` (module docstring): a text's code object through :func:`code_for`."""
    builtins.exec(code_for(source) if type(source) is str else source, globals, locals)


def save() -> None:
    """Write the kept code objects when this process compiled one the file did not hold (module docstring)."""
    if not _STATE["new"]:
        return
    keep = _CODE if len(_CODE) <= MOST else {k: v for k, v in _CODE.items() if k in _USED}
    try:
        path = _file()
        if path is not None:
            from rclverify.core.atomic import atomic_write_bytes  # deferred: start-up (only at exit, after a compile)
            atomic_write_bytes(path, marshal.dumps(keep))
    except (OSError, ValueError):
        return
    _STATE["new"] = False


def install() -> None:
    """Give ``dataclasses`` :func:`cached_exec` as its ``exec`` (once per process), and write the kept code
    at exit; nothing where ``dataclasses`` makes its methods otherwise (Python 3.13 on)."""
    if _STATE["installed"] or not hasattr(dataclasses, "_create_fn"):
        return
    _STATE["installed"] = True
    dataclasses.exec = cached_exec  # type: ignore[attr-defined]
    atexit.register(save)


__all__ = ["MOST", "cached_exec", "code_for", "install", "save"]
