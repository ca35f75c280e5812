"""doit tasks of the manipulator example.  `doit verify` runs the whole
pipeline; `doit list` shows the stages; `doit verify --strict` fails unless
every obligation is discharged.  All logic lives in rclverify.app.tasks."""
from pathlib import Path

from rclverify.app.tasks import build_tasks, doit_config

DOIT_CONFIG = doit_config()

globals().update(build_tasks(Path(__file__).parent))
