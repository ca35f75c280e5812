"""Margins over runs: per guarantee, the smallest space margin any recorded
run gave it, where, and the distribution of its answers' margins
(docs/semantics.md, "Margins over runs"; docs/reading-the-report.md).

Each monitors run's record names, per guarantee, its smallest margin, the
answers that gave one (``answers``), those that had none (``undefined``) and
the :data:`~rclverify.backends.monitors.verdicts.KEPT_MARGINS` smallest
margins (``lowest``; ``details.monitoring.margins``).  The report's
``margins`` (:func:`margin_rows`) has one row per guarantee judged with
margins on at least one run, each run counted once: a run is its identity
(``details.statistics.sha256``, :func:`rclverify.backends.monitors.run_identity.run_digest`,
as the statistics count runs), so one run given as a log, an sqlite3 bag
and an MCAP bag, or copied with a field no rule reads, is one run, its
first record in the report's obligation order standing for it.  Each row gives the
smallest over the runs (``margin``, the
run ``trace``, its ``obligation``, the answer's ``time`` and ``where``, the
deciding ``atom`` and ``unit``), the counts summed over the runs, and the
figures of :func:`figures`: ``count`` (every answer with a margin, on every
run), ``min`` and the quantiles ``p5`` and ``p50`` of those answers'
margins, each given by the bounds the kept margins prove (equal when they
decide it); ``time_margin``, for a ``triggered by ... within`` guarantee, its
smallest time margin over the runs (:func:`.chain_margins.hop_margin`, as a
deadline's hop has it; ``None`` for an untimed guarantee).  With at least two runs, ``plot_svg`` is the distribution drawn
per run (report/margin_plot.py, the ``plots`` extra), or ``plot_note`` says
why none was drawn.
"""
from __future__ import annotations

import math
from typing import Iterable, Mapping, Sequence

import msgspec
from msgspec.structs import replace

from rclverify.backends.monitors.payload import RunStatistics, SpaceMargin, TimeMarginItem, monitors_payload
from rclverify.backends.monitors.verdicts import KEPT_MARGINS
from rclverify.report.chain_margins import hop_margin
from rclverify.records.deadline_rows import HopTimeMargin
from rclverify.records.margin_rows import MarginBounds, MarginRow
from rclverify.records.obligations import ObligationRow
from rclverify.records.store import EvidenceStore
from rclverify.stages.workspace import Workspace

#: The quantiles the figures give (``p5``, ``p50``): the share of answers at or below them.
QUANTILES = (("p5", 0.05), ("p50", 0.5))
#: At most this many guarantees get a plot (the smallest margins first): each costs matplotlib a tenth of a
#: second and up to a few hundred kilobytes of the HTML report.
MAX_PLOTS = 12
#: The bounds of a figure no answer gives.
_NONE = MarginBounds(low=None, high=None)


def _number(v: float) -> float | None:
    """``v`` for JSON: ``None`` when infinite."""
    return v if math.isfinite(v) else None


def _run_margins(m: SpaceMargin) -> tuple[list[float], int, float | None]:
    """One run's record of one guarantee as ``(known, unknown, floor)``: the
    margins known exactly (the kept ones, ``null`` read as ``-inf``, and the
    answers the record dropped as ``+inf``), how many answers' margins are
    unknown, and the least those can be (the largest kept margin)."""
    answers = m.answers
    if m.lowest is not msgspec.UNSET:
        kept = [-math.inf if v is None else float(v) for v in m.lowest]
    else:  # a record that kept only the smallest
        v, holds = m.margin, m.holds
        kept = [] if not answers else [float(v) if v is not None else math.inf if holds else -math.inf]
    rest = max(answers - len(kept), 0)
    if m.lowest is not msgspec.UNSET and len(kept) < KEPT_MARGINS:  # to_json drops +inf: an answer not listed held without distance
        return kept + [math.inf] * rest, 0, None
    return kept, rest, (kept[-1] if kept else None)


def _kth(values: Sequence[float], k: int) -> float:
    return sorted(values)[k - 1]


