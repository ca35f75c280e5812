"""C++17 text of RCL formulas for generated ROS 2 nodes: expressions, quantifiers, values and candidate points."""
