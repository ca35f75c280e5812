"""Everything rclverify keeps between runs, in one place.

Results that outlive a process are either **doit's** (a task's file
dependencies, its ``config_changed`` code stamp and the evidence record's
seal decide whether it runs again: :mod:`rclverify.app.tasks`; ``doit info
TASK`` says why a task is not up to date) or **kept here**, under
``artifacts/cache/``, with one keying function (:mod:`.keys`), one file
format and one rule of what is kept (:mod:`.store`):

=====================================  ===================  ==========================================
file                                   kind                 keyed by
=====================================  ===================  ==========================================
``workspace.pickle``                   ``workspace``        sha256 of the plan and each contract file,
                                                            what each plan path resolves to
                                                            (:mod:`.workspace`)
``contract-texts.pickle``              ``contract-texts``   sha256 of each contract file's parsed text
                                                            (:mod:`rclverify.stages.contract_texts`)
``report-fragments.<part>.pickle``     ``report-fragments`` fingerprint of the data a piece shows
                                                            (:mod:`rclverify.report.fragments`)
``layout/<key>.svg``                   ``layout``           the DOT text and the ``dot`` program
                                                            (:mod:`rclverify.report.layoutcache`)
``summaries/<key>.json``               ``summaries``        a cone summary's inputs as text, its
                                                            producers' keys, Z3's version
                                                            (:mod:`rclverify.calculus.summary`)
``diagnosis.pickle``                   ``diagnosis``        the problem, the contract and plan files,
                                                            the program (:mod:`rclverify.diagnosis.build`)
``ros-scan.pickle``                    ``ros-scan``         sha256 of each scanned source file
                                                            (:mod:`rclverify.ros.extract.cache`)
``system-cycles.pickle``               ``system-cycles``    the system model's nodes and links
                                                            (:func:`rclverify.model.system.model.cycles_kept`)
=====================================  ===================  ==========================================

The files are read by :mod:`.safeload`, which constructs only
rclverify's own value classes: a poisoned pickle in a cloned workspace is
a cache miss, never run.  jinja2's compiled templates, which are code, are
kept in the user's cache (:func:`.keys.user_cache_dir`), not here; so is
what ``rclverify monitor`` computes at every start from its inputs'
content alone (:mod:`.startup`: parsed contracts, the plan's schema check,
the compiled formulas' sources, Z3's answers), keyed by that content.

Every key also holds the kind's salt: the cache format, the rclverify code
and the versions of the programs whose output is kept.  Deleting
``artifacts/cache`` is always safe; ``rclverify cache`` lists what it holds.

:mod:`.heap` decides when Python's collector looks at what a run keeps
live; :mod:`.memo` keeps one result per function for a report run.
"""
from rclverify.core.cache.keys import CACHE_DIR, Keyer, code_stamp, file_digest, fingerprint, salt
from rclverify.core.cache.store import Blobs, Shelf, kept_files, read_stream, write_stream

__all__ = ["CACHE_DIR", "Blobs", "Keyer", "Shelf", "code_stamp", "file_digest", "fingerprint",
           "kept_files", "read_stream", "salt", "write_stream"]
