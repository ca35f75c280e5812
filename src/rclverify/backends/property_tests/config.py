"""The plan entry of a property test read and checked, and the user's
implementation imported from it (docs/property-tests.md, "The plan entry").

``{backend: property_tests, implementation: file.py:callable, seed, steps,
max_examples, deadline_ms, bounds, timeout_s}`` becomes a :class:`Config`
(:func:`read_config`; ``bounds: {in.x: [lo, hi]}`` of a numeric input
bounds it, of a sequence of numbers each of its items, docs/property-tests.md,
"Sequences"); :func:`load_implementation` imports the named
callable afresh.  A bad entry is a :class:`ConfigError` carrying the key
path inside the entry, which the backend turns into a located message.
"""
from __future__ import annotations

import importlib.util
import os
import sys
from dataclasses import dataclass, field
from fractions import Fraction
from pathlib import Path
from typing import Any, Mapping

from rclverify.lang import types as T
from rclverify.lang.types import CheckedNode

DEFAULT_MAX_EXAMPLES = 200
DEFAULT_SEED = 20260
DEFAULT_STEPS = 4
#: Wall-clock limit of one guarantee's run when the entry gives no ``timeout_s`` (seconds).
DEFAULT_TIMEOUT_S = 600.0


class ConfigError(Exception):
    """A plan entry the harness cannot use; ``path`` is the key path inside the entry."""

    def __init__(self, message: str, *path: Any) -> None:
        super().__init__(message)
        self.path = path


@dataclass(frozen=True)
class Config:
    """A plan entry ``{backend: property_tests, implementation: file.py:callable, ...}``."""

    implementation: str
    file: str
    attr: str
    max_examples: int = DEFAULT_MAX_EXAMPLES
    seed: int = DEFAULT_SEED
    deadline_ms: int | None = None
    steps: int = DEFAULT_STEPS
    bounds: Mapping[str, tuple[Fraction | None, Fraction | None]] = field(default_factory=dict)
    #: Wall-clock limit of one guarantee's run, in seconds (``timeout_s``; :mod:`..timelimit`).
    timeout_s: float = 600.0


def _positive(raw: Mapping[str, object], key: str, default: int) -> int:
    v = raw.get(key, default)
    if isinstance(v, bool) or not isinstance(v, int) or v < 1:
        raise ConfigError(f"{key} must be a positive integer", key)
    return v


def _boundable(t: T.Type) -> bool:
    """A type the plan's ``bounds`` apply to: a number, or a sequence of numbers (its items)."""
    item = t.elem if isinstance(t, T.SeqT) else t
    return isinstance(item, T.Scalar) and item.name in ("REAL", "INTEGER", "NATURAL")


def read_config(raw: Mapping[str, object], node: CheckedNode, root: Path) -> Config:
    """Validate a plan entry.  Raises :class:`ConfigError` (with the key path)."""
    impl = raw.get("implementation")
    if not isinstance(impl, str) or ":" not in impl:
        raise ConfigError("implementation must be '<file.py>:<callable>' (workspace-relative)", "implementation")
    file, _, attr = impl.rpartition(":")
    if not (root / file).is_file():
        raise ConfigError(f"implementation file {file!r} does not exist", "implementation")
    seed = raw.get("seed", DEFAULT_SEED)
    if isinstance(seed, bool) or not isinstance(seed, int):
        raise ConfigError("seed must be an integer", "seed")
    deadline = raw.get("deadline_ms")
    if deadline is not None and (isinstance(deadline, bool) or not isinstance(deadline, int) or deadline < 1):
        raise ConfigError("deadline_ms must be a positive integer (milliseconds)", "deadline_ms")
    bounds: dict[str, tuple[Fraction | None, Fraction | None]] = {}
    raw_bounds = raw.get("bounds") or {}
    if not isinstance(raw_bounds, Mapping):
        raise ConfigError("bounds must map in.<input> to [lo, hi]", "bounds")
    for k, v in raw_bounds.items():
        name = str(k).removeprefix("in.")
        if name not in node.inputs:
            raise ConfigError(f"{k!r} is not an input of {node.name} ({', '.join(node.inputs)})", "bounds", k)
        if not _boundable(node.inputs[name]):
            raise ConfigError(f"bounds of {k}: {node.inputs[name]} has no numbers to bound (bounds apply to a "
                              f"REAL, INTEGER or NATURAL input, and to the items of a sequence of them)", "bounds", k)
        if (not isinstance(v, list) or len(v) != 2
                or any(x is not None and (isinstance(x, bool) or not isinstance(x, (int, float))) for x in v)):
            raise ConfigError(f"bounds of {k} must be [lo, hi] (numbers or null)", "bounds", k)
        bounds[name] = (None if v[0] is None else Fraction(v[0]), None if v[1] is None else Fraction(v[1]))
    timeout = raw.get("timeout_s", DEFAULT_TIMEOUT_S)
    if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not 0 < timeout <= 86400:
        raise ConfigError("timeout_s must be a number of seconds, above 0 and at most 86400", "timeout_s")
    return Config(impl, file, attr, _positive(raw, "max_examples", DEFAULT_MAX_EXAMPLES), seed, deadline,
                  _positive(raw, "steps", DEFAULT_STEPS), bounds, float(timeout))


