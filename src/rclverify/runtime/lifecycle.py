"""Managed (lifecycle) nodes judged by their state in a live run (docs/monitors.md, "Lifecycle nodes").

The gate itself is :mod:`rclverify.backends.monitors.lifecycle`, one layer down, so that the live
run (:class:`rclverify.runtime.live.LiveRun`), ``rclverify monitor TRACE`` and the pipeline's
monitors backend judge a managed node through the same code; this module gives the live run its
names.
"""
from __future__ import annotations

from rclverify.backends.monitors.lifecycle import (ACTIVE, STATES, TRANSITION_TYPE, TRANSITIONS, LifecycleGate,
                                                   event_topic, gate_of, managed_of, scope_ids, stated_deadlines)

__all__ = ["ACTIVE", "LifecycleGate", "STATES", "TRANSITIONS", "TRANSITION_TYPE", "event_topic", "gate_of",
           "managed_of", "scope_ids", "stated_deadlines"]
