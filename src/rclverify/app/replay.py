"""Re-run one property-test obligation from a workspace on disk.

What the pytest files that the property_tests backend writes
(``artifacts/property_tests/<Node>/test_<node>_e<entry>.py``) call: the
workspace is loaded as ``doit verify`` loads it (:class:`rclverify.app.pipeline.Workspace`)
and the guarantee is run by the backend's own code
(:mod:`rclverify.backends.property_tests.harness`), so the file passes
exactly when the evidence is ``discharged`` (docs/property-tests.md).

It sits in the app layer (docs/architecture.md): it needs
the pipeline's workspace, and a backend must not import the pipeline.
"""
from __future__ import annotations

from pathlib import Path

from rclverify.backends.property_tests.harness import Outcome, read_config, run_guarantee
from rclverify.stages.workspace import Workspace


def check_from_workspace(root: Path, plan_file: str, node: str, entry: int, guarantee: int) -> Outcome:
    """Run guarantee ``guarantee`` (1-based) of ``node``'s property-test plan entry
    ``entry`` (its index among the node's evidence entries) in the workspace at
    ``root`` with plan ``plan_file`` (workspace-relative), exactly as the backend does.

    Returns the harness's :class:`~rclverify.backends.property_tests.harness.Outcome`.
    Raises :class:`~rclverify.lang.errors.RclError` / ``PlanError`` for contracts or a
    plan that do not load, and
    :class:`~rclverify.backends.property_tests.harness.ConfigError` for an
    implementation that cannot be loaded.
    """
    target = Workspace(root, plan_file).target(node, entry)
    cfg = read_config(target.config, target.node, target.root)
    return run_guarantee(target.checked, target.node, guarantee, cfg, target.root, target.facts,
                         mapping=target.mapping)


__all__ = ["check_from_workspace"]
