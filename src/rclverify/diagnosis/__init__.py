"""Diagnosis of every problem the report lists, and repairs checked by Z3.

For each problem of the report dict (a health finding that is a problem, a
side condition that is not discharged, a failed or erroneous evidence
record) :func:`rclverify.diagnosis.build.diagnose` gives one *diagnosis
record*: a sentence naming the culprit by source location, the
counterexample as a table (:mod:`.table`), and repair suggestions
(:mod:`.repairs`) each of which Z3 has checked on the edited contract or
program before it is listed (docs/diagnosis.md).
"""
