"""core (its place among the layers: docs/architecture.md): what every layer needs and that knows nothing of RCL.

``faults`` (machine faults worded as one line), ``atomic`` (atomic file
writes, deterministic JSON), ``runlock`` (one run of a workspace at a
time), ``cache/`` (everything kept between runs: one keying function, one
file format), ``numeric`` (numpy and scipy loaded with one OpenBLAS
thread), ``environ`` (a variable set only while a library imports),
``svgplot`` (a matplotlib figure drawn as the same SVG bytes every time).  Imports only the standard library and third-party packages.
"""
