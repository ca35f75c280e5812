"""A package's ``CMakeLists.txt`` read as CMake commands (no CMake is run).

The CMake language (cmake-language(7)): a file is a sequence of command
invocations ``name(arg ...)``; ``#`` comments (and ``#[[ ]]`` bracket
comments) are dropped; an argument is unquoted, ``"quoted"`` or a
``[[bracket]]`` argument; ``${VAR}`` references are substituted from
``set(VAR value...)`` in order (``${PROJECT_NAME}`` is the package name); ``include(file.cmake)`` of a package
file runs that file's commands in place.

``function(name params...)`` / ``macro(name params...)`` bodies are recorded
and each call of them is replaced by the body with ``${param}``, ``${ARGV}``,
``${ARGN}``, ``${ARGVn}`` substituted (and ``cmake_parse_arguments(PREFIX
options one-value multi-value ${ARGN})`` evaluated, giving ``${PREFIX_KEY}``),
so a project's own wrapper of ``rclcpp_components_register_node`` or
``add_executable`` is traced to the commands it runs.  ``foreach(v items...)``
(also ``RANGE``, ``IN LISTS``/``IN ITEMS``) runs its body once per item with
``${v}`` substituted; ``file(GLOB|GLOB_RECURSE var patterns...)`` lists the
package's files through the caller's ``glob``.  ``if``/``while`` are not
evaluated: every branch's commands count.  Work is bounded
(:data:`MAX_COMMANDS`, :data:`MAX_DEPTH`, :data:`MAX_ITEMS`).
"""
from __future__ import annotations

import re
from typing import Callable

MAX_COMMANDS = 20_000  # commands produced, expansions included
MAX_DEPTH = 8  # nested function/macro calls and foreach loops
MAX_ITEMS = 1000  # items of one foreach

