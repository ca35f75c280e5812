"""Symbolic names: what a source file says about a topic, service, action or
node name that it does not write as one literal (docs/ros.md, "Reading real
code").  Both source readers (C++ and Python) give these values; the linker
(:mod:`link`) evaluates them across the files of one program.

A value is a tuple (hashable, picklable, so it lives in the parse cache):

* ``("str", s)``: a literal string;
* ``("arg", callable, i)``: the ``i``-th parameter of a function or
  constructor (``callable`` its key), bound where the program calls it;
* ``("field", unit, name)``: a member of class ``unit`` (C++ member,
  Python ``self.name``), bound in the class's constructor or methods;
* ``("param", name, default, handle)``: a ROS parameter read (``name`` a string,
  or the value of a ROS 2 key computed in the code, without its ``~``; ``default`` a
  string or ``None``, or a value of the function's own parameters that the
  linker reads to a string (a ``declare_parameter`` wrapper's default);
  ``handle`` the node handle it is read through, a value
  or ``None``; the parameter's name resolves against that handle's namespace);
* ``("ret", callee, unit, args)``: what a workspace function returns, called
  as ``callee`` (its text as written) from unit ``unit`` with argument values
  ``args``: the linker reads the callee's ``return`` statements with those
  arguments (a wrapper of ``declare_parameter``);
* ``("nh", segments)``: a node handle (roscpp ``ros::NodeHandle``, an rclcpp
  node or sub-node): what it adds to the node's namespace, in order, each
  ``("ns", value)`` (a namespace: ``"~"`` private, ``"left"`` relative) or
  ``("h", value)`` (the handle it was made from, spliced in; one that cannot be
  read is the node's own handle);
* ``("node",)``: the node's own full name (``ros::this_node::getName()``,
  ``rospy.get_name()``), which ROS resolves like ``~``;
* ``("cat", parts)``: the concatenation of ``parts``;
* ``("ext", dotted)``: a Python name imported from another module of the
  package (``from pkg.names import TOPIC``);
* ``("spec", struct)``: the ``static constexpr char name[]`` of interface
  spec ``struct`` (``ns::Spec``, an adaptor's template argument), read by the
  linker from the program's class of that name, never from another's;
* ``("each", param)``: one element of the string-array ROS 2 parameter
  ``param`` (``~observation_sources``), a C++ range-for's variable over it;
  its text is ``[~observation_sources]``, which the graph expands with the
  parameter's value (:func:`rclverify.ros.extract.param_yaml.expand_each`);
* ``("info", image)``: the ``camera_info`` topic image_transport pairs with
  image topic ``image`` (its namespace + ``camera_info``), for an image topic
  only the linker can read (a member, a parameter of the function);
* ``("opts", arguments)``: an ``rclcpp::NodeOptions`` given command-line
  ``arguments`` (``NodeOptions().arguments({"--ros-args", "-r",
  "__node:=fusion"})``), a tuple of values; the node it makes takes the name
  and namespace their remaps give (:func:`node_remaps`);
* ``("optarg", options, i)``: the ``i``-th of those arguments read back
  (``options.arguments()[0]``, ``.at(0)``, ``.front()``);
* ``("any", values)``: one of ``values`` each time (a range-for's variable
  over a container of literals, ``for (auto & [key, topic] : topics)``): one
  endpoint per value; ``("pair", (a, b))`` is one element of a map;
* ``("runtime", origin)``: a name only the running program knows, and where
  it comes from (``from argv``, ``from argparse option --topic``,
  ``discovered at run time (get_topic_names_and_types())``): never read, its
  located note says the origin.

``None`` is a value nobody can read statically (a computed string).
Source of the naming rules: ROS 1 wiki "Names" and roscpp's ``NodeHandle``
documentation (a handle's namespace is resolved, and remapped, when the
handle is made); ROS 2 design "Topic and Service Names".
"""
from __future__ import annotations

from typing import Any

Val = Any  # a tuple as described above, or None

NODE: tuple[str] = ("node",)


def lit(s: str) -> tuple[str, str]:
    """The literal ``s``."""
    return ("str", s)


def cat(parts: list[Val]) -> Val:
    """The concatenation of ``parts`` with adjacent literals folded; ``None`` when
    any part is ``None``; a single part is itself."""
    out: list[Val] = []
    for p in parts:
        if p is None:
            return None
        items = p[1] if p[0] == "cat" else (p,)
        for x in items:
            if out and x[0] == "str" and out[-1][0] == "str":
                out[-1] = ("str", out[-1][1] + x[1])
            else:
                out.append(x)
    if not out:
        return ("str", "")
    return out[0] if len(out) == 1 else ("cat", tuple(out))


