"""Who is named when a liveness requirement is refuted by a lasso.

The temporal check (:mod:`rclverify.calculus.requirements.progress_gap`) records what
a refuting lasso rests on:

* ``missing_progress``: nodes that accept their input in the loop and never
  answer there, while the search over the same system with every node held
  to fairness finds no lasso -- the requirement is refuted only because
  nothing says these nodes answer.  The culprit is each such node, at its
  contract's header (a declaration is missing from it, not a guarantee
  wrong), and the fix is ``progress( ... )`` on it if the node does answer;
* ``missing_initially``: a loop no node of which ever has a question it
  owes an answer, because an input its producer never publishes has no
  value (docs/semantics.md), or keeps a value its reader refuses.  The culprit is each such producer, at its header, and the fix an
  ``initially( ... )`` with a value its readers accept.

Neither names the node whose variables the goal reads (that node meets its
contract in the lasso).  A lasso with neither stays without culprit: no
guarantee is shown to let it through (docs/diagnosis.md, "Who is named").
No repair is checked by Z3 here: a declaration of progress is a claim about
the node's implementation, which the user must know to hold; the sentence
says so.
"""
from __future__ import annotations

from rclverify.calculus.shapes import Gaps
from rclverify.records.stage_records import Culprit


def liveness_culprits(temporal: Gaps) -> tuple[str, list[Culprit], str]:
    """``(node, culprits, sentence)`` of a refuted temporal record's
    ``temporal`` field: the first culprit node (``""``: none), the culprits
    as diagnosis records name them (``{"what", "source", "text"}``, the
    source a node's header ``file:line:col``), and the sentence that says
    what is missing (``""``: nothing)."""
    gaps = list(temporal.get("missing_progress") or [])
    stuck = list(temporal.get("missing_initially") or [])
    if gaps:
        culprits: list[Culprit] = [{"what": f"the contract of {g['node']}: no progress declared", "source": str(g["source"]),
                     "text": f"declares {g['declared']}"} for g in gaps]
        names = ", ".join(str(g["node"]) for g in gaps)
        steps = ", ".join(str(i) for i in gaps[0].get("accepted_at") or [])
        sentence = (f"{names} never answer{'s' if len(gaps) == 1 else ''} in the loop although "
                    f"{'its' if len(gaps) == 1 else 'their'} assumption holds there (step {steps} of the loop); "
                    "asked again with every node answering what it accepts, the lasso search found none. "
                    f"Declare progress( eventually ) or progress( within K steps ) on {names} if "
                    f"{'it answers' if len(gaps) == 1 else 'they answer'} every input "
                    f"{'its' if len(gaps) == 1 else 'their'} assumption accepts: that is a claim about the "
                    "implementation, to be shown by its evidence")
        return str(gaps[0]["node"]), culprits, sentence
    if stuck:
        producers = list(dict.fromkeys(str(r["node"]) for r in stuck))
        culprits = [{"what": f"the contract of {n}: no initial value declared",
                     "source": next(str(r["source"]) for r in stuck if r["node"] == n),
                     "text": "declares no initially(...)"} for n in producers]
        reads = "; ".join(f"{r['consumer']} never has a value: {r['node']} never publishes {r['node']}.{r['output']}"
                          if str(r["value"]).startswith("none") else
                          f"{r['consumer']} keeps {r['node']}.{r['output']} = {r['value']} from before the run"
                          for r in stuck)
        sentence = (f"no node of the loop ever accepts its input ({reads}), so none ever answers. Declare the "
                    f"initial value of the outputs of {', '.join(producers)} (initially( ... ), a value the readers' "
                    "assumptions accept) if they have one before their first answer")
        return producers[0], culprits, sentence
    return "", [], ""
