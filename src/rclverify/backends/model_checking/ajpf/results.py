"""Reading AJPF (Java PathFinder) output: did the property hold?

AJPF prints JPF's report, a sequence of sections headed by a rule of ``=``
characters and a title (``system under test``, ``search started: ...``,
``error 1``, ``results``, ``statistics``, ``search finished: ...``).  What
this module relies on:

* ``system under test``: ``ail.util.AJPF_w_AIL.main("<.ail>","<.psl>","<name>")``
  -- which property of which file was checked;
* ``results``: ``no errors detected`` when the property holds, else one
  ``error #k: <property class> "..."`` line per error;
* an ``error k`` section from ``ajpf.MCAPLListener`` with ``An Accepting Path
  has been found:`` and the path as ``[MS: m, BS: b, UN: u]`` triples (model
  state, Buchi automaton state, until counter) when the property is violated;
* ``statistics``: ``search: maxDepth=..,constraints=N``; ``N > 0`` means a
  search limit (depth, memory) cut the state space, so "no errors" is then
  not a proof;
* info log lines (``[INFO] ...``, or ``INFO: ...`` in the JDK's default log
  format) from the loggers the generated ``.jpf`` enables:
  ``ail.util.AJPF_w_AIL`` echoes the property text, ``ajpf.product.Product``
  reports ``Adding <state> to [<path>]`` and ``ail.mas.DefaultEnvironment``
  ``<agent> done <action>``; the actions logged before a state is added are
  taken as the transition into that state.

Format source: the MCAPL AJPF tutorials (property specification, JPF
configuration, "what to do when model checking fails").  Where a log lacks a
part, the corresponding field is empty rather than guessed.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from rclverify.backends.shapes import AcceptingPath

_SECTION = re.compile(r"^={6,}\s*(\S.*?)\s*$")
_SUT = re.compile(r'AJPF_w_AIL\.main\((.*)\)')
_PATH_STEP = re.compile(r"\[MS:\s*(-?\d+)\s*,\s*BS:\s*(-?\d+)\s*,\s*UN:\s*(-?\d+)\s*\]")
_INFO = re.compile(r"^\s*(?:\[INFO\]|INFO:)\s?(.*)$")
_ADDING = re.compile(r"^Adding\s+(\d+)\s+to\s+\[([\d,\s]*)\]")
_DONE = re.compile(r"^(\S+)\s+done\s+(.+?)\s*$")
_ERROR_LINE = re.compile(r"^error\s+#?(\d+):\s*(\S+)\s*(.*)$")


@dataclass(frozen=True)
class AjpfResult:
    """What one AJPF log says.

    ``verdict``          ``verified`` (no errors, search complete),
                         ``incomplete-search`` (no errors, but a search
                         constraint was hit), ``violated`` (an accepting path of
                         the negated property: counterexample), ``error`` (another
                         JPF error, e.g. an uncaught exception in the model), or
                         ``unfinished`` (no results section: killed, crashed,
                         timed out);
    ``property_name``    the property label checked (third AJPF_w_AIL argument);
    ``psl_file``/``ail_file`` the files named in ``system under test``;
    ``accepting_path``   ``(model state, automaton state, until count)`` triples;
    ``trace``            one text per model state of the path, with the actions
                         logged on the way into it;
    ``errors``           the ``error #k`` lines of the results section;
    ``constraints``      JPF's count of search constraints hit (``None`` if absent);
    ``elapsed``          JPF's elapsed time text (``hh:mm:ss``);
    ``mcapl_version``/``jpf_version`` versions printed in the log ('' if absent).
    """

    verdict: str
    property_name: str | None = None
    psl_file: str | None = None
    ail_file: str | None = None
    accepting_path: tuple[tuple[int, int, int], ...] = ()
    trace: tuple[str, ...] = ()
    errors: tuple[str, ...] = ()
    constraints: int | None = None
    elapsed: str | None = None
    mcapl_version: str = ""
    jpf_version: str = ""
    info: tuple[str, ...] = field(default=(), repr=False)

    @property
    def tool_version(self) -> str:
        """``MCAPL 2020, JPF 8.0`` (the parts the log names)."""
        parts = []
        if self.mcapl_version:
            parts.append(f"MCAPL {self.mcapl_version}")
        if self.jpf_version:
            parts.append(f"JPF {self.jpf_version}")
        return ", ".join(parts) or "unknown"

    def counterexample(self) -> AcceptingPath | None:
        """JSON-ready counterexample for a ``violated`` result, else ``None``.

        ``{"accepting_path": ["MS 0, BS 2, UN 0", ...], "trace": ["state 0", "state 1: jackal done move(..)", ...]}``
        """
        if self.verdict != "violated":
            return None
        return {
            "accepting_path": [f"MS {m}, BS {b}, UN {u}" for m, b, u in self.accepting_path],
            "trace": list(self.trace),
        }

    def checks(self, property_text: str) -> bool | None:
        """Whether the log echoes ``property_text`` (whitespace ignored);
        ``None`` when the log echoes no property at all."""
        want = _squash(property_text)
        echoed = [_squash(i) for i in self.info]
        if not any(e.startswith(("[]", "<>", "(", "~", "B(", "G(", "D(", "I(", "P(")) for e in echoed):
            return None
        return any(e == want or e.endswith(":" + want) for e in echoed)


def _squash(text: str) -> str:
    return re.sub(r"\s+", "", text)


def parse_log(text: str) -> AjpfResult:
    """Parse the console output of one AJPF run (see the module docstring).

    Never raises for odd input: an empty or foreign text gives verdict
    ``unfinished`` with empty fields.
    """
    prop_name = psl_file = ail_file = None
    m = _SUT.search(text)
    if m:
        args = re.findall(r'"([^"]*)"', m.group(1))
        if len(args) >= 3:
            ail_file, psl_file, prop_name = args[0], args[1], args[2]
    results_lines: list[str] | None = None
    error_sections: list[list[str]] = []
    stats: list[str] = []
    for title, lines in _sections(text):
        if title == "results":
            results_lines = lines
        elif re.match(r"^error\s+\d+$", title):
            error_sections.append(lines)
        elif title == "statistics":
            stats = lines
    errors, no_errors = _results(results_lines)
    path, listener_error = _accepting_path(error_sections)
    listener_error = listener_error or any("MCAPLListener" in e for e in errors)
    constraints, elapsed = _statistics(stats)
    if listener_error:
        verdict = "violated"
    elif errors:
        verdict = "error"
    elif no_errors:
        verdict = "verified" if not constraints else "incomplete-search"
    else:
        verdict = "unfinished"
    info, arrivals = _info_lines(text)
    mv = re.search(r"MCAPL Framework\s+(\S+)", text)
    jv = re.search(r"JavaPathfinder core system v(\S+)", text)
    return AjpfResult(
        verdict=verdict, property_name=prop_name, psl_file=psl_file, ail_file=ail_file,
        accepting_path=tuple(path), trace=tuple(_trace(path, arrivals)), errors=tuple(errors),
        constraints=constraints, elapsed=elapsed, mcapl_version=mv.group(1) if mv else "",
        jpf_version=jv.group(1) if jv else "", info=tuple(info),
    )


def _sections(text: str) -> list[tuple[str, list[str]]]:
    """The log's sections as ``(title, lines)``; the text before the first
    rule of ``=`` is the section titled ``""``."""
    sections: list[tuple[str, list[str]]] = [("", [])]
    for line in text.splitlines():
        m = _SECTION.match(line)
        if m:
            sections.append((m.group(1), []))
        else:
            sections[-1][1].append(line)
    return sections


def _results(lines: list[str] | None) -> tuple[list[str], bool]:
    """The ``error #k`` lines of the results section ``lines`` and whether
    it says ``no errors detected`` (``None``: no results section)."""
    errors: list[str] = []
    no_errors = False
    for line in lines or ():
        s = line.strip()
        if s == "no errors detected":
            no_errors = True
        elif _ERROR_LINE.match(s):
            errors.append(s)
    return errors, no_errors


def _accepting_path(error_sections: list[list[str]]) -> tuple[list[tuple[int, int, int]], bool]:
    """The accepting path of the first error section from
    ``ajpf.MCAPLListener`` as ``(model state, automaton state, until
    count)`` triples, and whether there is such a section."""
    for lines in error_sections:
        body = "\n".join(lines)
        if "MCAPLListener" in body or "Accepting Path" in body:
            return [(int(a), int(b), int(c)) for a, b, c in _PATH_STEP.findall(body)], True
    return [], False


def _statistics(lines: list[str]) -> tuple[int | None, str | None]:
    """JPF's count of search constraints hit and its elapsed time text
    (``hh:mm:ss``) from the statistics section ``lines`` (``None`` where absent)."""
    constraints = None
    elapsed = None
    for line in lines:
        cm = re.search(r"constraints=(\d+)", line)
        if cm:
            constraints = int(cm.group(1))
        em = re.match(r"\s*elapsed time:\s*(\S+)", line)
        if em:
            elapsed = em.group(1)
    return constraints, elapsed


def _trace(path: list[tuple[int, int, int]], arrivals: dict[int, list[str]]) -> list[str]:
    """One text per model state of ``path``, with the actions logged on the
    way into it (``arrivals``, from :func:`_info_lines`); a state seen
    before is marked ``(again)``."""
    trace = []
    seen: set[int] = set()
    for ms, _, _ in path:
        if ms in seen:
            trace.append(f"state {ms} (again)")
            continue
        seen.add(ms)
        acts = arrivals.get(ms, [])
        trace.append(f"state {ms}" + (": " + "; ".join(acts) if acts else ""))
    return trace


def _info_lines(text: str) -> tuple[list[str], dict[int, list[str]]]:
    """Info messages, and for each model state the actions logged just before it was added."""
    info: list[str] = []
    arrivals: dict[int, list[str]] = {}
    pending: list[str] = []
    for line in text.splitlines():
        m = _INFO.match(line)
        if not m:
            continue
        msg = m.group(1).strip()
        info.append(msg)
        am = _ADDING.match(msg)
        if am:
            state = int(am.group(1))
            if pending or state not in arrivals:
                arrivals[state] = pending
            pending = []
            continue
        dm = _DONE.match(msg)
        if dm:
            pending.append(f"{dm.group(1)} done {dm.group(2)}")
    return info, arrivals
