"""Verification backends, registered by the name a plan uses for them.

Each backend's folder holds its code and its ``declaration.yaml`` (name,
implementation, evidence kind and strength, plan entry schema, tools); the one
registry that lists them is :data:`rclverify.model.plan.declarations.REGISTRY`.

Implemented: ``hoare`` (Z3), ``dafny`` (Dafny), ``ajpf`` (AJPF/MCAPL
property instances), ``property_tests`` (Hypothesis, every example checked
by Z3), ``experiment`` (experiment figures against an acceptance
criterion), ``review`` (code review records), ``monitors``
(RML/ROSMonitoring, offline trace checking).
"""
from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, cast

from rclverify.model.plan.declarations import DECLARATIONS

if TYPE_CHECKING:
    from rclverify.backends.base import Backend

#: Backend name -> (module, class) of its implementation, from each backend's ``declaration.yaml``
#: (:mod:`rclverify.model.plan.declarations`, the one registry of backends).
IMPLEMENTED = {name: tuple(d.implementation.split(":", 1)) for name, d in DECLARATIONS.items()}
KNOWN = tuple(IMPLEMENTED)


def get_backend(name: str) -> "Backend":
    """The backend object for a plan's ``backend:`` value.

    Raises ``KeyError`` for an unknown name (the plan loader reports it,
    located, before this is ever called).
    """
    if name in IMPLEMENTED:
        module, cls = IMPLEMENTED[name]
        return cast("Backend", getattr(import_module(module), cls)())
    raise KeyError(name)
