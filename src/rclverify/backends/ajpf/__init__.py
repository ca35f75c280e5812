"""AJPF backend: RCL guarantees as AJPF properties of a Gwendolen BDI agent.

Paper lines 1338-1475 (the Agent node verified with AJPF).  Modules:
:mod:`.psl` (AJPF's property language), :mod:`.mapping` (the plan's mapping
table and how its rows match RCL atoms), :mod:`.instantiate` (guarantee ->
property instances), :mod:`.results` (reading AJPF logs), :mod:`.runner`
(finding MCAPL and running it), :mod:`.backend` (:class:`AjpfBackend`).
"""
from .backend import AjpfBackend, AjpfConfig, read_config

__all__ = ["AjpfBackend", "AjpfConfig", "read_config"]
