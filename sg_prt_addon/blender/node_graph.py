"""A node tree as its readers see it: node groups entered (nested, each group's inputs its node's sockets, an
unlinked one its default), reroutes, muted nodes (through their internal links) and muted links passed.

The readers (node_reader, world_reader) take a GraphNode for the output node and walk it as they would the bpy
nodes: a GraphNode answers what its bpy node answers, and its sockets' links lead straight to the node that
computes the value, wherever that lies.  A node inside a group is named by its path ("Group/Principled BSDF").
"""
from dataclasses import dataclass

# Nested groups deeper than this are not entered: a guard against a tree that reaches itself
MAX_GROUP_DEPTH = 32


def _matching(sockets, identifier):
    return next((socket for socket in sockets if socket.identifier == identifier), None)


def _group_output(tree):
    """A group's active Group Output node (the one Blender evaluates), else its first one, else None."""
    outputs = [node for node in tree.nodes if node.type == "GROUP_OUTPUT"]
    return next((node for node in outputs if getattr(node, "is_active_output", False)), outputs[0] if outputs else None)


def _passed_input(node, output):
    """The input a muted node passes to `output` (its internal link), or None."""
    for link in getattr(node, "internal_links", ()):
        if link.to_socket.identifier == output.identifier and link.from_socket.is_output is False:
            return link.from_socket
    return None


def _link_of(socket):
    """The link into an input socket that Blender evaluates, or None."""
    if not socket.is_linked or not socket.links:
        return None
    link = socket.links[0]
    if getattr(link, "is_muted", False) or not getattr(link, "is_valid", True):
        return None
    return link


def resolve(socket, groups):
    """Where an input socket's value comes from: (the bpy output socket computing it, its groups) or (None, the
    bpy socket whose default value it takes, its groups)."""
    holder = socket
    for _ in range(10_000):
        link = _link_of(socket)
        if link is None:
            return None, holder, groups
        out = link.from_socket
        node = out.node
        if node.type == "REROUTE":
            socket = holder = node.inputs[0]
            continue
        if getattr(node, "mute", False):
            passed = _passed_input(node, out)
            if passed is None:
                return None, out, groups
            socket = holder = passed
            continue
        if node.type == "GROUP":
            tree = node.node_tree
            output = _group_output(tree) if tree is not None else None
            inner = _matching(output.inputs, out.identifier) if output is not None else None
            if inner is None or len(groups) >= MAX_GROUP_DEPTH:
                return None, out, groups
            groups = groups + (node,)
            socket = holder = inner
            continue
        if node.type == "GROUP_INPUT":
            if not groups:
                return None, out, groups
            outer = _matching(groups[-1].inputs, out.identifier)
            groups = groups[:-1]
            if outer is None:
                return None, out, groups
            socket = holder = outer
            continue
        return out, None, groups
    return None, holder, groups


class Sockets:
    """A node's inputs or outputs, as bpy's collection is indexed: by name, by position, iterated, `in`."""

    def __init__(self, sockets, groups):
        self._sockets = sockets
        self._groups = groups

    def __getitem__(self, key):
        return GraphSocket(self._sockets[key], self._groups)

    def __iter__(self):
        return (GraphSocket(socket, self._groups) for socket in self._sockets)

    def __len__(self):
        return len(self._sockets)

    def __contains__(self, name):
        return name in self._sockets


@dataclass(frozen=True)
class GraphLink:
    from_socket: object
    is_muted: bool = False
    is_valid: bool = True


class GraphSocket:
    """A bpy socket inside its groups.  An input is linked when a node computes its value; unlinked, its
    default value is the one Blender uses (a group node's input's, where it takes a group input)."""

    def __init__(self, socket, groups):
        self._socket = socket
        self._groups = groups
        self._resolved = None

    def __getattr__(self, name):
        return getattr(self._socket, name)

    def _source(self):
        if self._resolved is None:
            self._resolved = (None, self._socket, self._groups) if self._socket.is_output \
                else resolve(self._socket, self._groups)
        return self._resolved

    @property
    def node(self):
        return GraphNode(self._socket.node, self._groups)

    @property
    def is_linked(self):
        return not self._socket.is_output and self._source()[0] is not None

    @property
    def links(self):
        out, _, groups = self._source()
        return [] if out is None or self._socket.is_output else [GraphLink(GraphSocket(out, groups))]

    @property
    def default_value(self):
        """Unlinked: the value Blender uses; linked: the socket's own (a reader's stand-in for a value it
        cannot read)."""
        out, holder, _ = self._source()
        return getattr(self._socket if out is not None else holder, "default_value", 0.0)


class GraphNode:
    """A bpy node inside its groups (outermost first)."""

    def __init__(self, node, groups=()):
        self._node = node
        self._groups = tuple(groups)

    def __getattr__(self, name):
        return getattr(self._node, name)

    def __eq__(self, other):
        return isinstance(other, GraphNode) and self._node == other._node and self._groups == other._groups

    def __hash__(self):
        return hash((self._node.name, tuple(group.name for group in self._groups)))

    @property
    def name(self):
        return "/".join([group.name for group in self._groups] + [self._node.name])

    @property
    def inputs(self):
        return Sockets(self._node.inputs, self._groups)

    @property
    def outputs(self):
        return Sockets(self._node.outputs, self._groups)


def enabled_inputs(node, *names):
    """A node's enabled inputs by identifier or name (None where it has none), for nodes whose sockets changed
    names across versions."""
    found = []
    for name in names:
        socket = next((s for s in node.inputs if s.identifier == name and s.enabled), None) \
            or next((s for s in node.inputs if s.name == name and s.enabled), None)
        found.append(socket)
    return found


def output_node(tree, node_type="OUTPUT_MATERIAL"):
    """A node tree's output node that EEVEE renders (its active one for EEVEE or all engines; else its first of
    `node_type`) as a GraphNode, or None."""
    node = tree.get_output_node("EEVEE") if hasattr(tree, "get_output_node") else None
    node = node or next((n for n in tree.nodes if n.type == node_type), None)
    return None if node is None else GraphNode(node)
