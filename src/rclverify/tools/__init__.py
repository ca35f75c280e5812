"""tools (its place among the layers: docs/architecture.md): what builds on a verified workspace.

``generate/`` (ROS 2 packages from checked contracts), ``lsp/`` (the RCL
language server), ``scaffold/`` (``rclverify init``, also ``--from-ros``).
Imports ``app`` and below.
"""
