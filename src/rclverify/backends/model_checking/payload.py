"""The ``ajpf`` backend's evidence payload, defined once: :class:`AjpfPayload`.

An evidence record's ``details`` (records/records.py ``Evidence.details``)
is its backend's own JSON object.  An ``ajpf`` obligation's evidence comes
from one of two model checkers, so its payload holds the keys of either:

* SPIN on rclverify's exploration of the agent program (:mod:`.backend`):
  the claim and its property, the state graph's size and bounds, the times
  of each stage, SPIN's verdict and states stored, the Promela model and its
  propositions, and for a violation the lasso over the graph, for a property
  that holds the antecedents witnessed and those that never hold
  (``vacuous``); without SPIN, why and how to install it;
* AJPF itself (:mod:`.ajpf.backend`): its verdict on the numbered property,
  the errors, the search constraints hit and the time it took, from a log
  imported (``imported``, ``property_echoed``) or a run (``returncode``,
  ``timed_out``, ``duration_s``, ``log_file``); a property with unmapped
  atoms names them, a run not made names the command.

Each producer checks its JSON object through the Struct
(:meth:`~rclverify.backends.payload_base.EvidencePayload.checked`) and
writes it unchanged.  A reader decodes the record's ``details`` once, by
its ``backend`` (``backends/payloads.py``
:func:`~rclverify.backends.payloads.payload_of`), and reads attributes mypy
checks.  A key where ``None`` is a value (the stored states, the
constraints, the elapsed time, the exit code, the echo) is
:data:`msgspec.UNSET` when absent; a key no field declares is refused.
"""
from __future__ import annotations

from msgspec import UNSET, UnsetType

from rclverify.backends.payload_base import EvidencePayload
from rclverify.backends.shapes import Antecedent, Lasso
from rclverify.backends.timing_scope import TimingNote

#: a number as the producer wrote it: an int stays an int
Number = int | float


class AjpfPayload(EvidencePayload, frozen=True, tag="ajpf"):
    """An ``ajpf`` obligation's evidence payload, checked by SPIN or by AJPF (module docstring)."""

    # SPIN (backends/model_checking/backend.py): the graph and its bounds, then what SPIN said
    model_checker: str = ""  #: ``spin``
    claim: str = ""  #: the claim's name in the Promela model
    psl: str = ""  #: the property as checked (both checkers)
    states: int = 0  #: the state graph's states
    transitions: int = 0
    complete: bool = False  #: whether the exploration reached every state
    cut: str = ""  #: the bound that cut the exploration
    depth: int = 0
    max_states: int = 0
    max_depth: int = 0
    timeout_s: Number = 0.0
    explore_s: Number = 0.0  #: stage one's seconds
    identifiers: str = ""
    spin_verdict: str = ""  #: ``holds``/``violated``/``incomplete``/``error``/``not run``
    bounded: bool = False  #: SPIN not run because the exploration was cut
    spin_states_stored: int | None | UnsetType = UNSET
    build_s: Number = 0.0
    pan_s: Number = 0.0
    promela: str = ""  #: the Promela model, relative to the workspace
    propositions: dict[str, str] = {}
    lasso: Lasso | None = None  #: a violation's counterexample over the graph
    antecedents: list[Antecedent] = []
    vacuous: list[str] = []  #: why the property holds vacuously
    install: str = ""  #: how to install SPIN (SPIN missing)
    reason: str = ""  #: why the checker was not run (SPIN or MCAPL missing)
    # AJPF (backends/model_checking/ajpf/backend.py)
    unmapped: list[str] = []  #: the atoms without a mapping row (no property)
    command: str = ""  #: the AJPF command to run
    verdict: str = ""  #: AJPF's verdict (``verified``, ``violated`` ...)
    property: int | str = ""  #: the property's number in ``agent.psl``
    errors: list[str] = []  #: the ``error #k`` lines of AJPF's results
    constraints: int | None | UnsetType = UNSET  #: search constraints hit (``None``: not in the log)
    elapsed: str | None | UnsetType = UNSET  #: JPF's elapsed time text
    imported: bool = False  #: the verdict is from a log imported, not a run
    property_echoed: bool | None | UnsetType = UNSET  #: whether the log echoes the property text
    returncode: int | None | UnsetType = UNSET  #: AJPF's exit code (``None``: killed at the timeout)
    timed_out: bool = False
    duration_s: Number = 0.0
    log_file: str = ""  #: the run's log, relative to the workspace
    timing: TimingNote | None = None  #: the timing part of the guarantee this evidence does not check


__all__ = ["AjpfPayload"]
