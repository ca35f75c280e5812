"""The assurance argument: the report's evidence as a GSN goal structure.

:mod:`.model` holds the plain, serialisable goal structure and the status
propagation (worst child wins); :mod:`.build` builds it from the report dict
(the same data the assurance report shows); :mod:`.export` writes it as JSON,
as YAML in gsn2x's input format, and as a Graphviz diagram.  See
docs/argument.md for the structure and every decision behind it.
"""
