"""Shader-node arithmetic: the tiers' formulas (lut_baker.closures.tier_formulas) emitted as
Math and Vector Math nodes.

- :class:`Builder` -- adds nodes to a tree, lays them out, links sockets or sets values; or
  takes a tree's nodes again in the order an earlier build added them (:class:`Mismatch` when
  they are not those).
- :class:`NodeValue` -- a node socket that takes part in ``+ - * /`` and ``** 2`` with other
  sockets and with constants (numbers, numpy arrays of 1 or 3 values): each operation adds one
  node, or none when the result is known (``x * 1``, ``x + 0``, ``x * 0``, two constants).
  Scalars are float sockets (Math nodes), colours vector sockets (Vector Math nodes); a scalar
  meeting a colour is linked into the vector input, where Blender reads it as grey.
- :class:`NodeAlgebra` -- the tier formulas' algebra on :class:`NodeValue`: ``maximum``,
  ``minimum``, ``floor``, ``lerp``, ``channel_mean``, ``channel_max``, ``row``.
- :class:`NodeShaders` -- the tier formulas' shader algebra on nodes: a closure, a Principled
  BSDF, their sum (Add Shader) and the areal mix by coverage (Mix Shader).
"""

from __future__ import annotations

import bpy
import numpy as np

from .group_parts import PART_KEY, part_holders

__all__ = ["Builder", "Mismatch", "Parts", "PART_NODES", "NodeValue", "NodeAlgebra",
           "NodeShaders", "socket", "value_of"]


def socket(sockets, identifier: str):
    """A node socket by identifier (display names differ between Blender versions)."""
    for item in sockets:
        if item.identifier == identifier:
            return item
    raise KeyError(identifier)


SAME_NODE = {"ShaderNodeBsdfGlossy": "ShaderNodeBsdfAnisotropic"}
"""Node types Blender adds as another (the Glossy BSDF is the Anisotropic one since 4.0)."""


class Mismatch(Exception):
    """A :class:`Builder` reusing a tree's nodes met one that is not what it would add."""


