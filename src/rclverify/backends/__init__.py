"""Verification backends, registered by the name a plan uses for them.

Implemented: ``hoare`` (Z3), ``dafny`` (Dafny), ``ajpf`` (AJPF/MCAPL
property instances), ``property_tests`` (Hypothesis, every example checked
by Z3), ``experiment`` (experiment figures against an acceptance
criterion), ``review`` (code review records), ``monitors``
(RML/ROSMonitoring, offline trace checking).
"""
from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, cast

if TYPE_CHECKING:
    from rclverify.backends.base import Backend

IMPLEMENTED = {
    "hoare": ("rclverify.backends.hoare.backend", "HoareBackend"),
    "dafny": ("rclverify.backends.dafny.backend", "DafnyBackend"),
    "ajpf": ("rclverify.backends.model_checking.ajpf.backend", "AjpfBackend"),
    "property_tests": ("rclverify.backends.property_tests.backend", "PropertyTestsBackend"),
    "experiment": ("rclverify.backends.experiment.backend", "ExperimentBackend"),
    "review": ("rclverify.backends.review.backend", "ReviewBackend"),
    "monitors": ("rclverify.backends.monitors.backend", "MonitorsBackend"),
}
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
