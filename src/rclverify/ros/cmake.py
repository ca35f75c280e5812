"""A package's ``CMakeLists.txt`` read as CMake commands (no CMake is run).

The CMake language (cmake-language(7)): a file is a sequence of command
invocations ``name(arg ...)``; ``#`` comments (and ``#[[ ]]`` bracket
comments) are dropped; an argument is unquoted, ``"quoted"`` or a
``[[bracket]]`` argument; ``${VAR}`` references are substituted from
``set(VAR value...)`` in order (``${PROJECT_NAME}`` is the package name).

``function(name params...)`` / ``macro(name params...)`` bodies are recorded
and each call of them is replaced by the body with ``${param}``, ``${ARGV}``,
``${ARGN}``, ``${ARGVn}`` substituted (and ``cmake_parse_arguments(PREFIX
options one-value multi-value ${ARGN})`` evaluated, giving ``${PREFIX_KEY}``),
so a project's own wrapper of ``rclcpp_components_register_node`` or
``add_executable`` is traced to the commands it runs.  ``if``/``foreach`` are
not evaluated: every branch's commands count.  Work is bounded
(:data:`MAX_COMMANDS`, :data:`MAX_DEPTH`).
"""
from __future__ import annotations

import re

MAX_COMMANDS = 20_000  # commands produced, expansions included
MAX_DEPTH = 8  # nested function/macro calls

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


def expand(text: str, pkg: str) -> list[tuple[str, list[str], int]]:
    """The commands ``text`` runs, with variables substituted and calls of the
    file's own ``function``/``macro`` definitions replaced by their bodies
    (arguments substituted); each keeps the line of the top-level call.
    Arguments holding ``;`` lists are split, as CMake does for unquoted ones."""
    cmds = commands_of(text)
    defs: dict[str, tuple[list[str], list[tuple[str, list[str], int]]]] = {}
    top: list[tuple[str, list[str], int]] = []
    i = 0
    while i < len(cmds):
        name, args, line = cmds[i]
        if name in ("function", "macro") and args:
            end = "endfunction" if name == "function" else "endmacro"
            body, depth, i = [], 1, i + 1
            while i < len(cmds) and depth:
                if cmds[i][0] == name:
                    depth += 1
                elif cmds[i][0] == end:
                    depth -= 1
                    if not depth:
                        break
                body.append(cmds[i])
                i += 1
            defs[args[0].lower()] = (args[1:], body)
        else:
            top.append(cmds[i])
        i += 1
    out: list[tuple[str, list[str], int]] = []
    env = {"PROJECT_NAME": pkg, "CMAKE_CURRENT_SOURCE_DIR": ".", "PROJECT_SOURCE_DIR": "."}

    def run(seq: list[tuple[str, list[str], int]], env: dict[str, str], depth: int, at: int | None) -> None:
        for name, raw, line in seq:
            if len(out) >= MAX_COMMANDS:
                return
            args = [x for a in raw for x in _subst(a, env).split(";") if x != ""]
            where = at if at is not None else line
            if name == "set" and args:
                env[args[0]] = ";".join(a for a in args[1:] if a != "PARENT_SCOPE")
            elif name == "project" and args:
                env["PROJECT_NAME"] = args[0]
            elif name == "cmake_parse_arguments" and len(args) >= 4:
                _parse_arguments(raw, env)
            elif name in defs and depth < MAX_DEPTH:
                params, body = defs[name]
                inner = dict(env)
                for k, p in enumerate(params):
                    inner[p] = args[k] if k < len(args) else ""
                inner["ARGV"] = ";".join(args)
                inner["ARGN"] = ";".join(args[len(params):])
                inner["ARGC"] = str(len(args))
                for k, a in enumerate(args):
                    inner[f"ARGV{k}"] = a
                run(body, inner, depth + 1, where)
            else:
                out.append((name, args, where))

    def _parse_arguments(raw: list[str], env: dict[str, str]) -> None:
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
    run(top, env, 0, None)
    return out
