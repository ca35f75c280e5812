"""model (its place among the layers: docs/architecture.md): the verification plan (``plan/``) and the system model
built from the checked contracts (``system/``), NoDL node interface documents read and checked
against the contracts (``nodl/``).  Imports ``lang``,
``semantics``, ``traces`` and below.
"""
