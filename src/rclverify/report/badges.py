"""A requirement's status in the HTML report as what was proved and what the evidence says.

A requirement's status (:mod:`rclverify.calculus.requirements.rollup`) rolls its Z3
verdict up with the evidence its proof rests on, so one red ``failed``
stood beside "proved vacuously" and beside "proved, evidence outstanding"
alike.  :func:`requirement_badges` shows the two apart:
the proof as one badge in words (``proved``, ``proved vacuously`` in the
warning colour, ``refuted``, ...) and, where the evidence decides the
status, ``evidence: <status>`` as a second.
"""
from __future__ import annotations

from typing import Mapping

import jinja2
from markupsafe import Markup, escape

from rclverify.records.requirement_rows import RequirementRow

__all__ = ["VERDICT_STYLE", "requirement_badges"]

#: Verdict word -> (badge text, badge style) of the proof badge; a verdict
#: not listed is shown with its status's style.
VERDICT_STYLE: Mapping[str, tuple[str, str]] = {
    "met": ("proved", "discharged"),
    "proved, evidence outstanding": ("proved", "discharged"),
    "proved vacuously": ("proved vacuously", "warning"),
    "proved from an inconsistency": ("proved from an inconsistency", "failed"),
    "refuted": ("refuted", "failed"),
    "inconclusive": ("not decided", "inconclusive"),
    "informal": ("informal", "pending"),
}

#: Verdicts whose status is the evidence's (the proof itself holds).
_EVIDENCE_DECIDES = ("met", "proved, evidence outstanding")


def _badge(text: str, style: str, title: str = "") -> Markup:
    t = Markup(' title="%s"') % title if title else Markup("")
    return Markup('<span class="badge st-%s"%s>%s</span>') % (style, t, text)


@jinja2.pass_environment
def requirement_badges(env: jinja2.Environment, req: RequirementRow) -> Markup:
    """The badges of a requirement's row (its ``status``, ``verdict`` and
    ``note``, read as the attributes mypy checks): the proof badge
    (:data:`VERDICT_STYLE`) and, when the proof holds and the status is the
    evidence's, ``evidence: <status>``.  The status word is the badges'
    ``title`` and the note the proof badge's; text escaped.  Raises
    ``TypeError`` for anything but a decoded row (the view decodes the
    requirements it hands the templates, report/view.py)."""
    if not isinstance(req, RequirementRow):
        raise TypeError(f"reqbadges reads a RequirementRow, not a {type(req).__name__}")
    status, verdict, note = req.status, req.verdict, req.note
    word, style = VERDICT_STYLE.get(verdict, (verdict, env.filters["style"](status)))
    out = _badge(escape(word), style, f"status: {status}" + (f"; {note}" if note else ""))
    if verdict in _EVIDENCE_DECIDES:
        out += Markup(" ") + _badge(Markup("evidence: %s") % status, env.filters["style"](status),
                                    f"status: {status}")
    return out
