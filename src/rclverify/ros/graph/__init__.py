"""ROS layer b: the computation graph assembled from what ``extract`` read
(``scan``, ``assemble``), from a bag (``bag``), drawn (``draw``), and the
files it was made from (``inputs``).
"""
