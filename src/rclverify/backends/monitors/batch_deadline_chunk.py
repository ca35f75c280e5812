"""One chunk of a run judged by the batch deadline judge, or declined (:mod:`.batch_deadlines`:
what a clean chunk is, in what order its verdicts are given, the state it leaves)."""
from __future__ import annotations

from operator import attrgetter
from typing import TYPE_CHECKING, Any, Callable, Mapping

from rclverify.core.numeric import np

from rclverify.traces.events import Event
from rclverify.targets.column_deadlines import expiries, first_answers, ns_column
from rclverify.targets.columns import block_column, column, field_values
from rclverify.backends.monitors import deadline_questions, deadline_skew
from rclverify.backends.monitors.deadline_records import Pending
from rclverify.backends.monitors.time_margins import TimeMargin

if TYPE_CHECKING:
    from rclverify.backends.monitors.batch_deadline_state import ChunkSide

_FIELDS, _TIME, _TOPIC = attrgetter("fields"), attrgetter("time"), attrgetter("topic")


def _headed(fields: list[Mapping[str, Any]]) -> bool:
    """Whether a message carries a header stamp, nested or flattened (the monitor's clock would read it)."""
    for f in fields:
        if "header" in f or "header.stamp.secs" in f or "header.stamp.sec" in f:
            return True
    return False


def _columns(evs: list[Event] | Any) -> tuple[list[str], np.ndarray, Callable[[np.ndarray, str], list[Any]]] | None:
    """The chunk's topics, times (float64 s) and a field's values at some rows (``None`` where a message has
    none); ``None`` when a message carries a header stamp.  ``evs``: a list of events, or a log block
    (:class:`~rclverify.traces.jsonl_blocks.LogBlock`: its columns, no row with a header)."""
    if not isinstance(evs, list):
        return evs.topics, evs.times, evs.values
    fields = list(map(_FIELDS, evs))
    if _headed(fields):
        return None
    return list(map(_TOPIC, evs)), np.fromiter(map(_TIME, evs), np.float64, len(evs)), \
        lambda rows, key: field_values(fields, rows, key)


def _kinds(mon: ChunkSide, evs: list[Event] | Any, topics: list[str]) -> np.ndarray:
    """Each row's topic as the plan's column code (:meth:`~.batch_deadline_plan.DeadlinePlan.kind_of`), int8;
    a log block's from its topic codes, each distinct name classified once."""
    kind_of = mon.plan.kind_of
    codes = getattr(evs, "topic_codes", None)
    if codes is not None:
        at, names = codes()
        by_code: np.ndarray = np.array([kind_of(t) for t in names] or [0], dtype=np.int8)[at]
        return by_code
    lut = {t: kind_of(t) for t in set(topics)}
    return np.fromiter(map(lut.__getitem__, topics), np.int8, len(topics))


def _typed(evs: list[Event] | Any, values: Callable[[np.ndarray, str], list[Any]], rows: np.ndarray, field: str,
           kind: str, codes: Mapping[str, int]) -> tuple[np.ndarray, np.ndarray]:
    """Field ``field`` at ``rows`` as :func:`~rclverify.targets.columns.column` reads it (``values``: the chunk's
    values, :func:`_columns`); of a log block, the columns the untimed check's batch path reads too, made once
    (:func:`~rclverify.targets.columns.block_column`)."""
    if isinstance(evs, list):
        return column(values(rows, field), kind, codes)
    return block_column(evs, rows, field, kind, codes)


def judge_chunk(mon: ChunkSide, evs: list[Event] | Any) -> bool:
    """Judge the events ``evs`` (a list, or a log block: :func:`_columns`) as the streaming monitor
    would, over columns, and leave its state; ``False`` (nothing changed) when the chunk is not clean,
    or when the node's deadlines may be kept in simulated time (streamed: :mod:`.deadline_clock`)."""
    return not (mon.sim_mode is True or mon.sim.heard) and _judge_chunk(mon, evs)


