"""The backends' JSON records as types: an obligation's ``data`` and an evidence's ``details``.

One TypedDict per record a backend writes into the evidence (docs/backends.md):
the Hoare backend's triple (:class:`HoareData`, :class:`HoareTriple`), Dafny's
diagnostics (:class:`DafnyDetails`), a review record's checklist
(:class:`ReviewDetails`), an experiment's figures (:class:`ExperimentDetails`),
a property test's coverage (:class:`InputCoverage`), the
declarations' verdict rows the property tests and the monitors share
(:class:`DeclarationRow`), SPIN's lasso (:class:`SpinDetails`, :class:`Lasso`),
an AJPF obligation (:class:`AjpfData`, :class:`AcceptingPath`), and the
search tree the Promela template walks (:class:`PromelaLeaf`,
:class:`PromelaSplit`).  The monitors' records are in
:mod:`rclverify.backends.monitors.shapes`; each backend's evidence
``details`` is a msgspec Struct declared beside it (``backends/<backend>/payload.py``,
decoded by ``backends/payloads.py``), whose fields use these types.
"""
# No ``from __future__ import annotations``: Python 3.11 reads ``NotRequired`` only from evaluated
# annotations (with string annotations every key would count as required).
from typing import NotRequired, TypedDict


class HoareData(TypedDict):
    """A Hoare obligation's ``data``: the program, the conjunct it proves and how (``vcs``), or why pending."""
    program: str
    guarantee: int
    conjunct: int
    conjunct_rcl: str
    binding: dict[str, str]
    conjunct_source: str
    timeout_ms: int
    pending: NotRequired[str]
    vcs: NotRequired[list[str]]


class HoareTriple(TypedDict):
    """A triple's pre- and postcondition as printed."""
    pre: str
    post: str


class DafnyPlace(TypedDict):
    """A Dafny diagnostic's place and text (a warning, or a related location of an error)."""
    file: str
    line: int
    col: int
    message: str


class DafnyError(TypedDict):
    """One Dafny error or time-out, with the RCL clause its stub line holds (``clause`` ... ``rcl``)."""
    severity: str
    file: str
    line: int
    col: int
    message: str
    code: str
    related: list[DafnyPlace]
    clause: NotRequired[str]
    role: NotRequired[str]
    index: NotRequired[int]
    rcl: NotRequired[str]
    guarantee: NotRequired[int]


class RefiningModule(TypedDict):
    """A module of the implementation that refines the stub, and its line."""
    module: str
    line: int


class UnsoundConstruct(TypedDict):
    """A construct Dafny does not prove (``assume``, ``{:extern}`` ...), and its line."""
    line: int
    construct: str


class DafnyRefutation(TypedDict):
    """One sought refutation of a guarantee clause Dafny could not prove (backends/dafny/refute.py):
    ``clause`` ``"2"`` or ``"2.1"``, ``rcl`` its RCL location, ``inputs`` the pinned inputs (RCL name ->
    value text), ``status`` ``refuted`` or ``not refuted`` with the ``reason``, ``artifact`` its stub."""
    guarantee: int
    conjunct: int
    clause: str
    rcl: str
    inputs: dict[str, str]
    status: str
    reason: str
    artifact: str


class DafnyDetails(TypedDict):
    """A Dafny run's evidence ``details``: its counts, diagnostics and a verdict per guarantee."""
    verified: int
    errors: list[DafnyError]
    error_count: int
    timeouts: int
    other_outcomes: int
    warnings: list[DafnyPlace]
    exit_code: int | None
    parse_errors: int
    resolution_errors: int
    prover_messages: list[str]
    cli: str
    guarantees: NotRequired[dict[str, str]]
    refining_modules: NotRequired[list[RefiningModule]]
    unsound_constructs: NotRequired[list[UnsoundConstruct]]
    command: NotRequired[str]
    log_filtered: NotRequired[list[str]]
    refutations: NotRequired[list[DafnyRefutation]]


class DafnyScan(TypedDict):
    """What the scan of a Dafny implementation adds to the evidence ``details``."""
    refining_modules: list[RefiningModule]
    unsound_constructs: list[UnsoundConstruct]


class ReviewedFile(TypedDict):
    """A file a review covers, with its sha256 at the review."""
    path: str
    sha256: str


class ChecklistAnswer(TypedDict):
    """One checklist question and the reviewer's answer (``None``: unanswered)."""
    id: str
    question: str
    location: str
    answer: str | None
    note: str


class ReviewDetails(TypedDict):
    """A review record's evidence ``details``: ``author`` who wrote what was reviewed (``""``: not named),
    ``independence`` the record's stated level (``""``: not stated)."""
    reviewer: str
    author: str
    independence: str
    date: str
    scope: str
    files: list[ReviewedFile]
    verdict: str | None
    checklist: list[ChecklistAnswer]
    record: NotRequired[str]
    figures_table: NotRequired[list[list[str]]]


