"""records (its place among the layers: docs/architecture.md): the formats every stage writes and the report reads.

Obligations and evidence records (``records``), their atomic store
(``store``), sealed stage records (``sealed``) and their types
(``stage_records``), the lines that tie a kept query to the statement it
decides and a kept proof to its query (``ties``), published artifacts,
run-based statistics, the one status vocabulary (``statuses``), the
assurance report's schema as types (``report_schema``, its NoDL part
``nodl_rows``), the records
defined once as msgspec Structs: the contract-health finding
(``findings``) and every part of the report (``obligations``,
``evidence_rows``, ``requirement_rows``, ``statistics_rows``,
``standards_rows``, ``node_rows``, ``derived_rows``, ``strength_rows``,
``side_condition_rows``, ``deadline_rows``, ``margin_rows``,
``solvers_rows``, ``summary_rows``, ``verdict_rows``, ``lint_rows``,
``problem_rows``, ``grounding_rows``, ``nodl_rows``, on one base, ``row``),
the report whole (``report_record``, whose fields are its top-level keys),
and the report's JSON Schema generated from them (``schema_gen``).
Imports ``core``.
"""