def _judge_chunk(mon: ChunkSide, evs: list[Event] | Any) -> bool:
    """:func:`judge_chunk` of a chunk whose deadlines are kept in the run's clock."""
    plan = mon.plan
    n = len(evs)
    got = _columns(evs)
    if got is None:
        return False
    topics, times, values = got
    kind = _kinds(mon, evs, topics)
    ns = ns_column(times)
    if ns is None or bool((kind == 2).any()) or (n > 1 and bool((np.diff(ns) < 0).any())) or \
            (mon.now_ns is not None and int(ns[0]) < mon.now_ns):
        return False
    in_rows, out_rows = np.flatnonzero(kind == 1), np.flatnonzero(kind == -1)
    ik, ok = plan.in_key, plan.out_key
    good_in, col_in = _typed(evs, values, in_rows, plan.in_field, plan.in_kind, plan.codes.get(ik, {}))
    good_out, col_out = _typed(evs, values, out_rows, plan.out_field, plan.out_kind, plan.codes.get(ok, {}))
    if not (bool(good_in.all()) and bool(good_out.all())):
        return False
    accepted = np.ones(len(in_rows), dtype=bool)
    for a in plan.assumptions:
        truth, sure = a({ik: col_in})
        if not bool(np.broadcast_to(sure, accepted.shape).all()):
            return False
        accepted &= np.broadcast_to(truth, accepted.shape)
    refused = in_rows[~accepted]
    first_refused = None
    if refused.size and mon.result.first_unaccepted is None:
        first_refused = deadline_questions.refused(mon, {ik: mon.mapped(evs[int(refused[0])], ik)})
        if first_refused is None or first_refused[0] != "assumption violated":
            return False
    # the obligations: the expired ones kept (oldest expiry first), the open ones, then each accepted trigger's
    carried_exp, carried_open = list(mon.expired), list(mon.pending)
    carried = carried_exp + carried_open
    seeds = [plan.seed(ik, p.inputs.get(ik)) for p in carried]
    if any(s is None for s in seeds):
        return False
    T, L0 = len(plan.timed), len(carried_exp)
    acc_rows = in_rows[accepted]
    rows = np.concatenate([np.full(len(carried), -1, dtype=np.int64), np.repeat(acc_rows, T)])
    which = np.concatenate([np.array([plan.place[p.k] for p in carried], dtype=np.int64),
                            np.tile(np.arange(T, dtype=np.int64), len(acc_rows))])
    bounds = np.array([b for _, b, _, _ in plan.timed], dtype=np.int64)
    stamp = np.concatenate([np.array([p.stamp_ns for p in carried], dtype=np.int64), ns[rows[len(carried):]]])
    due = np.concatenate([np.array([p.due_ns for p in carried], dtype=np.int64),
                          stamp[len(carried):] + bounds[which[len(carried):]]])
    inputs = np.concatenate([np.array(seeds, dtype=col_in.dtype), np.repeat(col_in[accepted], T)])
    answer = first_answers(rows, out_rows, which, inputs, col_out, [j for _, _, _, j in plan.timed], ik, ok)
    if answer is None:
        return False
    m = len(rows)
    expiry = expiries(ns, due)
    is_open = np.arange(m) >= L0
    met = is_open & (answer >= 0) & ((expiry >= n) | (answer <= expiry))
    lapsed = is_open & ~met & (expiry < n)
    late = (~is_open | lapsed) & (answer >= 0)
    in_time = met & (ns[np.maximum(answer, 0)] <= due)  # a marked one answered after its deadline: undecided
    skewed = _skew_window(mon, ns, rows, out_rows, ~in_time & (np.arange(m) >= len(carried)),
                          bool(refused.size) and bool(lapsed.any()))
    if skewed is None:
        return False  # a window past the 64 outputs the monitor keeps, or which unaccepted trigger is first
    order = np.arange(m) - L0  # an open obligation's place in the monitor's list (the expired: below 0)
    # each verdict as (row, phase, place): late answers of expired obligations (0), answers (1), expiries (2)
    ev_at = np.concatenate([answer[late], answer[met], expiry[lapsed]])
    ev_phase = np.concatenate([np.zeros(int(late.sum()), np.int64), np.ones(int(met.sum()), np.int64),
                               np.full(int(lapsed.sum()), 2, np.int64)])
    queue = np.where(is_open, expiry * (m + 1) + order + 1, order)  # the expired list's order
    ev_place = np.concatenate([queue[late], order[met], order[lapsed]])
    ev_ob = np.concatenate([np.flatnonzero(late), np.flatnonzero(met), np.flatnonzero(lapsed)])
    sort = np.lexsort((ev_place, ev_phase, ev_at))
    ev_at, ev_phase, ev_ob = ev_at[sort], ev_phase[sort], ev_ob[sort]
    step = np.where(ev_phase == 2, 1, np.where(ev_phase == 0, -1, 0))
    held = L0 + np.cumsum(step)
    if held.size and int(held[ev_phase == 2].max(initial=0)) > (mon.expired.maxlen or 0):
        return False  # the monitor would drop an expired obligation: its own judging
    _apply(mon, evs, ns, rows, which, due, out_rows, carried, L0, answer, expiry, met, lapsed,
           (ev_at, ev_phase, ev_ob), refused, first_refused, skewed)
    return True


