"""``python -m rclverify.cli``: the ``rclverify`` command."""
import sys

from rclverify.cli import main

sys.exit(main())