class FigureJson(TypedDict):
    """One statistic of an experiment as written and in base units (``None``: derived)."""
    as_written: str
    base_value: str | None
    dimension: str


class ExperimentDetails(TypedDict):
    """An experiment's evidence ``details``: the criterion, the figures, their consistency flags."""
    criterion: str
    file: str
    figures: dict[str, FigureJson]
    constants: dict[str, str]
    criterion_holds: bool | None
    flags: list[dict[str, str]]
    per_trial: bool
    failing_trials: list[int]
    figures_table: list[list[str]]
    plot: str | None


#: One step of a model checker's lasso (:func:`.model_checking.trail.counterexample`):
#: a transition (``transition`` its index) or a final state's stutter
#: (``stutter`` the state); ``from`` and ``to`` states, the label, its Gwendolen
#: ``line`` (``None``: an environment step), ``where`` ``file:line`` or ``""``,
#: ``holds`` the propositions true in ``to`` (the functional form: ``from`` is a keyword).
LassoStep = TypedDict("LassoStep", {"transition": NotRequired[int], "stutter": NotRequired[int], "from": int,
                                    "to": int, "label": str, "line": int | None, "stage": str, "where": str,
                                    "holds": list[str]})


class LassoState(TypedDict):
    """The initial state of a lasso and the propositions true in it."""
    state: int
    holds: list[str]


class Lasso(TypedDict):
    """A model checker's counterexample over the state graph (``kind`` ``lasso`` or ``prefix``)."""
    kind: str
    source: str
    initial: LassoState
    prefix: list[LassoStep]
    cycle: list[LassoStep]
    trace: list[str]


class Antecedent(TypedDict):
    """An antecedent of a claim and a state it holds in."""
    antecedent: str
    holds_in_state: int


class SpinDetails(TypedDict):
    """A SPIN check's evidence ``details``: the graph and its bounds, then what SPIN said."""
    model_checker: str
    claim: str
    psl: str
    states: int
    transitions: int
    complete: bool
    cut: str
    depth: int
    max_states: int
    max_depth: int
    timeout_s: float
    explore_s: float
    identifiers: str
    spin_verdict: NotRequired[str]
    bounded: NotRequired[bool]
    spin_states_stored: NotRequired[int | None]
    build_s: NotRequired[float]
    pan_s: NotRequired[float]
    promela: NotRequired[str]
    propositions: NotRequired[dict[str, str]]
    lasso: NotRequired[Lasso]
    antecedents: NotRequired[list[Antecedent]]
    vacuous: NotRequired[list[str]]


class AcceptingPath(TypedDict):
    """AJPF's counterexample: the accepting path's states and the trace's lines."""
    accepting_path: list[str]
    trace: list[str]


class DeclarationRow(TypedDict):
    """One declaration's verdict on a run (:class:`.monitors.declarations.DeclarationResult`, :mod:`.property_tests.declared`): ``premise``
    the kind of premise the requirement check makes of it (``"initial value"``, ``"progress"``,
    ``""`` for a period in time)."""
    declaration: str
    premise: str
    index: int
    source: str
    text: str
    verdict: str
    status: str
    reason: str
    #: ``progress( within K steps )`` or a period in steps judged ``true``: K less the longest row of accepted
    #: steps left unanswered (the steps to spare; docs/semantics.md, "Margins in steps")
    spare: NotRequired[int]


class InputCoverage(TypedDict):
    """How much of an input's range the valid examples of a property test covered (``None``: not measured)."""
    range: str
    drawn: str
    buckets: int | None
    covered: int | None
    fraction: float | None
    admitted: NotRequired[str]


class AjpfData(TypedDict):
    """An AJPF obligation's ``data``: the guarantee's instance and the rows that map it; for a
    mapped instance the property (``property`` its number, ``psl`` its text) and its files."""
    instance: dict[str, int]
    rows: list[int]
    notes: list[str]
    unmapped: list[str]
    guarantee_unmapped: list[str]
    agent: str
    property: NotRequired[int]
    psl: NotRequired[str]
    trivial: NotRequired[bool]
    jpf: NotRequired[str]
    ail: NotRequired[str]
    log: NotRequired[str]
    command: NotRequired[str]
    coverage: NotRequired[str]
    coverage_notes: NotRequired[list[str]]


class PromelaBranch(TypedDict):
    """One transition as the Promela template writes it: from ``src`` to ``dst`` (transition ``t``),
    with the assignments ``sets`` it makes."""
    src: int
    dst: int
    t: int
    sets: list[str]


class PromelaLeaf(TypedDict):
    """A leaf of the Promela template's search tree over the branches: the branches themselves."""
    leaf: list[PromelaBranch]


class PromelaSplit(TypedDict):
    """An inner node of that tree: the branches with ``src`` below ``split`` in ``low``, the rest in ``high``."""
    split: int
    low: "PromelaLeaf | PromelaSplit"
    high: "PromelaLeaf | PromelaSplit"