def _skew_window(mon: ChunkSide, ns: np.ndarray, rows: np.ndarray, out_rows: np.ndarray, unmet: np.ndarray,
                 race: bool) -> np.ndarray | None:
    """With the transport skew, the obligations ``unmet`` (new ones, not met in time in the chunk) with an output
    stamped within the skew before their trigger (the chunk's, or one the monitor heard before it): those
    :func:`_mark` reads; ``None`` (the chunk is the monitor's) when such a window holds more than the 64
    outputs the monitor keeps, or when ``race`` (a trigger refused by the assumption and an obligation
    lapsing in the chunk) and no unaccepted trigger is first yet (which one would be first)."""
    if not mon.skew_ns:
        return np.zeros(0, dtype=np.int64)
    if race and mon.result.first_unaccepted is None:
        return None
    idx = np.flatnonzero(unmet & (rows >= 0))
    if not idx.size:
        return idx
    trig = rows[idx]
    lo_ns = ns[trig] - mon.skew_ns
    lo = np.searchsorted(ns[out_rows], lo_ns, side="left")
    hi = np.searchsorted(out_rows, trig, side="left")
    count = np.maximum(hi - lo, 0)
    heard = np.array([h[0] for h in mon.heard], dtype=np.int64)
    before = np.where(lo == 0, len(heard) - np.searchsorted(heard, lo_ns, side="left"), 0) if heard.size else 0
    count = count + before
    if bool((count > (mon.heard.maxlen or 64)).any()):
        return None
    out: np.ndarray = idx[count > 0]
    return out


def _mark(mon: ChunkSide, p: Pending, evs: list[Event], ns: np.ndarray, out_rows: np.ndarray, r: int,
          heard_hi: int | None, out_ns: np.ndarray) -> bool:
    """Mark obligation ``p`` (its trigger at row ``r``) as :func:`.deadline_skew.scan_heard` marks it when the
    trigger comes: the outputs heard before the chunk, then the chunk's before row ``r``, oldest first, within
    the skew; whether it is marked.  ``heard_hi``: the latest stamp (ns) among the outputs heard before the
    chunk (``None``: none); none of them is scanned when it lies before the skew's window.  ``out_ns``: the
    outputs' stamps (``ns[out_rows]``, made once per chunk)."""
    if heard_hi is not None and heard_hi >= p.stamp_ns - mon.skew_ns:
        deadline_skew.scan_heard(mon, p)
    if not p.maybe:
        ok = mon.plan.out_key
        lo = int(np.searchsorted(out_ns, p.stamp_ns - mon.skew_ns, side="left"))
        hi = int(np.searchsorted(out_rows, r, side="left"))
        for j in out_rows[lo:hi].tolist():
            out = evs[j]  # (a log block's row made an event once)
            deadline_skew.mark_early(mon, p, out, int(ns[j]), {ok: mon.mapped(out, ok)})
            if p.maybe:
                break
    return bool(p.maybe)


