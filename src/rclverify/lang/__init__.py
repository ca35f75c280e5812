"""lang (its place among the layers: docs/architecture.md): RCL text to checked contracts (paper section 3).

The grammar and parser, the AST, the type checker, units, timing, the
printer, LaTeX and lint.  Imports ``core`` and ``records``.
"""
