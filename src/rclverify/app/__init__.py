"""app (its place among the layers: docs/architecture.md): the one orchestrator.

``pipeline`` (the stages run in order), ``tasks`` (the same stages as doit
tasks: what every workspace's ``dodo.py`` imports), ``cluster`` (Dask),
``conetask`` (a node's calculus re-run when its cone changed),
``progress``, ``doitstate``, ``ros_stage`` (the ROS grounding stage) and
``replay`` (one property test replayed from a workspace).  Imports
``report`` and below.
"""