def _apply(mon: ChunkSide, evs: list[Event], ns: np.ndarray, rows: np.ndarray, which: np.ndarray,  # long: verdicts and state share ob
           due: np.ndarray, out_rows: np.ndarray, carried: list[Pending], L0: int, answer: np.ndarray,
           expiry: np.ndarray, met: np.ndarray, lapsed: np.ndarray,
           verdicts: tuple[np.ndarray, np.ndarray, np.ndarray], refused: np.ndarray,
           first_refused: tuple[str, str] | None, skewed: np.ndarray) -> None:
    """Give a clean chunk's verdicts in order and leave the monitor's state (module docstring of
    :mod:`.batch_deadlines`)."""
    plan, result = mon.plan, mon.result
    ik, ok = plan.in_key, plan.out_key
    n, T, C = len(evs), len(plan.timed), len(carried)
    if refused.size:
        result.unaccepted["assumption violated"] += int(refused.size) * T
        if first_refused is not None:
            r = int(refused[0])
            result.first_unaccepted = {"guarantee": plan.timed[0][0], "where": evs[r].where, "stamp": int(ns[r]) / 1e9,
                                       "why": first_refused[0], "reason": first_refused[1]}
    made: dict[int, Pending] = {}
    trig_inputs: dict[int, dict[str, object]] = {}

    def ob(i: int) -> Pending:
        """Obligation ``i`` as the monitor's record (a trigger's made when first needed)."""
        if i < C:
            return carried[i]
        p = made.get(i)
        if p is None:
            r = int(rows[i])
            trig = evs[r]  # (a log block's row made an event once)
            got = trig_inputs.get(r)
            if got is None:
                got = trig_inputs[r] = {ik: mon.mapped(trig, ik)}
            k, bound, _, _ = plan.timed[int(which[i])]
            s = int(ns[r])
            p = made[i] = Pending(k, trig, s / 1e9, (s + bound) / 1e9, got, stamp_ns=s, due_ns=s + bound)
        return p

    def last_output(i: int, upto: int) -> int:
        """The last output row after obligation ``i``'s row and at or before row ``upto`` (-1: none)."""
        j = int(np.searchsorted(out_rows, upto, side="right")) - 1
        return int(out_rows[j]) if j >= 0 and int(out_rows[j]) > int(rows[i]) else -1

    # the transport skew (deadline_skew): a marked obligation unanswered by its deadline is undecided, its late
    # answer gives no verdict
    maybe = np.zeros(len(rows), dtype=bool)
    if mon.skew_ns:
        for i, p in enumerate(carried):
            maybe[i] = bool(p.maybe)
        heard_hi = max((h[0] for h in mon.heard), default=None)
        out_ns = ns[out_rows]
        for i in skewed.tolist():
            maybe[i] = _mark(mon, ob(i), evs, ns, out_rows, int(rows[i]), heard_hi, out_ns)
    at, phase, obs = verdicts
    # with no verdict callback an answer within its deadline is only counted: the loop visits the rest, in order
    plain = (phase == 1) & (ns[at] <= due[obs]) if mon.on_verdict is None else np.zeros(len(at), dtype=bool)
    trues = int(np.count_nonzero(plain))
    rest = ~plain
    for r, ph, i in zip(at[rest].tolist(), phase[rest].tolist(), obs[rest].tolist()):
        if ph == 1:
            if maybe[i] and int(ns[r]) > int(due[i]):  # a marked obligation's own answer after its deadline
                deadline_skew.undecided(mon, ob(i))
            else:
                mon._emit(mon.answered_verdict(ob(i), int(ns[r]), evs[r], plan.timed[int(which[i])][2]))
        elif ph == 0:
            if not maybe[i]:
                mon._emit(mon.late_verdict(ob(i), int(ns[r]), evs[r]))
        else:
            p = ob(i)
            j = last_output(i, r)
            if j >= 0 and plan.timed[int(which[i])][3] is not None:
                p.rejected = mon.rejection(p.k, p.inputs, ok, evs[j])
            if maybe[i]:
                deadline_skew.undecided(mon, p)
            else:
                mon._emit(mon.expired_verdict(p, int(ns[r])))
    result.counts["true"] += trues
    counted = ~(maybe[obs] & ((phase != 1) | (ns[at] > due[obs])))  # a marked one's answer after it counts none
    _note_margins(mon, evs, ns, which, due, ob, (at[counted], phase[counted], obs[counted]))
    # the state: the open obligations left (in order), the expired ones not answered (in the expired list's order)
    last_out = int(out_rows[-1]) if out_rows.size else -1
    out_value = mon.mapped(evs[last_out], ok) if last_out >= 0 else None
    every = np.arange(len(rows))
    still = np.flatnonzero((every >= L0) & ~met & (expiry >= n))
    gone = np.flatnonzero((answer < 0) & (lapsed | (every < L0)))
    keyed = sorted(gone.tolist(), key=lambda i: (-1, i) if i < L0 else (int(expiry[i]), i))
    pending = [ob(i) for i in still.tolist()]
    expired = [ob(i) for i in keyed]
    for i, p in zip(still.tolist() + keyed, pending + expired):
        if out_value is not None and last_out > int(rows[i]):
            p.outs[ok] = out_value
    for i, p in zip(still.tolist(), pending):
        j = last_output(i, n - 1)
        if j >= 0 and plan.timed[int(which[i])][3] is not None:
            p.rejected = mon.rejection(p.k, p.inputs, ok, evs[j])
    values: dict[str, object] = {}
    in_rows = rows[C:]
    if len(in_rows) or refused.size:
        r = max(int(in_rows.max()) if len(in_rows) else -1, int(refused.max()) if refused.size else -1)
        values[ik] = mon.mapped(evs[r], ik)
    if out_value is not None:
        values[ok] = out_value
    heard = [(int(ns[j]), e, {ok}, {ok: mon.mapped(e, ok)}) for j in out_rows[-64:].tolist() for e in (evs[j],)]
    mon.take_state(pending, expired, values, heard, int(ns[-1]))


