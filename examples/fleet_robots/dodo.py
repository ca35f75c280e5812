"""doit tasks of the fleet_robots example.  `doit verify` runs the whole
pipeline, the fleet's instances and the requirements decided per robot
included; all logic lives in rclverify.app.tasks."""
from pathlib import Path

from rclverify.app.tasks import build_tasks, doit_config

DOIT_CONFIG = doit_config()

globals().update(build_tasks(Path(__file__).parent))