class Builder:
    """Adds nodes to a tree and links them; values may be sockets, :class:`NodeValue` or
    constants.

    Every setting, value and link set through the Python API updates the whole tree (a cost
    that grows with the tree's nodes at the time, and jumps above 32 nodes: ``parts``), so
    only what differs from a new node's own is set, and the new nodes are laid out in one
    call by :meth:`finish` (their places matter to no render).

    ``parts``: the tree is built as nested groups of at most :data:`PART_NODES` nodes
    (:class:`Parts`), which keeps that update from going parallel, several times dearer.

    ``reuse``: the tree holds what an earlier build of the same structure added, in the same
    order (a group rebuilt from a new fit of the same tier): its nodes are taken in turn
    instead of added (with ``parts``, the Group Input and Output from the tree and the rest
    from its parts, in order), and only the settings, values and links that differ are set,
    which costs a fraction of adding them (a live update's group swap on the main thread).
    Every input the build feeds is fed again, so a node taken for another of its type ends
    up as a new one would.  A node of another type or label, or nodes, links or part sockets
    left over (:meth:`finish`), raise :class:`Mismatch`: the caller then clears the tree and
    builds anew."""

    def __init__(self, tree, *, reuse: bool = False, parts: bool = False):
        self.tree = tree
        self.count = 0
        self._parts = Parts(tree, reuse=reuse) if parts else None
        self._pools: dict | None = None
        if reuse:
            self._pools = ({"outer": [n for n in tree.nodes if n.bl_idname in Parts.OUTER],
                            "inner": [n for part in self._parts.trees() for n in part.nodes
                                      if n.bl_idname not in Parts.OUTER]}
                           if self._parts is not None else {"all": list(tree.nodes)})
        self._taken: dict = {}
        # The trees' links by their input (a socket's own ``links`` walks every link).
        self._into = {link.to_socket.as_pointer(): link for part in self._trees()
                      for link in part.links} if reuse else {}
        self._links = 0

    def _trees(self) -> list:
        """The tree and, built as parts, its parts."""
        return [self.tree, *(self._parts.trees() if self._parts is not None else ())]

    def node(self, kind: str, label: str = "", **props):
        if self._pools is not None:
            return self._reused(kind, label, props)
        tree = self._parts.tree_for(kind) if self._parts is not None else self.tree
        node = tree.nodes.new(kind)
        self.count += 1
        if label:
            node.label = label
        _set(node, props)
        return node

    def _pool(self, kind: str) -> str:
        if self._parts is None:
            return "all"
        return "outer" if kind in Parts.OUTER else "inner"

    def _reused(self, kind: str, label: str, props: dict):
        """The next node of the tree (or of its parts), if it is of the type and label
        :meth:`node` would add (its settings set where they differ: an operation, a
        distribution, an image)."""
        assert self._pools is not None
        pool = self._pool(kind)
        taken = self._taken.get(pool, 0)
        if taken >= len(self._pools[pool]):
            raise Mismatch("more nodes than the tree holds")
        node = self._pools[pool][taken]
        self._taken[pool] = taken + 1
        self.count += 1
        if node.bl_idname != SAME_NODE.get(kind, kind) or node.label != label:
            raise Mismatch(f"{node.bl_idname} {node.label!r} where {kind} {label!r} goes")
        _set(node, props)
        return node

    def link(self, source, target) -> None:
        """Link output ``source`` into input ``target`` (reusing: unless it is linked so),
        through the parts' sockets when they are in two trees."""
        if self._parts is not None:
            source = self._parts.route(source, target.id_data, self._connect)
        self._connect(source, target)

    def _connect(self, source, target) -> None:
        """Link two sockets of one tree (reusing: unless they are linked so)."""
        if self._pools is None:
            target.id_data.links.new(source, target)
            return
        self._links += 1
        key = target.as_pointer()
        old = self._into.get(key)
        if old is not None and old.from_socket.as_pointer() == source.as_pointer():
            return
        self._into[key] = target.id_data.links.new(source, target)

    def finish(self) -> None:
        """Adding: lay the new nodes out (columns of ten, in the order they were added).
        Reusing: :class:`Mismatch` unless every node, link and part socket was taken."""
        trees = self._trees()
        if self._pools is None:
            for tree in trees:  # a part's nodes are all new
                _lay_out(tree.nodes, self.count if self._parts is None else len(tree.nodes))
            return
        left = any(self._taken.get(pool, 0) != len(nodes) for pool, nodes in
                   self._pools.items())
        if left or self._links != sum(len(tree.links) for tree in trees) or (
                self._parts is not None and not self._parts.all_sockets_taken()):
            raise Mismatch("the tree holds nodes or links this build does not add")

    def feed(self, target, value):
        """Link a socket into ``target`` or set its default value (only if it differs;
        reusing, a link where a value goes removed)."""
        value = value_of(value)
        if isinstance(value, bpy.types.NodeSocket):
            self.link(value, target)
            return
        new: float | tuple[float, ...]
        if target.type in ("VECTOR", "RGBA") and np.size(value) == 1:
            n = len(target.default_value)
            new = (float(np.ravel(value)[0]),) * n
        elif target.type == "RGBA" and len(value) == 3:
            new = (*map(float, value), 1.0)
        elif np.ndim(value) == 0 or np.size(value) == 1:
            new = float(np.ravel(value)[0])
        else:
            new = tuple(map(float, value))
        if self._pools is not None:
            link = self._into.pop(target.as_pointer(), None)
            if link is not None:
                target.id_data.links.remove(link)
        old = target.default_value
        if (tuple(old) if isinstance(new, tuple) else old) != new:
            target.default_value = new

    def math(self, operation: str, a, b=0.0, label: str = ""):
        node = self.node("ShaderNodeMath", label, operation=operation)
        self.feed(node.inputs[0], a)
        self.feed(node.inputs[1], b)
        return node.outputs[0]

    def vector(self, operation: str, a, b=(0.0, 0.0, 0.0), label: str = ""):
        node = self.node("ShaderNodeVectorMath", label, operation=operation)
        self.feed(socket(node.inputs, "Vector"), a)
        self.feed(socket(node.inputs, "Vector_001"), b)
        return node.outputs["Value" if operation in ("DOT_PRODUCT", "LENGTH") else "Vector"]

    def mix_vector(self, factor, a, b, label: str = ""):
        """``a + factor (b - a)``, factor unclamped."""
        node = self.node("ShaderNodeMix", label, data_type="VECTOR", clamp_factor=False)
        self.feed(socket(node.inputs, "Factor_Float"), factor)
        self.feed(socket(node.inputs, "A_Vector"), a)
        self.feed(socket(node.inputs, "B_Vector"), b)
        return socket(node.outputs, "Result_Vector")


