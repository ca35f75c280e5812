"""Errors in the verification plan (or in files it points at).

A :class:`PlanError` is an :class:`~rclverify.lang.errors.RclError`: it
carries located diagnostics (``plan.yaml:line:col``) and is reported the same
way, one clear message and a non-zero exit.
"""
from __future__ import annotations

from rclverify.lang.ast import Loc
from rclverify.lang.errors import RclError, error


class PlanError(RclError):
    """A user mistake in the plan or in a file the plan names."""


def plan_error(file: str, line: int, col: int, message: str, code: str = "E-plan") -> PlanError:
    """Build a :class:`PlanError` with one diagnostic at ``file:line:col``."""
    return PlanError([error(Loc(file, line, col), message, code)])
