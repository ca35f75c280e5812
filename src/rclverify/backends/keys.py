"""The keys an evidence entry of each backend may have.

The table itself is the registry :mod:`rclverify.model.plan.entries` (below both
the plan and the backends, so the plan validates entries without importing
backend code); this module re-exports it for the backends.
"""
from __future__ import annotations

from rclverify.model.plan.entries import COMMON_KEYS, SCHEMAS, allowed_keys, unknown_key_messages

#: Backend name -> the keys of its own configuration.
ENTRY_KEYS: dict[str, tuple[str, ...]] = {name: s.keys for name, s in SCHEMAS.items()}

__all__ = ["COMMON_KEYS", "ENTRY_KEYS", "allowed_keys", "unknown_key_messages"]