PART_NODES = 30
"""Nodes a part holds at most, its Group Input and Output included (:class:`Parts`)."""
_INTERFACE_TYPES = {"VALUE": "NodeSocketFloat", "VECTOR": "NodeSocketVector",
                    "RGBA": "NodeSocketColor", "SHADER": "NodeSocketShader"}


class Parts:
    """A group built as parts: node groups of at most :data:`PART_NODES` nodes nested in it,
    filled in turn, a value crossing from one tree to another through the parts' sockets
    (each crossing made once).  Every change made through Python runs Blender's node-tree
    update over the whole tree, and above 32 nodes that update works in parallel, several
    times dearer on a free core (docs/addon.md, "Not done"); parts keep every tree under it.
    A part is named after its group with a leading '.', so that Blender's Add > Group menu
    leaves it out.  The group's own Group Input and Output stay in it, beside the parts'
    group nodes.  ``reuse``: the parts the group holds are taken again, their sockets found
    by name."""

    OUTER = ("NodeGroupInput", "NodeGroupOutput")

    def __init__(self, tree, *, reuse: bool = False):
        self.tree = tree
        self._parts: list = []  # (part tree, its group node, its Group Input, Group Output)
        self._of: dict = {}  # part tree pointer -> index
        self._routes: dict = {}  # (socket pointer, tree pointer) -> the socket there
        self._reuse = reuse
        self._used: set = set()  # the sockets' (part pointer, identifier) taken, reusing
        if reuse:
            for holder in part_holders(tree):
                self._remember(holder.node_tree, holder)

    def trees(self) -> list:
        return [part[0] for part in self._parts]

    def tree_for(self, kind: str):
        """The tree a new node of ``kind`` goes into: the group for its Group Input and
        Output, else the last part (a new one when it is full)."""
        if kind in self.OUTER:
            return self.tree
        if not self._parts or len(self._parts[-1][0].nodes) >= PART_NODES:
            # A leading '.': Blender's Add > Group menu leaves the parts out.
            part = bpy.data.node_groups.new(f".{self.tree.name} part {len(self._parts) + 1}",
                                            "ShaderNodeTree")
            part[PART_KEY] = True
            part.nodes.new("NodeGroupInput")
            part.nodes.new("NodeGroupOutput")
            holder = self.tree.nodes.new("ShaderNodeGroup")
            holder.node_tree = part
            self._remember(part, holder)
        return self._parts[-1][0]

    def _remember(self, part, holder) -> None:
        io = {node.bl_idname: node for node in part.nodes if node.bl_idname in self.OUTER}
        self._of[part.as_pointer()] = len(self._parts)
        self._parts.append((part, holder, io.get("NodeGroupInput"), io.get("NodeGroupOutput")))

    def route(self, source, tree, connect):
        """``source`` (an output socket of any tree of the group) as a socket of ``tree``:
        itself, or through the sockets of the part it leaves and of the part it enters,
        linked by ``connect(source, target)``."""
        if source.id_data == tree:
            return source
        key = (source.as_pointer(), tree.as_pointer())
        if key not in self._routes:
            outer = self._left(source, connect)
            self._routes[key] = outer if tree == self.tree else self._entered(outer, tree,
                                                                             connect)
        return self._routes[key]

    def _left(self, source, connect):
        """``source`` as a socket of the group: its part's group node's output for it."""
        if source.id_data == self.tree:
            return source
        key = (source.as_pointer(), self.tree.as_pointer())
        if key not in self._routes:
            index = self._of[source.id_data.as_pointer()]
            part, holder, _, outputs = self._parts[index]
            item = self._item(part, f"part {index + 1} {source.node.name} {source.identifier}",
                              source.type, "OUTPUT")
            connect(source, socket(outputs.inputs, item.identifier))
            self._routes[key] = socket(holder.outputs, item.identifier)
        return self._routes[key]

    def _entered(self, outer, tree, connect):
        """The group's socket ``outer`` as a socket inside the part ``tree``."""
        part, holder, inputs, _ = self._parts[self._of[tree.as_pointer()]]
        item = self._item(part, outer.name, outer.type, "INPUT")
        hidden = self._hidden(outer)
        if item.hide_value != hidden:
            item.hide_value = hidden
        connect(outer, socket(holder.inputs, item.identifier))
        return socket(inputs.outputs, item.identifier)

    def _hidden(self, outer) -> bool:
        """Whether ``outer`` is one of the group's inputs whose value is hidden: unlinked, the
        engines then take what it feeds as unlinked too (a BSDF's Normal: the shading
        normal), so the part's socket that carries it on is hidden as well."""
        if outer.node.bl_idname != "NodeGroupInput":
            return False
        item = next((item for item in self.tree.interface.items_tree
                     if item.item_type == "SOCKET" and item.in_out == "INPUT"
                     and item.identifier == outer.identifier), None)
        return bool(item is not None and item.hide_value)

    def _item(self, part, name: str, carried: str, in_out: str):
        """``part``'s interface socket ``name`` for a socket of type ``carried``, taken again
        when reusing and there, else added.  A value leaving a part is named after its part,
        node and socket; one entering a part after the group's socket that carries it (the
        group's input, or the part's output it left by)."""
        kind = _INTERFACE_TYPES[carried]
        if self._reuse:
            for item in part.interface.items_tree:
                if (item.item_type == "SOCKET" and item.name == name and item.in_out == in_out
                        and item.socket_type == kind):
                    self._used.add((part.as_pointer(), item.identifier))
                    return item
        item = part.interface.new_socket(name, in_out=in_out, socket_type=kind)
        self._used.add((part.as_pointer(), item.identifier))
        return item

    def all_sockets_taken(self) -> bool:
        """Reusing: whether every socket of every part was taken again."""
        return all((part.as_pointer(), item.identifier) in self._used
                   for part in self.trees() for item in part.interface.items_tree
                   if item.item_type == "SOCKET")