def figures(runs: Iterable[SpaceMargin]) -> tuple[int, int, dict[str, MarginBounds]]:
    """``(count, kept, quantiles)`` of one guarantee's margins over ``runs``
    (each a ``details.monitoring.margins`` item).

    ``count`` is every answer with a margin on every run; the q-quantile is
    the ``ceil(q * count)``-th smallest of their margins (the empirical
    quantile that inverts the distribution function, Hyndman and Fan's type 1,
    "Sample quantiles in statistical packages", The American Statistician,
    1996); ``min`` is the first.  A run records its smallest margins only,
    so each quantile is given by bounds: ``high`` the rank's margin among
    the kept ones (adding the unkept answers can only lower it), ``low`` the
    same with every unkept answer at the least it can be, its run's largest
    kept margin.  They are equal where the kept margins decide the quantile,
    always for ``min``.  ``None`` stands for an infinite bound."""
    known: list[float] = []
    floors: list[float] = []
    for m in runs:
        k, unknown, floor = _run_margins(m)
        known += k
        if unknown and floor is not None:
            floors += [floor] * unknown
    count = len(known) + len(floors)
    out: dict[str, MarginBounds] = {}
    if not count:
        return 0, 0, out
    for name, q in (("min", 0.0), *QUANTILES):
        rank = max(1, math.ceil(q * count))
        high = _kth(known, rank) if rank <= len(known) else math.inf
        low = _kth(known + floors, rank)
        out[name] = MarginBounds(low=_number(low), high=_number(high))
    return count, len(known), out


def _guarantee_place(ws: Workspace, node: str, k: int) -> str:
    cn = ws.checked.nodes.get(node)
    if cn is None or not 1 <= k <= len(cn.node.guarantees):
        return ""
    loc = cn.node.guarantees[k - 1].loc
    return f"{loc.file}:{loc.line}:{loc.col}"


def _formula(ws: Workspace, node: str, k: int) -> str:
    from rclverify.lang.printer import expr_to_rcl  # deferred: start-up (only for a guarantee timed but never measured)
    cn = ws.checked.nodes.get(node)
    return expr_to_rcl(cn.node.guarantees[k - 1].formula) if cn is not None and 1 <= k <= len(cn.node.guarantees) \
        else ""


def margin_rows(ws: Workspace, ob_rows: Sequence[ObligationRow]) -> list[MarginRow]:
    """The report's ``margins`` (module docstring), by node and guarantee, each a
    :class:`~rclverify.records.margin_rows.MarginRow`."""
    runs: dict[tuple[str, int], list[tuple[str, str, SpaceMargin]]] = {}
    timed: dict[tuple[str, int], list[tuple[str, list[TimeMarginItem]]]] = {}  # the runs' time margins, by obligation
    seen: dict[str, set[str]] = {}  # node -> the identities of its runs read so far
    store: EvidenceStore | None = None
    for o in ob_rows:
        if o.backend != "monitors" or o.status == "error":
            continue
        store = store or EvidenceStore(ws.root)
        ev, problem = store.read(o.id)
        payload = monitors_payload(ev.backend, ev.details) if ev is not None and not problem else None
        if payload is None:  # no record, an altered one, or one whose payload does not decode (shown as error)
            continue
        if _seen_before(seen.setdefault(o.node, set()), payload.statistics, o.id):
            continue  # another form or copy of a run already read: one run, counted once
        mon = payload.monitoring
        for m in mon.margins if mon is not None else ():
            trace = m.trace if m.trace is not msgspec.UNSET and m.trace else mon.trace if mon is not None else ""
            runs.setdefault((o.node, m.guarantee), []).append((o.id, trace, m))
        for t in payload.deadlines.time_margins if payload.deadlines is not None else ():
            timed.setdefault((o.node, t.guarantee), []).append((o.id, [t]))
    rows = [_row(ws, node, k, runs.get((node, k), []), hop_margin(k, timed.get((node, k), [])))
            for node, k in sorted(set(runs) | set(timed))]
    return _plots(rows, runs)


