"""The ``monitors`` backend: RML monitors and a ROSMonitoring configuration
from the contracts, and offline checking of recorded runs (paper lines
791-980; docs/monitors.md).

:mod:`rclverify.targets.rml` translates guarantees to RML, :mod:`.config` reads the plan
entry and the mapping file, :mod:`.check` checks a trace against a node's
contract, :mod:`.margin_target` counts a margin target's trials on a run,
:mod:`.near_miss` reads an entry's near-miss threshold, :mod:`.backend` is
the plug-in (export, run).
"""
