"""doit tasks of this workspace.  `doit verify` runs the whole pipeline;
`doit list` shows the stages; `doit verify --strict` fails unless every
obligation is discharged.  All logic lives in rclverify.tasks."""
from pathlib import Path

from rclverify.progress import ProgressReporter
from rclverify.tasks import build_tasks

DOIT_CONFIG = {"default_tasks": ["verify"], "verbosity": 2, "dep_file": ".doit.db", "reporter": ProgressReporter}

globals().update(build_tasks(Path(__file__).parent))