def _seen_before(seen: set[str], stats: RunStatistics | None, obligation: str) -> bool:
    """Whether the run of a record with the statistics ``stats`` is among the identities ``seen`` (which it
    joins): its ``sha256``; a record without one (written before runs had an identity) is a run of its own,
    by its obligation."""
    sha = stats.sha256 if stats is not None else msgspec.UNSET
    key = sha if isinstance(sha, str) and sha else "obligation:" + obligation
    if key in seen:
        return True
    seen.add(key)
    return False


def _order(r: tuple[str, str, SpaceMargin]) -> float:
    """A run's smallest margin of a guarantee as a number (``inf`` for one held without a distance, ``nan``
    when no answer gave one)."""
    v, holds, answers = r[2].margin, r[2].holds, r[2].answers
    if not answers:
        return math.nan
    return float(v) if v is not None else math.inf if holds else -math.inf


def _row(ws: Workspace, node: str, k: int, got: Sequence[tuple[str, str, SpaceMargin]],
         time_margin: HopTimeMargin | None) -> MarginRow:
    """Guarantee ``k`` of ``node``'s row over the runs ``got`` (``[(obligation, trace, margins item)]``) with
    its smallest time margin ``time_margin`` (module docstring)."""
    place = _guarantee_place(ws, node, k)
    if not got:  # timed only: no answer was judged with a space margin
        return MarginRow(node=node, guarantee=k, formula=_formula(ws, node, k), source=place, margin=None,
                         holds=None, unit="", atom="", trace="", obligation="", time=None, where="", runs=0,
                         answers=0, undefined=0, count=0, kept=0, min=_NONE, p5=_NONE, p50=_NONE,
                         time_margin=time_margin)
    measured = [r for r in got if not math.isnan(_order(r))]
    least = min(measured, key=_order) if measured else got[0]
    m = least[2]
    count, kept, fig = figures(r[2] for r in got)
    v = _order(least)
    return MarginRow(node=node, guarantee=k, formula=m.formula, source=place,
                     margin=None if math.isnan(v) else _number(v), holds=(v > 0) if math.isinf(v) else None,
                     unit=m.unit, atom=m.atom, trace=least[1], obligation=least[0],
                     time=float(m.time) if measured and m.time is not None else None,
                     where=m.where if measured else "", runs=len(got),
                     answers=sum(r[2].answers for r in got),
                     undefined=sum(r[2].undefined for r in got), count=count, kept=kept,
                     min=fig.get("min", _NONE), p5=fig.get("p5", _NONE), p50=fig.get("p50", _NONE),
                     time_margin=time_margin)


def _plots(rows: list[MarginRow],
           runs: Mapping[tuple[str, int], list[tuple[str, str, SpaceMargin]]]) -> list[MarginRow]:
    """``rows`` with the distribution of every row measured on two runs or more drawn (``plot_svg``, at most
    :data:`MAX_PLOTS`) or why not (``plot_note``)."""
    from rclverify.core.extras import MissingExtra  # deferred: start-up (only where a plot is drawn)
    wanted = [r for r in rows if r.runs >= 2 and r.count]
    wanted.sort(key=lambda r: math.inf if r.margin is None else r.margin)
    drawn: dict[int, MarginRow] = {}
    for n, r in enumerate(wanted):
        if n >= MAX_PLOTS:
            drawn[id(r)] = replace(r, plot_note=f"no plot drawn: the report draws the {MAX_PLOTS} smallest margins' "
                                                "plots only")
            continue
        try:
            from rclverify.report.margin_plot import render_svg  # deferred: start-up (matplotlib only when drawn)
            per_run = [(trace, [-math.inf if v is None else float(v)
                                for v in (m.lowest if m.lowest is not msgspec.UNSET else ())])
                       for _, trace, m in runs[(r.node, r.guarantee)]]
            drawn[id(r)] = replace(r, plot_svg=render_svg(r, per_run))
        except MissingExtra as exc:  # the plot illustrates; the figures above do not rest on it
            drawn[id(r)] = replace(r, plot_note=f"no plot drawn: {exc}")
    return [drawn.get(id(r), r) for r in rows]


__all__ = ["MAX_PLOTS", "QUANTILES", "figures", "margin_rows"]
