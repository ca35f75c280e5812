"""records (its place among the layers: docs/architecture.md): the formats every stage writes and the report reads.

Obligations and evidence records (``records``), their atomic store
(``store``), sealed stage records (``sealed``) and their types
(``stage_records``), the lines that tie a kept query to the statement it
decides and a kept proof to its query (``ties``), published artifacts,
run-based statistics, the one status vocabulary (``statuses``), the
assurance report's schema as types (``report_schema``), the contract-health
finding defined once (``findings``) and the parts of the report's JSON
Schema generated from such definitions (``schema_gen``).  Imports ``core``.
"""
