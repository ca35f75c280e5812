"""AJPF backend: RCL guarantees as AJPF properties of a Gwendolen BDI agent.

Paper lines 1338-1475 (the Agent node verified with AJPF).  Modules:
:mod:`.psl` (AJPF's property language), :mod:`.mapping` (the plan's mapping
table and how its rows match RCL atoms), :mod:`.instantiate` (guarantee ->
property instances), :mod:`.results` (reading AJPF logs), :mod:`.runner`
(finding MCAPL and running it), :mod:`.backend` (:class:`AjpfBackend`).

The package imports none of them: :mod:`.psl` is also the property language
of the SPIN stage (:mod:`rclverify.backends.model_checking`), which
:mod:`.backend` calls, so importing the backend here would close an import
circle.  Import :class:`.backend.AjpfBackend` from :mod:`.backend`.
"""
