"""The dataclass methods compiled once and kept between runs (rclverify/cli/dataclass_code.py): the methods
are the ones ``dataclasses`` makes with the builtin ``exec``, and the kept file is read, rewritten only when
a text was compiled, and a damaged one costs only the compiles."""
from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any, Callable, ClassVar, Optional

import pytest

from rclverify.cli import dataclass_code

pytestmark = pytest.mark.skipif(not hasattr(dataclasses, "_create_fn"), reason="dataclasses makes its methods "
                                "otherwise here (the module installs nothing)")

SRC = Path(__file__).resolve().parents[2] / "src"
_METHODS = ("__init__", "__repr__", "__eq__", "__lt__", "__le__", "__gt__", "__ge__", "__hash__", "__setattr__",
            "__delattr__", "__getstate__", "__setstate__")


def _classes() -> list[type]:
    """Dataclasses of most kinds ``dataclasses`` writes methods for, made by whatever ``exec`` it has now."""
    made: list[type] = []

    @dataclasses.dataclass
    class Plain:
        a: int
        b: str = "x"
        c: list[int] = dataclasses.field(default_factory=list)
        k: ClassVar[int] = 3
    made.append(Plain)

    @dataclasses.dataclass(frozen=True, order=True)
    class Frozen:
        x: float
        y: Optional[float] = None
        z: tuple[int, ...] = ()
    made.append(Frozen)

    @dataclasses.dataclass(eq=False, repr=False)
    class Bare:
        f: Callable[[int], int]
        g: Any = dataclasses.field(default=None, compare=False, repr=False)
    made.append(Bare)

    @dataclasses.dataclass(slots=True, kw_only=True)
    class Slotted:
        p: int
        q: dict[str, int] = dataclasses.field(default_factory=dict)
    made.append(Slotted)

    @dataclasses.dataclass(frozen=True, slots=True)
    class FrozenSlots:
        r: bytes
        s: int = dataclasses.field(default=2, kw_only=True)

        def __post_init__(self) -> None:
            object.__setattr__(self, "s", self.s)
    made.append(FrozenSlots)

    @dataclasses.dataclass(unsafe_hash=True)
    class Hashed(Plain):
        d: float = 1.5
        e: dataclasses.InitVar[int] = 0

        def __post_init__(self, e: int) -> None:
            self.d += e
    made.append(Hashed)
    return made


def _shape(cls: type) -> list[Any]:
    """What each generated method is: its code (compared by value, and its file name), annotations,
    defaults and closure's contents."""
    out: list[Any] = []
    for name in _METHODS:
        fn: Any = cls.__dict__.get(name)
        code = getattr(fn, "__code__", None)
        if code is None:
            out.append((name, fn is None))
            continue
        cells = tuple(c.cell_contents for c in fn.__closure__ or ())
        out.append((name, code, code.co_filename, code.co_firstlineno, dict(fn.__annotations__), fn.__defaults__,
                    fn.__kwdefaults__, tuple(_named(c) for c in cells)))
    return out


def _named(value: Any) -> Any:
    """A closure's content as compared: a class by its qualified name (each making of the classes makes
    new ones), a number, text or tuple itself, anything else by its type's name."""
    if isinstance(value, type):
        return value.__qualname__
    return value if isinstance(value, (int, str, tuple)) else type(value).__qualname__


def _made_with(exec_fn: Callable[..., None] | None) -> list[list[Any]]:
    """The classes' shapes with ``exec_fn`` as ``dataclasses``' ``exec`` (``None``: the builtin's)."""
    had = dataclasses.__dict__.get("exec")
    try:
        if exec_fn is None:
            dataclasses.__dict__.pop("exec", None)
        else:
            dataclasses.exec = exec_fn  # type: ignore[attr-defined]
        return [_shape(c) for c in _classes()]
    finally:
        if had is None:
            dataclasses.__dict__.pop("exec", None)
        else:
            dataclasses.exec = had  # type: ignore[attr-defined]


def test_the_methods_are_the_builtin_execs() -> None:
    """Every method, compiled or taken from the kept texts, is the one the builtin ``exec`` makes: the same
    code, file name, line, annotations (objects, not strings), defaults and closure; the instances behave
    alike."""
    want = _made_with(None)
    assert _made_with(dataclass_code.cached_exec) == want  # compiled now, or found among the kept texts
    assert _made_with(dataclass_code.cached_exec) == want  # found: the texts are kept
    init = [s for s in want[0] if s[0] == "__init__"][0]
    assert init[4]["return"] is None  # an object, not the text "None" (dataclasses has no ``annotations`` future)
    plain, frozen = _classes()[:2]
    assert plain(1) == plain(1, "x", []) and repr(plain(2)).endswith("Plain(a=2, b='x', c=[])")
    assert frozen(1.0) < frozen(2.0) and hash(frozen(1.0, 2.0)) == hash(frozen(1.0, 2.0))


def test_control_a_text_compiled_with_this_modules_flags_is_another_method() -> None:
    """The control: compiled as ``compile`` compiles it here (inheriting this module's ``annotations``
    future), the methods' annotations are strings, which the comparison above catches."""
    def inheriting(source: Any, globals: Any = None, locals: Any = None, /) -> None:
        exec(compile(source, "<string>", "exec") if type(source) is str else source, globals, locals)
    assert _made_with(inheriting) != _made_with(None)


_PROBE = """
import json, sys
from rclverify.cli import dataclass_code
import rclverify.lang.ast  # classes of its own: their methods compiled or read
print(json.dumps({"new": dataclass_code._STATE["new"], "kept": len(dataclass_code._CODE)}))
"""


def _probe(cache: Path) -> dict[str, Any]:
    env = {**os.environ, "XDG_CACHE_HOME": str(cache), "PYTHONPATH": str(SRC)}
    p = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True, env=env, timeout=120)
    assert p.returncode == 0, p.stderr
    got: dict[str, Any] = json.loads(p.stdout)
    return got


def test_the_kept_file_is_read_and_written_only_after_a_compile(tmp_path: Path) -> None:
    """A first process compiles and writes the file; the next reads it and compiles nothing (no write);
    a damaged file is read as none, and the process compiles and writes it again."""
    first = _probe(tmp_path)
    assert first["new"] and first["kept"] > 20
    files = list((tmp_path / "rclverify" / "code").iterdir())
    assert len(files) == 1 and files[0].name.startswith("dataclasses-")
    stamp = files[0].stat().st_mtime_ns
    again = _probe(tmp_path)
    assert not again["new"] and again["kept"] >= first["kept"]
    assert files[0].stat().st_mtime_ns == stamp  # nothing compiled: not written
    files[0].write_bytes(b"\x00 not marshal data")
    damaged = _probe(tmp_path)
    assert damaged["new"]
    assert not _probe(tmp_path)["new"]  # written again whole
