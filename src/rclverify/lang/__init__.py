"""Layer 3, lang: RCL text to checked contracts (paper section 3).

The grammar and parser, the AST, the type checker, units, timing, the
printer, LaTeX and lint.  Imports ``core`` and ``records``.
"""
