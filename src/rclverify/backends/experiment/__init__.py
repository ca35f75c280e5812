"""The ``experiment`` backend: a node guarantee supported by experiments
(simulation or field trials) judged against an acceptance criterion (paper:
Navigation node, shared/reference lines 1318-1329).

Modules: :mod:`.figures` (data: per-trial CSV or summary statistics, with
units), :mod:`.criterion` (the criterion: an RCL expression over the
figures, checked and evaluated exactly with Z3), :mod:`.consistency` (bounds
every sample's summary statistics obey), :mod:`.plot` (SVG plot with
matplotlib), :mod:`.config` (the plan entry), :mod:`.backend`
(:class:`ExperimentBackend`).
"""
from typing import Any

__all__ = ["ExperimentBackend"]


def __getattr__(name: str) -> Any:
    """``ExperimentBackend`` loaded on first use (PEP 562): ``rclverify check``
    enters the package only for :mod:`.config` (the plan entry's checks)."""
    if name == "ExperimentBackend":
        from rclverify.backends.experiment.backend import ExperimentBackend  # deferred: optional or conditional (inside a block)
        return ExperimentBackend
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
