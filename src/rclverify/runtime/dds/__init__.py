"""The live monitor over DDS, ROS 2's wire (docs/monitors.md): message types
made from the ``.msg`` files, the bus and its readers, services, the bag
recorder and the live loop.
"""
