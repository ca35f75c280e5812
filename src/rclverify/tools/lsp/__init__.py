"""``rclverify lsp``: the RCL language server.

A Language Server Protocol server over stdio, built on pygls and
lsprotocol, for the ``.rcl`` files of a workspace and its plan
(``contracts/plan.yaml``).  It sits at the top of the layers, beside the
command line: it reads the contracts with the ``rcl`` layer, the plan with
the ``plan`` layer, the connections with the ``system`` layer and the last
run's findings from the files the report wrote (``reports/assurance.sarif``
and ``reports/assurance.json``); it runs no verification stage itself.

Modules: :mod:`.workspace` (the workspace root, file names, which files are
checked together), :mod:`.diagnostics` (parse, type, unit and lint errors of
the unsaved text), :mod:`.lastrun` (the last run's findings, stale once the
text changes), :mod:`.index` (what is at a position), :mod:`.hover`,
:mod:`.navigate` (definition, references), :mod:`.actions` (quick fixes,
formatting), :mod:`.complete`, :mod:`.lines` (LSP's lines: ``\r\n``, ``\r``,
``\n``), :mod:`.rpc` (every request answered in one line), :mod:`.server`
(the pygls handlers).
"""
