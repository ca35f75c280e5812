"""Safety-standard profiles (``profiles/*.yaml``, checked against ``profile.schema.json``), the plan's
``standards:`` entries and the mapping of a report's evidence rows onto a profile's clauses
(docs/standards.md).  A sub-folder of the plan (model layer): imports ``lang`` and the plan's YAML
reader and errors; the plan's loader imports :mod:`.choice`.
"""
