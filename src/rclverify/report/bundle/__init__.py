"""The assessor's bundle: one archive with the reports, every artifact and
evidence record, the plan, the contracts and every file the plan names, plus
``MANIFEST.json`` (sha256 of every file, tool versions, the command that
reproduces it).  :mod:`.manifest` collects the files and versions,
:mod:`.archive` writes and verifies archives.  See docs/argument.md.
"""
