"""Layer 6, model: the verification plan (``plan/``) and the system model
built from the checked contracts (``system/``).  Imports ``lang``,
``semantics``, ``traces`` and below.
"""