def camera_info(image: Val) -> Val:
    """The ``camera_info`` topic beside image topic ``image`` (image_transport's
    ``getCameraInfoTopic``: the image topic's namespace + ``camera_info``): a
    literal when ``image``'s text is known, ``("info", image)`` while it needs
    the program's context, ``None`` when it cannot be read."""
    t = text(image)
    if t is None:
        return ("info", image) if image is not None and not is_concrete(image) else None
    head = t.rsplit("/", 1)[0] + "/" if "/" in t else ("~" if t.startswith("~") else "")
    return lit(head + "camera_info")


def is_concrete(v: Val) -> bool:
    """Whether ``v`` needs no program context (no ``arg``, ``field`` or ``ext``
    part): it can be read, or be found unreadable, in its file alone."""
    if v is None:
        return True
    k = v[0]
    if k in ("arg", "field", "ext", "ret", "any"):
        return False
    if k == "info":
        return is_concrete(v[1])
    if k == "opts":
        return all(is_concrete(x) for x in v[1])
    if k == "optarg":
        return is_concrete(v[1])
    if k == "param":
        return is_concrete(v[3]) and (isinstance(v[1], str) or is_concrete(v[1])) and \
            (not isinstance(v[2], tuple) or is_concrete(v[2]))
    if k == "nh":
        return all(is_concrete(x) for _kind, x in v[1])
    if k == "cat":
        return all(is_concrete(x) for x in v[1])
    return True


def text(v: Val) -> str | None:
    """The string a concrete value stands for (``("node",)`` is ``~``, the node's
    own name, as the first part of a name only); ``None`` for a parameter read,
    a handle, a name with the node's name after its start, or anything unknown."""
    if v is None:
        return None
    if v[0] == "str":
        return str(v[1])
    if v[0] == "node":
        return "~"
    if v[0] == "each":
        return f"[{v[1]}]"
    if v[0] == "cat":
        if any(x is not None and x[0] == "node" for x in v[1][1:]):
            return None  # "get_cost_" + get_name(): the node's bare name inside a name, which "~" is not
        parts = [text(x) for x in v[1]]
        if any(p is None for p in parts):
            return None
        s = "".join(p for p in parts if p is not None)
        return "~" + s[1:].lstrip("/") if s.startswith("~") else s
    return None


def segments(v: Val) -> list[str] | None:
    """A concrete handle value's namespaces as strings (``[]`` for the node's own
    handle, and for any value that is no handle); ``None`` when a namespace of
    it is not a string."""
    if v is None or v[0] != "nh":
        return []
    out: list[str] = []
    for kind, x in v[1]:
        if kind == "h":
            inner = segments(x)
            if inner is None:
                return None
            out.extend(inner)
            continue
        t = text(x)
        if t is None:
            return None
        if t:
            out.append(t)
    return out


def under(handle: list[str], name: str) -> str:
    """``name`` as written through a handle of namespaces ``handle``, in the
    written form the graph resolves: ``["~"]`` + ``status`` is ``~status``,
    ``["left"]`` + ``scan`` is ``left/scan``; a global or private ``name``, or an
    empty handle, leaves it as it is."""
    if not handle or name.startswith(("/", "~")):
        return name
    ns = handle[0]
    for s in handle[1:]:
        ns = s if s.startswith(("/", "~")) else f"{ns.rstrip('/')}/{s}"
    if ns == "~":
        return f"~{name}"
    return f"{ns.rstrip('/')}/{name}" if name else ns


def param_name(pname: str, handle: list[str] | None) -> str:
    """A parameter's name read through a handle: ``param_name("rate", ["~"])`` is
    ``~rate`` (roscpp resolves parameter names like topic names)."""
    return under(handle or [], pname)


#: the remap names rcl reads for a node's name and namespace (rcl/src/rcl/arguments.c, ROS 2
#: design "Remapping Names": ``__node:=`` and its older spelling ``__name:=``, ``__ns:=``)
_NODE_KEYS, _NS_KEYS = ("__node:=", "__name:="), ("__ns:=",)


def node_remaps(opts: Val) -> tuple[str | None, str | None]:
    """``(name, namespace)`` the remap rules of an ``("opts", arguments)`` value
    give the node it makes (``-r __node:=n``, ``--remap __ns:=/x``, ``-r
    n:__node:=m`` is left out: it targets another node), ``None`` for each not
    given; the last rule wins, as rcl applies them."""
    name = ns = None
    if opts is None or opts[0] != "opts":
        return None, None
    for x in opts[1]:
        t = text(x) if x is not None else None
        if t is None:
            continue
        for key in _NODE_KEYS:
            if t.startswith(key):
                name = t[len(key):]
        if t.startswith(_NS_KEYS[0]):
            ns = t[len(_NS_KEYS[0]):]
    return name, ns
