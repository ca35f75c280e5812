"""rclverify: compositional verification of modular robotic systems.

Data flows one way: RCL text -> AST (:mod:`rclverify.lang`) -> typed contracts
-> system model (:mod:`rclverify.model.system`) -> calculus and health
(:mod:`rclverify.calculus`, :mod:`rclverify.calculus.health`) -> obligations and
evidence (:mod:`rclverify.backends`, :mod:`rclverify.records`) -> assurance
report (:mod:`rclverify.report`).
"""

__version__ = "0.1.0"