def _forget_bytecode(files: set[Path]) -> None:
    """Remove the cached bytecode of the workspace's own files before they are imported.

    Python trusts a ``__pycache__`` file whose recorded source modification
    time (whole seconds) and size match the source: an implementation edited
    within the second it was last imported, to a text of the same length (a
    ``-`` made a ``+``), would run its old code, and its evidence would be of
    a file it does not hash.  With no bytecode left, and none written while
    the workspace's files import, the source itself is always what runs."""
    if sys.implementation.cache_tag is None:  # an interpreter that caches no bytecode
        return
    for f in files:
        try:
            os.unlink(importlib.util.cache_from_source(str(f)))
        except (OSError, ValueError):  # none cached, or a name Python would not cache
            pass


def load_implementation(root: Path, cfg: Config) -> Any:
    """Import the implementation's file afresh, with every workspace module of
    its import closure (:mod:`.closure`) that this process imported before,
    and return the named callable or class.  The import runs with the
    harness's folders first on ``sys.path``
    (:func:`~.importpath.on_harness_path`, the path the closure resolves
    imports with); every module name the closure finds in the workspace is
    imported again, whatever file this process loaded under that name
    before (another implementation's ``helper``).

    Raises :class:`ConfigError` when the file does not import or lacks the name.
    """
    path = (root / cfg.file).resolve()
    from rclverify.backends.property_tests.closure import resolve_closure  # deferred: start-up (loads rclverify.backends.property_tests, ast only when called)
    from rclverify.backends.property_tests.importpath import on_harness_path  # deferred: start-up (as the closure)
    found = resolve_closure(root, cfg.file)
    closure = {(root / f).resolve() for f in found.files}
    names = {p.name for p in closure}
    again = set(found.modules)
    for name, mod in list(sys.modules.items()):  # the workspace modules it imports, afresh too (a long-lived process)
        where = getattr(mod, "__file__", None)
        # the file name first: resolving every loaded module's path cost seconds per run
        if name in again or (where and os.path.basename(where) in names and Path(where).resolve() in closure):
            del sys.modules[name]
    modname = f"rclverify_impl_{abs(hash(str(path)))}"
    spec = importlib.util.spec_from_file_location(modname, path)
    if spec is None or spec.loader is None:
        raise ConfigError(f"cannot import {cfg.file}", "implementation")
    module = importlib.util.module_from_spec(spec)
    sys.modules[modname] = module
    _forget_bytecode(closure | {path})
    dont_write = sys.dont_write_bytecode
    sys.dont_write_bytecode = True
    try:
        with on_harness_path(root, cfg.file):
            spec.loader.exec_module(module)
    except Exception as exc:  # the user's file: any error is theirs
        raise ConfigError(f"importing {cfg.file} failed: {type(exc).__name__}: {exc}", "implementation") from None
    finally:
        sys.dont_write_bytecode = dont_write
    obj = getattr(module, cfg.attr, None)
    if obj is None or not callable(obj):
        raise ConfigError(f"{cfg.file} has no callable {cfg.attr!r}", "implementation")
    return obj
