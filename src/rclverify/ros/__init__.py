"""ros (its place among the layers: docs/architecture.md): the ROS computation graph read from a robot's software, and
contracts grounded in it (docs/ros.md).

Four folders, lowest first, each importing only those before it:
``extract/`` (code, launch files, packages read into graph records),
``graph/`` (the computation graph assembled), ``live/`` (the running system:
ROS 1 master, ROS 2 on DDS, ``ros diff``), ``ground/`` (contracts grounded
in the graph).  Imports ``model`` and below.
"""
