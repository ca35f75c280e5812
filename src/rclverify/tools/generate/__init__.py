"""``rclverify generate``: from checked RCL contracts to ROS 2 packages (docs/generate.md).

The paper's reversed workflow (Luckcuck et al., lines 1864-1866): write and
check the contracts first, then produce the message type definitions and the
node skeletons from them.  Modules by job (the translations they use, RCL types and names to ROS
interface fields and C++ or Python, are in :mod:`rclverify.targets`): :mod:`.interfaces` (the interface packages),
:mod:`.nodes` (one ament_python package per node and the launch files),
:mod:`.namecheck` (the generated names' check),
:mod:`.rosnames` (ROS 2's rules for node, namespace, topic, service and
action names),
:mod:`.writer` (rendering and writing, generated-every-time versus
generated-once files), :mod:`.cli` (the command).
"""
