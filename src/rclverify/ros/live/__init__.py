"""ROS layer c: the running system: the ROS 1 master (``master``,
``master_rpc``), ROS 2's conventions on DDS (``dds``, ``dds_qos``,
``dds_discovery``, ``type_hash``) and ``ros diff`` against either
(``diff``, ``diff_dds``).
"""
