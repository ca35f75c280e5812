"""How the task table hands its definitions to doit, cheaply and typed:
``uptodate`` checks with their signature computed once (:func:`signed`), a
``config_changed`` check given its digest once per run (:func:`digested`), and
doit's delayed task creation typed (:func:`create_after`).  Used by
:mod:`rclverify.app.task_table`.
"""
from __future__ import annotations

import hashlib
import inspect
import json
from typing import Any, Callable, Mapping, TypeVar, cast

from doit import create_after as _create_after
from doit.tools import config_changed

_F = TypeVar("_F", bound=Callable[..., Any])
_C = TypeVar("_C", bound=Callable[..., Any])


def signed(check: _C) -> _C:
    """``check`` (a doit ``uptodate`` callable) with its signature computed once: doit calls
    ``inspect.signature`` on every uptodate callable of every task on every run, and an object's own
    ``__signature__`` (PEP 362) answers it at once (about 20 us a call, 4,000 tasks at 1000 nodes)."""
    check.__signature__ = inspect.signature(check)  # type: ignore[attr-defined]
    return check


def digested(config: Mapping[str, object]) -> config_changed:
    """doit's ``config_changed(config)`` given the digest doit would take of
    ``config`` (the md5 of its JSON, keys sorted: doit 0.36-0.37's
    ``_calc_digest``), so the same value is stored and compared, but the
    JSON is encoded once per run instead of once per task and run (4,300
    tasks at 1000 nodes: 0.1 s of a no-op run)."""
    digest = hashlib.md5(json.dumps(config, sort_keys=True).encode("utf-8")).hexdigest()
    return config_changed(digest)


def create_after(executed: str) -> Callable[[_F], _F]:
    """doit's ``create_after`` (delayed task creation), typed."""
    return cast(Callable[[_F], _F], _create_after(executed=executed))
