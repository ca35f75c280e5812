"""doit tasks of the fret_rover example.  `doit verify` runs the whole
pipeline, the requirements imported from FRET included; all logic lives in
rclverify.app.tasks."""
from pathlib import Path

from rclverify.app.tasks import build_tasks, doit_config

DOIT_CONFIG = doit_config()

globals().update(build_tasks(Path(__file__).parent))
