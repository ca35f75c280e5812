"""runtime (its place among the layers: docs/architecture.md): live monitoring as a product.

The monitors' engine (``backends/monitors``) judging a running robot: the
ROS 1 transport (``ros1``, ``ros1_interfaces``, ``service_proxy``,
``live``), ROS 2 over DDS (``dds/``), enforcement (``enforce``), the
WebSocket oracle (``oracle``), the checking worker, and what a live run
says while it runs (``live_status``: the status line, ``--warn-margin``).  Imports
``backends`` and below.
"""
