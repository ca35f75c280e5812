"""Which Python runs the rclpy agent, and which source a live ROS 2 run uses.

The sources (docs/ros2.md, "Two sources"): ``rclpy`` (the agent,
:mod:`.agent`, in a ROS 2 Python) and ``dds`` (rclverify's own Cyclone DDS
participant, :mod:`rclverify.runtime.dds.live`).  ``auto`` takes rclpy
where rclverify's own Python imports it (a sourced ROS 2 installation, or
ROS 2's wheels beside rclverify), else DDS; a ROS 2 Python elsewhere
(``--ros2-python``, ``RCLVERIFY_ROS2_PYTHON``) is used when ``rclpy`` is
asked.
"""
from __future__ import annotations

import importlib.util
import os
import sys
from pathlib import Path

SOURCES = ("auto", "rclpy", "dds")


def ros2_python(named: str | None = None) -> Path | None:
    """The ROS 2 Python: ``named`` (``--ros2-python``), else
    ``RCLVERIFY_ROS2_PYTHON``, else this Python when it can import rclpy (a
    sourced ROS 2 installation, or ROS 2's wheels installed beside
    rclverify); ``None`` when there is none."""
    for candidate in (named, os.environ.get("RCLVERIFY_ROS2_PYTHON")):
        if candidate:
            return Path(candidate)
    if importlib.util.find_spec("rclpy") is not None:
        return Path(sys.executable)
    return None


def pick_source(source: str, named: str | None = None) -> tuple[str, Path | None, str]:
    """``(source, ros2 python, why)`` for the asked ``source`` (:data:`SOURCES`):
    ``auto`` is ``rclpy`` where this Python imports rclpy, else ``dds``;
    ``why`` says in one clause why that source.  Raises ``ValueError`` (one
    line) for ``rclpy`` without a ROS 2 Python."""
    py = ros2_python(named)
    if source == "dds":
        return "dds", None, "asked (--source dds)"
    if source == "rclpy":
        if py is None:
            raise ValueError("--source rclpy needs a Python with rclpy: source your ROS 2 installation's "
                             "setup.bash, or name its Python with --ros2-python or RCLVERIFY_ROS2_PYTHON")
        return "rclpy", py, "asked (--source rclpy)"
    if importlib.util.find_spec("rclpy") is not None:
        return "rclpy", Path(sys.executable), "rclpy is importable in rclverify's Python"
    return "dds", None, "rclpy is not importable in rclverify's Python (--source rclpy with --ros2-python uses another)"


__all__ = ["SOURCES", "pick_source", "ros2_python"]
