"""The nodes and edges of a scanned graph (:mod:`.scan`): a node added with
its endpoints resolved against its parameters and remaps
(:meth:`GraphNodes.add_node`, the callback
:class:`~rclverify.ros.graph.assemble.Assembly` calls per node), programs
no launch file starts kept apart by their executable (:func:`apart_name`),
and each endpoint's edge, its name taken from a parameter where the code
reads it from one.  Mixed into the scan's state, which provides the
attributes annotated on the class.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

from rclverify.ros.extract import names
from rclverify.ros.extract import namespaces
from rclverify.ros.graph.assemble import Assembly
from rclverify.ros.extract.model import Endpoint, Graph, GraphEdge, GraphNode, Note, Src
from rclverify.ros.extract.param_yaml import PackageParams, expand_each


class GraphNodes:
    """Adding nodes and their edges to the scan's graph (module docstring)."""

    g: Graph
    unsure: dict[Src, Src]  # a launch node -> the unevaluated condition it was read under
    by_ros_name: dict[str, list[str]]  # a ROS node name -> the graph nodes of the programs taking it
    launch_params: dict[str, tuple[str, Src]]
    pfiles: PackageParams
    asm: Assembly

    def add_node(self, full: str, ns: str, pkg: str | None, exe: str | None, files: list[str], declared: Src,
                 eps: list[Endpoint], remaps: list[tuple[str, str, Src]], origin: str,
                 params: dict[str, tuple[str, Src]] | None = None, lifecycle: bool = False) -> None:
        """Add the node ``full`` (in namespace ``ns``) with its endpoints
        ``eps`` resolved against its parameters and ``remaps``: the callback
        :class:`~rclverify.ros.graph.assemble.Assembly` calls per node."""
        g = self.g
        node = GraphNode(full, ns, pkg, exe, files, declared, origin=origin, lifecycle=lifecycle)
        key = full
        if origin == "source":
            node, key = self._source_key(node, full, pkg, exe, files, declared, lifecycle)
        elif full in g.nodes:
            first = g.nodes[full].declared_at
            guess = self.unsure.get(declared) or (self.unsure.get(first) if first is not None else None)
            if guess is not None:  # one of two branches whose condition is not known: alternatives
                g.notes.append(Note(declared, f"node {full} is also started at {first}, under a condition not "
                                              f"evaluated statically ({guess}): taken as alternatives, the first "
                                              f"is kept", "ROS-LAUNCH"))
                return
            g.notes.append(Note(declared, f"node {full} is started twice (first at {first}); "
                                          f"ROS keeps only the last one", "ROS-LAUNCH"))
        mine: dict[str, Any] = {names.resolve(k, ns, full): v for k, v in (params or {}).items()}
        if origin == "source":  # no launch file: the package's parameter files (param_yaml)
            from_files, said = self.pfiles.for_node(pkg, full)
            g.notes.extend(said)
            mine = {**from_files, **mine}
            more, more_files, said = self.asm.plugin_endpoints(full, mine)  # pluginlib plugins it loads
            g.notes.extend(said)
            eps = eps + more
            node.sources.extend(f for f in more_files if f not in node.sources)
        eps = expand_each(eps, lambda a: (mine.get(names.resolve(a, ns, full)) or (None,))[0], g.notes)
        for e in eps:
            self._add_edge(node, e, mine, ns, full, remaps)
        g.nodes[key] = node

    def _source_key(self, node: GraphNode, full: str, pkg: str | None, exe: str | None, files: list[str],
                    declared: Src, lifecycle: bool) -> tuple[GraphNode, str]:
        """A node no launch file starts: each program taking a name is a node
        of its own, kept apart by its executable (docs/ros.md, "Programs
        without launch files"); returns the node to fill and its graph key."""
        g = self.g
        key = full
        keys = self.by_ros_name.setdefault(full, [])
        same = next((k for k in keys if g.nodes[k].declared_at == declared), None)
        if same is not None:  # one code named twice (an executable and its component): one node
            node, key = g.nodes[same], same
            node.lifecycle = node.lifecycle or lifecycle
            node.sources.extend(f for f in files if f not in node.sources)
        elif keys:
            if keys == [full]:  # the first program taking the name is kept apart too
                first = g.nodes.pop(full)
                first.name = keys[0] = apart_name(full, first.package, first.executable, first.declared_at,
                                                  g.nodes)
                g.nodes[first.name] = first
            key = node.name = apart_name(full, pkg, exe, declared, g.nodes)
            g.notes.append(Note(declared, f"node {full} is also named at {g.nodes[keys[0]].declared_at}; "
                                          f"no launch file starts these programs together: kept apart as "
                                          f"{key} (and {', '.join(keys)})", "ROS-LAUNCH"))
            keys.append(key)
        else:
            keys.append(full)
        return node, key

    def _add_edge(self, node: GraphNode, e: Endpoint, mine: dict[str, Any], ns: str, full: str,
                  remaps: list[tuple[str, str, Src]]) -> None:
        """The edge of endpoint ``e``, its name taken from a parameter where
        the code reads it from one (``mine``: the node's parameters)."""
        written, pname, set_at = e.topic, None, None
        if e.param is not None:
            pname = names.resolve(e.param, ns, full)
            got = mine.get(pname) or self.launch_params.get(pname)
            if got is not None and isinstance(got[0], str):
                written, set_at = e.affix[0] + got[0] + e.affix[1], got[1]
            elif e.unread is not None:
                self.g.notes.append(e.unread)
                return
            elif not e.topic:
                self.g.notes.append(Note(e.src, f"name of {e.kind} comes from parameter {pname}, which has no "
                                                f"default in the code and no value in the launch files: "
                                                f"not resolved statically"))
                return
        topic, at = namespaces.resolve(written, e.handle, ns, full, remaps)
        edge = GraphEdge(topic, e.msg_type, e.src, at, namespaces.shown(written, e.handle), pname, set_at, e.via)
        lst = node.edges_of(e.kind)
        # every call site keeps its own edge (the same name created twice is two edges)
        if not any(x.topic == edge.topic and x.msg_type == edge.msg_type and x.src == edge.src for x in lst):
            lst.append(edge)


def apart_name(full: str, pkg: str | None, exe: str | None, declared: Src | None, taken: dict[str, Any]) -> str:
    """The graph name of one of several programs that take node name ``full`` with no
    launch file starting them: ``/talker@demo_nodes_cpp.talker`` (``full@package.executable``;
    the file's stem for a loose file; characters other than letters, digits, ``_``
    and ``.`` as ``_``; ``.2``, ``.3`` ... appended while ``taken`` has it).  The
    ``@`` makes it no ROS name, so it is never a running node's (docs/ros.md)."""
    what = exe or (Path(declared.file).stem if declared is not None else "program")
    tail = "".join(c if c.isalnum() or c in "_." else "_" for c in f"{pkg or 'loose'}.{what}")
    out, k = f"{full}@{tail}", 1
    while out in taken:
        k += 1
        out = f"{full}@{tail}.{k}"
    return out
