"""Hypothesis as the property-test runs use it: imported without the
``hypothesis`` entry-point plugins of whatever else is installed.

Hypothesis runs every function registered under its ``hypothesis`` entry
point when it is first imported (its ``entry_points.run``), unless
``HYPOTHESIS_NO_PLUGINS`` is set (Hypothesis's documentation, "Third-party
extensions": entry points).  Such a plugin comes with another package, not
with the workspace: trio's, for one, registers trio's random generator
(``register_random``, which walks the process's heap to check that
generator's referrers) and imports pytest.  A property-test run uses no
registered type strategy (its strategies are made from RCL types,
:mod:`.strategies`), so the plugins cannot change what it draws or
decides; they cost time in every process that imports Hypothesis (0.85 ->
0.55 CPU s for importing :mod:`.harness` with trio installed).

The variable is set only while Hypothesis is imported and restored after, so
a workspace's own processes see the environment they were given.  A process
that had imported Hypothesis before (a pytest session, whose Hypothesis
plugin imports it first) keeps the import it made.  Every import of
Hypothesis in rclverify goes through this module (tests/backends/test_property_tests_plugins.py).
"""
from __future__ import annotations

from rclverify.core.environ import variable_during

with variable_during("HYPOTHESIS_NO_PLUGINS", "1", override=True):
    import hypothesis
    from hypothesis import HealthCheck, Phase, Verbosity, given, settings
    from hypothesis import strategies as st
    from hypothesis.errors import FailedHealthCheck, Unsatisfiable

__all__ = ["hypothesis", "HealthCheck", "Phase", "Verbosity", "given", "settings", "st", "FailedHealthCheck",
           "Unsatisfiable"]
