"""model (its place among the layers: docs/architecture.md): the verification plan (``plan/``) and the system model
built from the checked contracts (``system/``).  Imports ``lang``,
``semantics``, ``traces`` and below.
"""
