"""rclverify: compositional verification of modular robotic systems.

Data flows one way: RCL text -> AST (:mod:`rclverify.rcl`) -> typed contracts
-> system model (:mod:`rclverify.system`) -> calculus and health
(:mod:`rclverify.calculus`, :mod:`rclverify.health`) -> obligations and
evidence (:mod:`rclverify.backends`, :mod:`rclverify.evidence`) -> assurance
report (:mod:`rclverify.report`).
"""

__version__ = "0.1.0"
