"""Verification backends, registered by the name a plan uses for them.

Implemented: ``hoare`` (Z3), ``dafny`` (Dafny), ``ajpf`` (AJPF/MCAPL
property instances), ``monitors`` (RML/ROSMonitoring, offline trace checking).  Named but not implemented yet (their evidence is
``pending`` with "backend not available"): ``review``, ``experiment``,
``property_tests``.
"""
from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, cast

if TYPE_CHECKING:
    from .base import Backend

IMPLEMENTED = {
    "hoare": ("rclverify.backends.hoare.backend", "HoareBackend"),
    "dafny": ("rclverify.backends.dafny.backend", "DafnyBackend"),
    "ajpf": ("rclverify.backends.ajpf.backend", "AjpfBackend"),
    "monitors": ("rclverify.backends.monitors.backend", "MonitorsBackend"),
}
NOT_AVAILABLE = ("review", "experiment", "property_tests")
KNOWN = tuple(IMPLEMENTED) + NOT_AVAILABLE


def get_backend(name: str) -> "Backend":
    """The backend object for a plan's ``backend:`` value.

    Raises ``KeyError`` for an unknown name (the plan loader reports it,
    located, before this is ever called).
    """
    if name in IMPLEMENTED:
        module, cls = IMPLEMENTED[name]
        return cast("Backend", getattr(import_module(module), cls)())
    if name in NOT_AVAILABLE:
        from .unavailable import UnavailableBackend
        return UnavailableBackend(name)
    raise KeyError(name)
