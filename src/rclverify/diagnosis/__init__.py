"""Diagnosis of every problem the report lists, and repairs checked by Z3.

For each problem of the report (a health finding that is a problem, a
side condition that is not discharged, a refuted requirement, an end-to-end
deadline refuted or not decided, a failed or erroneous evidence record)
:func:`rclverify.diagnosis.build.diagnose` gives one *diagnosis record*: a
sentence naming the culprit by source location, the counterexample as a
table (:mod:`.table`), and repair suggestions, cheapest for the user first
(:mod:`.repairs`, :mod:`.sidecond`, :mod:`.deadline`, :mod:`.constants`),
each of which Z3 has checked on the edited contract or program before it
is listed, saying what Z3 showed and what it did not (docs/diagnosis.md).
"""
