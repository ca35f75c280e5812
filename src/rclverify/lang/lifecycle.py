"""Lifecycle scopes and transition deadlines of RCL (docs/rcl-language.md, "Lifecycle nodes").

A node's contract declares it a managed (lifecycle) node by naming its transition topic: a topic of
type ``lifecycle_msgs/TransitionEvent`` (``lifecycle_msgs/msg/TransitionEvent`` as well) whose name
ends in ``/transition_event`` and that ``matches`` no variable (:func:`transition_topic`).  Such a
node's contract may

* scope a guarantee to lifecycle states: ``guarantee( out.level >= in.request ) while active``
  (``while S1 or S2 ...``, each a primary state of :data:`PRIMARY_STATES`): the guarantee is asked
  of the questions heard while the node is in one of them;
* bound a transition: ``ready within 200 ms of activate`` (a transition of :data:`TRANSITIONS`): the
  node reaches the state the transition leads to within that time of entering its transition state.

The names follow the ROS 2 design article "Managed nodes" and ``lifecycle_msgs/msg/State`` and
``lifecycle_msgs/msg/Transition``.  The rules checked here (each violation a located diagnostic,
nothing raised): the node is managed; each state and transition is known; a state is named once;
the guarantees of one node share one scope (an unscoped one's is :data:`DEFAULT_SCOPE`); a
transition is bounded once; the bound has a unit of time, a positive amount.
"""
from __future__ import annotations

from typing import Callable

from rclverify.lang import ast

#: The primary states a guarantee may be scoped to (lifecycle_msgs/msg/State labels).
PRIMARY_STATES = ("unconfigured", "inactive", "active", "finalized")
#: The transitions a deadline may bound (lifecycle_msgs/msg/Transition labels).
TRANSITIONS = ("configure", "activate", "deactivate", "cleanup", "shutdown")
#: The scope of an unscoped guarantee of a managed node (its meaning before scopes were written).
DEFAULT_SCOPE = ("active",)

Report = Callable[[ast.Loc, str, str], None]


def transition_topic(n: ast.Node) -> ast.Topic | None:
    """The transition topic of node ``n`` (module docstring), ``None`` when it is not managed."""
    for t in n.topics:
        if t.match is None and t.msg_type.replace("/msg/", "/") == "lifecycle_msgs/TransitionEvent" \
                and t.key.endswith("/transition_event"):
            return t
    return None


def scope_of(n: ast.Node, clause: ast.Clause) -> tuple[str, ...] | None:
    """The lifecycle states guarantee ``clause`` of node ``n`` is judged in: its ``while`` states in
    the order of :data:`PRIMARY_STATES`, :data:`DEFAULT_SCOPE` for an unscoped guarantee of a managed
    node, ``None`` for a node that is not managed (every state: it has none)."""
    if transition_topic(n) is None:
        return None
    if clause.scope is None:
        return DEFAULT_SCOPE
    return tuple(s for s in PRIMARY_STATES if s in clause.scope.states)


def check_node(n: ast.Node, err: Report, seconds: Callable[[ast.Deadline], object]) -> bool:
    """Check the scopes and transition deadlines of node ``n`` (module docstring), reporting through
    ``err(loc, message, code)`` (codes ``E-lifecycle``, ``E-deadline``); ``seconds`` gives a
    deadline's seconds or ``None`` (:func:`rclverify.lang.timing.seconds`).  Returns ``True`` when
    all hold."""
    ok = True
    managed = transition_topic(n) is not None
    why = (f"node {n.name} is not a lifecycle node: name its transition topic in topics(...), "
           f"e.g. lifecycle_msgs/TransitionEvent {n.name.lower()}/transition_event")
    for k, cl in enumerate(n.guarantees, 1):
        sc = cl.scope
        if sc is None:
            continue
        if not managed:
            err(sc.loc, f"guarantee {k} is scoped to lifecycle states ('while {' or '.join(sc.states)}'), but {why}",
                "E-lifecycle")
            ok = False
        for s in sc.states:
            if s not in PRIMARY_STATES:
                err(sc.loc, f"guarantee {k}: {s!r} is not a lifecycle state a guarantee can be scoped to "
                            f"(states: {', '.join(PRIMARY_STATES)})", "E-lifecycle")
                ok = False
        twice = sorted({s for s in sc.states if sc.states.count(s) > 1})
        if twice:
            err(sc.loc, f"guarantee {k}: state {twice[0]} is named twice in its scope", "E-lifecycle")
            ok = False
    if managed and n.guarantees:
        first = scope_of(n, n.guarantees[0])
        for k, cl in enumerate(n.guarantees[1:], 2):
            mine = scope_of(n, cl)
            if mine != first and ok:
                err(cl.scope.loc if cl.scope is not None else cl.loc,
                    f"guarantee {k} is judged while {' or '.join(mine or ())}, guarantee 1 while "
                    f"{' or '.join(first or ())}: the guarantees of one lifecycle node share one scope (an "
                    f"unscoped one: while active), since the monitors ask a node's questions by its state",
                    "E-lifecycle")
                ok = False
                break
    seen: dict[str, ast.Loc] = {}
    for td in n.transitions:
        if not managed:
            d = td.deadline
            err(td.loc, f"a transition deadline ('ready within {d.amount}{' ' + d.unit if d.unit else ''} of "
                        f"{td.transition}'), but {why}",
                "E-lifecycle")
            ok = False
        if td.transition not in TRANSITIONS:
            err(td.loc, f"{td.transition!r} is not a lifecycle transition (transitions: {', '.join(TRANSITIONS)})",
                "E-lifecycle")
            ok = False
        elif td.transition in seen:
            err(td.loc, f"the {td.transition} transition of node {n.name} is bounded twice "
                        f"(first at {seen[td.transition]})", "E-lifecycle")
            ok = False
        seen.setdefault(td.transition, td.loc)
        if seconds(td.deadline) is None:
            d = td.deadline
            err(d.loc, f"transition deadline 'within {d.amount}{' ' + d.unit if d.unit else ''}' needs a unit of "
                       f"time and a positive amount, e.g. 'ready within {d.amount} ms of {td.transition}'",
                "E-deadline")
            ok = False
    return ok


__all__ = ["DEFAULT_SCOPE", "PRIMARY_STATES", "TRANSITIONS", "check_node", "scope_of", "transition_topic"]