def _note_margins(mon: ChunkSide, evs: list[Event], ns: np.ndarray, which: np.ndarray, due: np.ndarray,
                  ob: Callable[[int], Pending],
                  verdicts: tuple[np.ndarray, np.ndarray, np.ndarray]) -> None:
    """Each guarantee's time margins of the chunk's verdicts, as :func:`.time_margins.note` counts them one by
    one in their order: answers and late answers counted with their margin (a late one no longer
    unanswered), expiries unanswered, the first smallest margin kept with its places."""
    at, phase, obs = verdicts
    kept = mon.result.time_margins
    g_of = which[obs]
    margin = due[obs] - ns[at]
    for g, (k, _, _, _) in enumerate(mon.plan.timed):
        mine = g_of == g
        if not bool(mine.any()):
            continue
        ph = phase[mine]
        tm = kept.setdefault(k, TimeMargin(k))
        tm.unanswered += int((ph == 2).sum()) - int((ph == 0).sum())
        answered = np.flatnonzero(ph != 2)
        if not answered.size:
            continue
        got = margin[mine][answered]
        best = int(np.argmin(got))
        low = int(got[best])
        if not tm.answers or low < tm.margin_ns:
            i, r = int(obs[mine][answered][best]), int(at[mine][answered][best])
            tm.margin_ns, tm.trigger_where, tm.answer_where, tm.answer = low, ob(i).trigger.where, evs[r].where, \
                int(ns[r]) / 1e9
        tm.answers += int(answered.size)
