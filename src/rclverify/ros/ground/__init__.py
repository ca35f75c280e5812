"""ROS layer d: contracts grounded in the computation graph (``ground``,
``ground_services``, the lifecycle management interface), and NoDL
documents against the code's endpoints (``nodl_code``) and as ``ros diff``'s
expected graph (``diff_nodl``).
"""
