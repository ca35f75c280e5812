"""One endpoint from a name value (:mod:`symbols`): read now when the file
alone tells it, left to the linker (:mod:`link`) when it needs the program
(a constructor argument, a member, an imported constant), or a located
``ROS-UNRESOLVED`` note when it cannot be read statically (docs/ros.md,
"Reading real code").  Used by both source readers and by the linker, so the
notes say the same thing whoever gives up.
"""
from __future__ import annotations

from typing import Any

from rclverify.ros.extract import symbols
from rclverify.ros.extract.model import Endpoint, Note, Src

WHAT = {"pub": "publisher topic", "sub": "subscriber topic", "service_servers": "service server",
        "service_clients": "service client", "action_servers": "action server", "action_clients": "action client"}


def short(text: str, limit: int = 80) -> str:
    """Source text quoted in a note, cut to ``limit`` characters."""
    return text if len(text) <= limit else text[: limit - 3] + "..."


def make(kind: str, name: symbols.Val, handle: symbols.Val, msg_type: str | None, src: Src, unit: str | None,
         func: str | None, written: str, name_src: Src, cb: Any = None) -> tuple[Endpoint | None, Note | None]:
    """The endpoint of role ``kind`` created at ``src`` whose name has value ``name``
    (written ``written`` at ``name_src``) through handle ``handle``: resolved
    when both values are concrete (and the type is known or cannot be found
    elsewhere), else pending (``Endpoint.pending``), or ``(None, note)``."""
    if symbols.is_concrete(name) and symbols.is_concrete(handle) and (msg_type is not None or cb is None):
        return resolve(kind, name, handle, msg_type, src, unit, written, name_src, func)
    return Endpoint(kind, "", msg_type, src, None, (), unit, (name, handle, cb, func, written, name_src), func), None


def resolve(kind: str, name: symbols.Val, handle: symbols.Val, msg_type: str | None, src: Src, unit: str | None,
            written: str, name_src: Src, func: str | None = None) -> tuple[Endpoint | None, Note | None]:
    """The endpoint for concrete values ``name`` and ``handle`` (see :func:`make`),
    or ``(None, note)`` when either cannot be read."""
    what = WHAT[kind]
    if name is not None and name[0] == "runtime":  # argv, argparse, the graph at run time (symbols)
        return None, Note(name_src, f"{what} name is '{short(written)}', {name[1]}: not resolved statically")
    if name is None or name[0] in ("arg", "field", "ext", "nh", "ret"):
        return None, Note(name_src, f"{what} name is '{short(written)}', not a string literal: not resolved statically")
    segs = symbols.segments(handle)
    if segs is None:
        return None, Note(src, f"namespace of the node handle of {what} '{short(written)}' is computed at run "
                               f"time: not resolved statically")
    if name[0] == "param":
        psegs = symbols.segments(name[3])
        if psegs is None:
            return None, Note(src, f"namespace of the node handle the parameter of {what} '{short(written)}' is "
                                   f"read through is computed at run time: not resolved statically")
        return Endpoint(kind, name[2] or "", msg_type, src, symbols.param_name(name[1], psegs), tuple(segs), unit,
                        None, func), None
    if name[0] == "cat":  # '/%s/pose' % rospy.get_param('~turtle'): one parameter between literals
        ps = [i for i, x in enumerate(name[1]) if x is not None and x[0] == "param"]
        texts = [symbols.text(x) for x in name[1]]
        if len(ps) == 1 and all(t is not None for i, t in enumerate(texts) if i != ps[0]):
            p = name[1][ps[0]]
            psegs = symbols.segments(p[3])
            if psegs is not None:
                # read only where a launch file sets the parameter (the code's default alone is not
                # taken for a name built around it: docs/ros.md); else the note below
                pre, post = "".join(texts[:ps[0]]), "".join(texts[ps[0] + 1:])  # type: ignore[arg-type]
                unread = Note(name_src, f"{what} name is '{short(written)}', not a string literal: not resolved "
                                        f"statically")
                return Endpoint(kind, "", msg_type, src, symbols.param_name(p[1], psegs), tuple(segs), unit, None,
                                func, (pre, post), unread), None
    t = symbols.text(name)
    if t is None:
        return None, Note(name_src, f"{what} name is '{short(written)}', not a string literal: not resolved statically")
    return Endpoint(kind, t, msg_type, src, None, tuple(segs), unit, None, func), None


def type_note(e: Endpoint) -> Note:
    """The note of an endpoint whose type cannot be read statically."""
    return Note(e.src, f"type of {WHAT[e.kind]} '{symbols.under(list(e.handle), e.topic) or e.param}' "
                       f"not resolved statically")
