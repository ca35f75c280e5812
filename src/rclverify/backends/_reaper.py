"""The reaper: kills the external tools of an rclverify process that died.

Run as a script (``python -I -S _reaper.py``), never imported: it uses the
standard library only.  :mod:`rclverify.backends.bounded` starts one per
rclverify process, in a session of its own, and keeps the write end of its
standard input.  Each line it receives is a JSON pair:

* ``["+g", pgid]`` / ``["-g", pgid]``: a tool's process group started / ended;
* ``["+d", path]`` / ``["-d", path]``: a temporary directory made / removed.

When its standard input reaches end of file -- the rclverify process ended,
normally or killed with SIGKILL, which nothing inside it can catch -- the
reaper sends SIGKILL to every process group still registered (the tool and
everything it started: ``gcc``'s ``cc1`` and ``as``, a JVM's children) and
removes every directory still registered, then exits.  A process group is
the unit because a parent-death signal (``PR_SET_PDEATHSIG``) reaches only
the direct child, not ``cc1`` (Linux ``prctl(2)``: the setting is cleared
in the child of a ``fork``).
"""
import json
import os
import shutil
import signal
import sys


def main() -> None:
    """Read registrations until end of file, then kill and remove what is left."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a terminal's Ctrl-C is the parent's to handle
    groups: set[int] = set()
    dirs: set[str] = set()
    for line in sys.stdin.buffer:
        try:
            op, arg = json.loads(line)
        except ValueError:
            continue
        if op == "+g":
            groups.add(int(arg))
        elif op == "-g":
            groups.discard(int(arg))
        elif op == "+d":
            dirs.add(str(arg))
        elif op == "-d":
            dirs.discard(str(arg))
    for pgid in groups:
        try:
            os.killpg(pgid, signal.SIGKILL)
        except OSError:
            pass
    for d in dirs:
        shutil.rmtree(d, ignore_errors=True)


if __name__ == "__main__":
    main()
