"""The import every workspace's ``dodo.py`` has had since the first release:
``from rclverify.tasks import build_tasks, doit_config``.

The tasks live in :mod:`rclverify.app.tasks` (docs/architecture.md); this
module keeps ``dodo.py`` files written before the folders were layered
working unchanged.  It is the one module outside a layer folder besides the
package's ``__init__`` (tests/project/test_layers.py)."""
from rclverify.app.tasks import build_tasks, doit_config

__all__ = ["build_tasks", "doit_config"]