_CMD = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)[ \t]*\(")
_ARG = re.compile(r'"((?:[^"\\]|\\.)*)"|\[(=*)\[(.*?)\]\2\]|([^\s()"#]+)', re.S)
_VAR = re.compile(r"\$\{([A-Za-z0-9_.+\-/]+)\}")


def _strip_comments(text: str) -> str:
    text = re.sub(r"#\[(=*)\[.*?\]\1\]", " ", text, flags=re.S)
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(text[i:j + 1])
            i = j + 1
        elif c == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def commands_of(text: str) -> list[tuple[str, list[str], int]]:
    """``[(command name lower-cased, raw arguments, line)]`` of CMake source ``text``
    (arguments unsubstituted; quotes and brackets removed; nested parentheses kept
    as separate tokens' text)."""
    text = _strip_comments(text)
    out: list[tuple[str, list[str], int]] = []
    pos = 0
    while len(out) < MAX_COMMANDS:
        m = _CMD.search(text, pos)
        if m is None:
            break
        depth, j = 1, m.end()
        while j < len(text) and depth:
            if text[j] == '"':
                k = j + 1
                while k < len(text) and text[k] != '"':
                    k += 2 if text[k] == "\\" else 1
                j = k + 1
                continue
            depth += {"(": 1, ")": -1}.get(text[j], 0)
            j += 1
        body = text[m.end(): j - 1]
        args = [a.group(1) if a.group(1) is not None else a.group(3) if a.group(3) is not None else a.group(4)
                for a in _ARG.finditer(body)]
        out.append((m.group(1).lower(), args, text.count("\n", 0, m.start()) + 1))
        pos = j
    return out


def _subst(s: str, env: dict[str, str]) -> str:
    for _ in range(8):
        new = _VAR.sub(lambda m: env.get(m.group(1), ""), s)
        if new == s:
            break
        s = new
    return s


def _items(args: list[str], env: dict[str, str]) -> list[str]:
    """The items of ``foreach(var ...)`` given its substituted arguments after ``var``."""
    if args[:1] == ["RANGE"]:
        try:
            n = [int(a) for a in args[1:4]]
        except ValueError:
            return []
        start, stop, step = (0, n[0], 1) if len(n) == 1 else (n[0], n[1], n[2] if len(n) > 2 else 1)
        return [str(i) for i in range(start, stop + 1, step or 1)][:MAX_ITEMS] if step > 0 else []
    if args[:1] == ["IN"]:
        out: list[str] = []
        mode = None
        for a in args[1:]:
            if a in ("LISTS", "ITEMS", "ZIP_LISTS"):
                mode = a
            elif mode == "LISTS":
                out.extend(x for x in env.get(a, "").split(";") if x)
            elif mode == "ITEMS":
                out.append(a)
        return out[:MAX_ITEMS]
    return args[:MAX_ITEMS]


def _block(seq: list[tuple[str, list[str], int]], i: int, opener: str, closer: str) -> tuple[list[_Cmd], int]:
    """The commands between ``seq[i]`` (an ``opener``) and its matching ``closer``, and
    the index of that closer (``len(seq)`` when missing)."""
    body: list[_Cmd] = []
    depth, j = 1, i + 1
    while j < len(seq):
        if seq[j][0] == opener:
            depth += 1
        elif seq[j][0] == closer:
            depth -= 1
            if not depth:
                break
        body.append(seq[j])
        j += 1
    return body, j


_Cmd = tuple[str, list[str], int]


Definitions = dict[str, tuple[list[str], list[tuple[str, list[str], int]]]]


def definitions_of(text: str) -> Definitions:
    """The ``function``/``macro`` definitions of CMake source ``text`` (name
    lower-cased -> (parameters, body)): what a package exports for others to
    call (``cmake/*.cmake``, ``*-extras.cmake``)."""
    return _definitions(commands_of(text))[0]


def expand(text: str, pkg: str, glob: Callable[[str, bool], list[str]] | None = None,
           read: Callable[[str], str | None] | None = None,
           extra: Definitions | None = None) -> list[tuple[str, list[str], int]]:
    """The commands ``text`` runs, with variables substituted, ``foreach`` loops
    unrolled and calls of the file's own ``function``/``macro`` definitions
    replaced by their bodies (arguments substituted); each keeps the line of
    the top-level call.  Arguments holding ``;`` lists are split, as CMake does
    for unquoted ones.  ``glob(pattern, recurse)`` lists the package files a
    ``file(GLOB ...)`` pattern matches (relative paths); without it globs are empty.
    ``read(path)`` gives the text of a package file an ``include(path.cmake)`` names
    (``None`` when it cannot): its commands, its functions and macros included, run
    where the ``include`` is, at its line.  ``extra``: the functions and macros of
    other packages (:func:`definitions_of`), called as the package's own are; the
    package's own of the same name win."""
    defs, top = _definitions(_included(commands_of(text), read, 0))
    runner = _Runner({**(extra or {}), **defs}, glob)
    runner.run(top, {"PROJECT_NAME": pkg, "CMAKE_CURRENT_SOURCE_DIR": ".", "PROJECT_SOURCE_DIR": "."}, 0, None)
    return runner.out


MAX_INCLUDES = 4  # nested include() of package .cmake files


def _included(cmds: list[_Cmd], read: Callable[[str], str | None] | None, depth: int) -> list[_Cmd]:
    """``cmds`` with each ``include(file.cmake)`` of the package replaced by that
    file's commands (at the ``include``'s line); a module name (``include(CTest)``)
    or a file that cannot be read stays as it is."""
    out: list[_Cmd] = []
    for name, args, line in cmds:
        if name == "include" and read is not None and args and depth < MAX_INCLUDES \
                and args[0].endswith(".cmake"):
            path = args[0]
            for var in ("${CMAKE_CURRENT_SOURCE_DIR}/", "${PROJECT_SOURCE_DIR}/", "${CMAKE_CURRENT_LIST_DIR}/"):
                path = path.replace(var, "")
            text = read(path) if "${" not in path else None
            if text is not None:
                out += [(n, a, line) for n, a, _l in _included(commands_of(text), read, depth + 1)]
                continue
        out.append((name, args, line))
    return out


def _definitions(cmds: list[_Cmd]) -> tuple[dict[str, tuple[list[str], list[_Cmd]]], list[_Cmd]]:
    """The file's ``function``/``macro`` definitions (name lower-cased ->
    (parameters, body)) and its other top-level commands."""
    defs: dict[str, tuple[list[str], list[_Cmd]]] = {}
    top: list[_Cmd] = []
    i = 0
    while i < len(cmds):
        name, args, line = cmds[i]
        if name in ("function", "macro") and args:
            body, i = _block(cmds, i, name, "endfunction" if name == "function" else "endmacro")
            defs[args[0].lower()] = (args[1:], body)
        else:
            top.append(cmds[i])
        i += 1
    return defs, top


class _Runner:
    """Runs commands into ``out`` (bounded by :data:`MAX_COMMANDS` and :data:`MAX_DEPTH`)."""

    def __init__(self, defs: dict[str, tuple[list[str], list[_Cmd]]],
                 glob: Callable[[str, bool], list[str]] | None) -> None:
        self.defs, self.glob = defs, glob
        self.out: list[_Cmd] = []

    def run(self, seq: list[_Cmd], env: dict[str, str], depth: int, at: int | None) -> None:
        """Run ``seq`` in ``env`` at nesting ``depth``; ``at`` the line of the
        top-level call every produced command keeps (``None``: its own)."""
        i = 0
        while i < len(seq):
            name, raw, line = seq[i]
            i += 1
            if len(self.out) >= MAX_COMMANDS:
                return
            args = [x for a in raw for x in _subst(a, env).split(";") if x != ""]
            where = at if at is not None else line
            if name == "foreach":
                body, end = _block(seq, i - 1, "foreach", "endforeach")
                i = end + 1
                if args and depth < MAX_DEPTH:
                    for item in _items(args[1:], env):
                        env[args[0]] = item
                        self.run(body, env, depth + 1, where)
                continue
            if name == "file" and len(args) >= 2 and args[0] in ("GLOB", "GLOB_RECURSE"):
                self.file_glob(args, env)
                continue
            if name == "set" and args:
                env[args[0]] = ";".join(a for a in args[1:] if a != "PARENT_SCOPE")
            elif name == "project" and args:
                env["PROJECT_NAME"] = args[0]
            elif name == "cmake_parse_arguments" and len(args) >= 4:
                _parse_arguments(raw, env)
            elif name in self.defs and depth < MAX_DEPTH:
                self.call(name, args, env, depth, where)
            else:
                self.out.append((name, args, where))

    def file_glob(self, args: list[str], env: dict[str, str]) -> None:
        """``file(GLOB|GLOB_RECURSE var [RELATIVE dir] patterns...)``: ``var`` the files found."""
        pats = [a for a in args[2:] if a not in ("LIST_DIRECTORIES", "CONFIGURE_DEPENDS", "true", "false")]
        if "RELATIVE" in pats:
            k = pats.index("RELATIVE")
            pats = pats[:k] + pats[k + 2:]
        glob = self.glob
        found = [f for p in pats for f in (glob(p, args[0] == "GLOB_RECURSE") if glob else [])]
        env[args[1]] = ";".join(sorted(set(found)))

    def call(self, name: str, args: list[str], env: dict[str, str], depth: int, where: int) -> None:
        """A call of the file's own function or macro: its body run with its
        parameters, ``ARGV``, ``ARGN``, ``ARGC`` and ``ARGVn`` set."""
        params, body = self.defs[name]
        inner = dict(env)
        for k, p in enumerate(params):
            inner[p] = args[k] if k < len(args) else ""
        inner["ARGV"] = ";".join(args)
        inner["ARGN"] = ";".join(args[len(params):])
        inner["ARGC"] = str(len(args))
        for k, a in enumerate(args):
            inner[f"ARGV{k}"] = a
        self.run(body, inner, depth + 1, where)


def _parse_arguments(raw: list[str], env: dict[str, str]) -> None:
    """``cmake_parse_arguments(PREFIX options one-value multi-value args...)``:
    ``PREFIX_KEY`` set in ``env`` (cmake-commands(7))."""
    prefix, opts, one, multi = (_subst(x, env) for x in raw[:4])
    rest = [x for a in raw[4:] for x in _subst(a, env).split(";") if x != ""]
    o, s, m = opts.split(";"), one.split(";"), multi.split(";")
    for k in o + s + m:
        if k:
            env[f"{prefix}_{k}"] = ""
    cur = None
    for tok in rest:
        if tok in o:
            env[f"{prefix}_{tok}"], cur = "TRUE", None
        elif tok in s or tok in m:
            cur = tok
        elif cur is not None:
            key = f"{prefix}_{cur}"
            env[key] = f"{env[key]};{tok}" if env.get(key) and cur in m else tok
            if cur in s:
                cur = None