def _set(node, props: dict) -> None:
    """Set the settings ``props`` of ``node`` that differ (each set updates the tree)."""
    for name, value in props.items():
        if getattr(node, name) != value:
            setattr(node, name, value)


def _lay_out(nodes, count: int) -> None:
    """Place the last ``count`` of ``nodes`` (the tree's collection) in columns of ten, in one
    call (``foreach_set`` updates nothing; a node's ``location`` set alone updates the
    tree)."""
    places = np.empty(2 * len(nodes), np.float32)
    nodes.foreach_get("location", places)
    index = np.arange(count)
    places[len(places) - 2 * count:] = np.column_stack(
        [200 * (index // 10) - 400, -160 * (index % 10)]).ravel()
    nodes.foreach_set("location", places)


def _constant(value):
    """A constant as a float (one value) or an RGB tuple (three)."""
    array = np.asarray(value, float).ravel()
    if array.size == 1:
        return float(array[0])
    if array.size == 3:
        return tuple(float(v) for v in array)
    raise ValueError(f"a node constant is 1 or 3 values, got {array.size}")


def value_of(value):
    """What :meth:`Builder.feed` takes for ``value``: a :class:`NodeValue`'s socket, else the
    value."""
    return value.socket if isinstance(value, NodeValue) else value


def _is_colour(value) -> bool:
    if isinstance(value, NodeValue):
        return value.colour
    return np.size(value) == 3


def _equals(value, number: float) -> bool:
    """Whether a constant is ``number`` in every channel (never for a socket)."""
    return not isinstance(value, NodeValue) and bool(np.all(np.asarray(value) == number))


class NodeValue:
    """A node output socket in the tier formulas' arithmetic (see the module's docstring)."""

    __array_ufunc__ = None  # numpy's operators hand an array * NodeValue to __rmul__

    def __init__(self, build: Builder, output, colour: bool):
        self.build = build
        self.socket = output
        self.colour = colour

    # --- one node per operation, or none when the result is known ---------------------------
    def _neutral(self, other, number: float) -> bool:
        """Whether ``self (op) other`` is ``self`` itself: ``other`` is the constant
        ``number`` and does not turn a scalar into a colour."""
        return _equals(other, number) and (self.colour or not _is_colour(other))

    def _op(self, operation: str, a, b, label: str = ""):
        build = self.build
        if _is_colour(a) or _is_colour(b):
            return NodeValue(build, build.vector(operation, _operand(a), _operand(b), label),
                             True)
        return NodeValue(build, build.math(operation, _operand(a), _operand(b), label), False)

    def __add__(self, other):
        return self if self._neutral(other, 0.0) else self._op("ADD", self, other)

    def __radd__(self, other):
        return self.__add__(other)

    def __sub__(self, other):
        return self if self._neutral(other, 0.0) else self._op("SUBTRACT", self, other)

    def __rsub__(self, other):
        return self._op("SUBTRACT", other, self)

    def __mul__(self, other):
        if _equals(other, 0.0):
            return np.zeros(3) if self.colour or _is_colour(other) else 0.0
        if self._neutral(other, 1.0):
            return self
        return self._op("MULTIPLY", self, other)

    def __rmul__(self, other):
        return self.__mul__(other)

    def __truediv__(self, other):
        if self._neutral(other, 1.0):
            return self
        return self._op("DIVIDE", self, other)

    def __rtruediv__(self, other):
        return self._op("DIVIDE", other, self)

    def __pow__(self, exponent):
        if exponent != 2:
            raise ValueError("node values are only squared")
        return self._op("MULTIPLY", self, self)

    def __neg__(self):
        return self._op("MULTIPLY", self, -1.0)


def _operand(value):
    return value.socket if isinstance(value, NodeValue) else _constant(value)


class NodeAlgebra:
    """The algebra of :mod:`lut_baker.closures.tier_formulas` on :class:`NodeValue`: each
    function adds the nodes that compute it; ``rows`` maps a view-angle image row's name to
    its (colour) :class:`NodeValue`."""

    def __init__(self, build: Builder, rows: dict | None = None):
        self.build = build
        self._rows = rows or {}

    def _either(self, operation: str, a, b, fold):
        if not isinstance(a, NodeValue) and not isinstance(b, NodeValue):
            return fold(np.asarray(a, float), np.asarray(b, float))
        node = a if isinstance(a, NodeValue) else b
        return node._op(operation, a, b)

    def maximum(self, a, b):
        return self._either("MAXIMUM", a, b, np.maximum)

    def minimum(self, a, b):
        return self._either("MINIMUM", a, b, np.minimum)

    def floor(self, a):
        if not isinstance(a, NodeValue):
            return np.floor(np.asarray(a, float))
        return a._op("FLOOR", a, 0.0)

    def lerp(self, t, a, b, label: str = ""):
        """``a + t (b - a)`` of two colours (a Mix node, factor unclamped)."""
        return NodeValue(self.build, self.build.mix_vector(value_of(t), value_of(a),
                                                           value_of(b), label=label), True)

    def channel_mean(self, colour):
        if not isinstance(colour, NodeValue):
            return float(np.mean(np.asarray(colour, float) * np.ones(3)))
        if not colour.colour:
            return colour
        return NodeValue(self.build, self.build.vector("DOT_PRODUCT", colour.socket,
                                                       (1 / 3, 1 / 3, 1 / 3),
                                                       label="channel mean"), False)

    def channel_max(self, colour):
        if not isinstance(colour, NodeValue):
            return float(np.max(np.asarray(colour, float) * np.ones(3)))
        if not colour.colour:
            return colour
        build = self.build
        separate = build.node("ShaderNodeSeparateXYZ", "channels")
        build.feed(separate.inputs[0], colour.socket)
        strongest = build.math("MAXIMUM", separate.outputs[0],
                               build.math("MAXIMUM", separate.outputs[1], separate.outputs[2]),
                               label="strongest channel")
        return NodeValue(build, strongest, False)

    def row(self, name: str):
        return self._rows[name]


class NodeShaders(NodeAlgebra):
    """The shader algebra of :mod:`lut_baker.closures.tier_formulas` on nodes: a closure is a
    Glossy (its lobe of ``lobes``), Diffuse or Subsurface BSDF node (``subsurface``: its
    ``(method, radius, scale, ior)``), through a Mix Shader when it has a weight; its normal
    ``normals[surface]``; a Principled BSDF (GGX) takes the sockets of
    :func:`~lut_baker.closures.tier_formulas.principled_sockets`, the subsurface's and the
    normals (Coat Normal the film's).  A colour of 0 (Gloss 0) is a closure Cycles does not
    allocate (``bsdf_alloc``'s cutoff)."""

    def __init__(self, build: Builder, rows: dict, *, lobes: dict, normals: dict,
                 subsurface: tuple):
        super().__init__(build, rows)
        self.lobes, self.normals, self.subsurface = lobes, normals, subsurface

    def closure(self, closure):
        build = self.build
        method, radius, scale, ior = self.subsurface
        if closure.kind == "glossy":
            lobe = self.lobes[closure.name]
            node = build.node("ShaderNodeBsdfGlossy", closure.name.replace("_", " "),
                              distribution=lobe.distribution)
            build.feed(node.inputs["Roughness"], lobe.roughness)
        elif closure.kind == "diffuse":
            node = build.node("ShaderNodeBsdfDiffuse", closure.name)
        else:
            node = build.node("ShaderNodeSubsurfaceScattering", closure.name, falloff=method)
            build.feed(socket(node.inputs, "Radius"), radius)
            build.feed(socket(node.inputs, "Scale"), scale)
            build.feed(socket(node.inputs, "IOR"), ior)
        build.feed(socket(node.inputs, "Color"), closure.colour)
        build.feed(socket(node.inputs, "Normal"), self.normals[closure.surface])
        if closure.weight is None:
            return node.outputs[0]
        weighted = build.node("ShaderNodeMixShader", f"{closure.name} (weight)")
        build.feed(socket(weighted.inputs, "Fac"), closure.weight)
        build.link(node.outputs[0], socket(weighted.inputs, "Shader_001"))
        return weighted.outputs[0]

    def principled(self, sockets: dict):
        build = self.build
        method, radius, scale, ior = self.subsurface
        bsdf = build.node("ShaderNodeBsdfPrincipled", "Made-up skin", distribution="GGX",
                          subsurface_method=method)
        values = {**sockets, "Subsurface Radius": radius, "Subsurface Scale": scale,
                  "Subsurface IOR": ior, "Normal": self.normals["skin"],
                  "Coat Normal": self.normals["film"]}
        for name, value in values.items():
            # By identifier: a socket the method leaves unavailable is not found by name in 5.0.
            build.feed(socket(bsdf.inputs, name), value)
        return bsdf.outputs[0]

    def add(self, *shaders):
        total = shaders[0]
        for shader in shaders[1:]:
            node = self.build.node("ShaderNodeAddShader")
            self.build.link(total, node.inputs[0])
            self.build.link(shader, node.inputs[1])
            total = node.outputs[0]
        return total

    def mix(self, coverage, bare, covered):
        mix = self.build.node("ShaderNodeMixShader", "coverage (areal mix)")
        self.build.feed(socket(mix.inputs, "Fac"), coverage)
        self.build.link(bare, socket(mix.inputs, "Shader"))
        self.build.link(covered, socket(mix.inputs, "Shader_001"))
        return mix.outputs[0]
