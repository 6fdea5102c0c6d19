"""What an input of the artist's shader takes over the material's surface: the nodes that feed
it evaluated with numpy at points sampled on the surface.

The made-up skin needs a few numbers of the artist's shader: the mean of what feeds a Base
Color (an albedo texture, often through a tint or a mix), of a Mix Shader's factor, of a
roughness.  :func:`values` evaluates the nodes feeding an input at the sample points of a
:class:`Samples` (their UVs and images read by :mod:`.skin_sampling`), as Blender's shader
nodes compute them, for the nodes a skin's colour is commonly built from: Image Texture (its
UV map, a UV Map, Texture Coordinate's UV or a Mapping node before it), RGB and Value, Mix (any
data type; the usual blend modes), the older MixRGB, Math, Vector Math, Invert, Gamma,
Hue/Saturation/Value, Brightness/Contrast, Separate and Combine Color (RGB) and XYZ, Clamp, Map
Range (linear), Color Ramp (linear and constant), RGB Curves, Color Attribute and Attribute (of
the geometry: vertex colours and other mesh attributes, :mod:`.mesh_attributes`), Fresnel and
Layer Weight (their averages under uniform light, over the directions the surface is seen
from: a Mix Shader's factor for a sheen or a rim), reroutes and node groups.  A node it
cannot evaluate (a procedural texture, an object's attribute) gives a neutral 0.5 and a note
saying so.

Values are arrays with a leading axis of the sample count (or 1 for a constant) and a trailing
axis of 3 (colours and vectors) or 1 (floats).

- :class:`Samples` -- what evaluation needs of the surface: UVs by map, image lookups, mesh
  attributes.
- :func:`values` -- an input's values at the samples (:class:`.artist_shader.Source`).
- :func:`mean` -- their mean (RGB or a float).
- :func:`assumed` -- whether a note says a value was assumed, not read.

What the colour and math nodes compute is written in :mod:`.node_maths`.
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np

from . import node_maths
from .artist_shader import Source, source
from .core import film_slab

__all__ = ["Samples", "values", "mean", "assumed", "NEUTRAL", "ASSUMED"]

NEUTRAL = 0.5
"""What a node that cannot be evaluated gives (a procedural texture's mean, about)."""
ASSUMED = (": taken as ", "read at UV (0, 0)")
"""What the notes of a value assumed, not read, say (a node not evaluated, an attribute or a
UV map missing): :func:`assumed`."""


def assumed(note: str) -> bool:
    """Whether a note of the evaluation says a value was assumed, not read from the shader."""
    return any(words in note for words in ASSUMED)


class Samples(Protocol):
    """Points on the material's surface (equal-area samples): their UVs and image values."""

    count: int

    def uv(self, name: str, reader: str = "") -> np.ndarray:
        """``(count, 2)`` UVs of the map ``name`` (``""``: the active render map) read by the
        node named ``reader`` (for the notes)."""

    def image(self, image, uv: np.ndarray, extension: str) -> np.ndarray:
        """``(count, 4)`` linear RGBA of ``image`` at ``uv``, as an Image Texture reads it."""

    def attribute(self, name: str, reader: str = "") -> tuple[np.ndarray, bool]:
        """``((count, 4) values, colour)``: the mesh attribute ``name`` ("": the colour
        attribute to render) as an Attribute node reads it, and whether it holds colours."""


def _colour(value) -> np.ndarray:
    """A value as colours ``(n, 3)``: an array of values per sample as it is (a float per
    sample grey), a constant (a number, a tuple) as one row."""
    array = np.asarray(value, float)
    if array.ndim < 2:
        array = array.reshape(1, -1)
    if array.shape[1] == 1:
        return np.repeat(array, 3, axis=1)
    return array[:, :3]


def _float(value) -> np.ndarray:
    """A value as floats ``(n, 1)``: a colour's luminance (Blender's conversion), a vector's
    mean, a constant as one row."""
    array = np.asarray(value, float)
    if array.ndim < 2:
        array = array.reshape(1, -1)
    if array.shape[1] >= 3:
        return (array[:, :3] @ np.array([0.2126, 0.7152, 0.0722]))[:, None]
    return array[:, :1]


def _as(kind: str, value) -> np.ndarray:
    return _float(value) if kind == "VALUE" else _colour(value)


def _fresnel_average(ior: np.ndarray) -> np.ndarray:
    """``(n, 1)``: a Fresnel factor of index ``ior`` ((n, 1)) averaged over the directions a
    surface is seen from under uniform light (cosine-weighted,
    :func:`lut_baker.model.film_slab.interface_albedo`): what it weighs a Mix Shader's two
    shaders by in the colour under uniform light."""
    values, inverse = np.unique(np.maximum(np.asarray(ior, float), 1.0), return_inverse=True)
    averages = np.array([film_slab.interface_albedo(float(value)) for value in values])
    return averages[inverse].reshape(np.shape(ior))


CURVE_NODES = 1025
"""Values a curve of an RGB Curves node is tabulated at (over the values it is given, 0 to 1
at least; read between them linearly: within about 1e-5 of the curve)."""


def _curve(mapping, curve, values: np.ndarray) -> np.ndarray:
    """``curve`` (of the CurveMapping ``mapping``, as Blender evaluates it) at ``values``:
    tabulated at :data:`CURVE_NODES` values from the least to the largest (Blender's own
    evaluation, a value at a time) and read between them."""
    values = np.asarray(values, float)
    low, high = min(0.0, float(values.min())), max(1.0, float(values.max()))
    nodes = np.linspace(low, high, CURVE_NODES)
    table = np.array([mapping.evaluate(curve, float(x)) for x in nodes])
    return np.interp(values, nodes, table)


class _Evaluator:
    def __init__(self, samples: Samples, notes: list):
        self.samples, self.notes = samples, notes
        self.memo: dict = {}
        self.readers: list[str] = []  # the image textures whose coordinates are evaluated

    def say(self, sentence: str) -> None:
        """Add ``sentence`` to the notes, once."""
        if sentence not in self.notes:
            self.notes.append(sentence)

    def note(self, node, what: str) -> np.ndarray:
        self.say(f"{node.name!r} ({what}) is not evaluated: taken as {NEUTRAL:g}")
        return np.full((1, 3), NEUTRAL)

    def input(self, node, key, groups, kind: str = "RGBA") -> np.ndarray:
        """An input of ``node`` (by identifier or name) as ``kind``."""
        socket = next((s for s in node.inputs if s.identifier == key), None)
        if socket is None:
            socket = node.inputs[key]
        return self.source(source(socket, groups), kind)

    def source(self, where: Source, kind: str) -> np.ndarray:
        if not where.linked:
            value = where.value if where.value is not None else 0.0
            return _as(kind, value)
        return _as(kind, self.output(where.socket, where.groups))

    def output(self, socket, groups) -> np.ndarray:
        key = (socket.as_pointer(), tuple(g.as_pointer() for g in groups))
        if key not in self.memo:
            self.memo[key] = self._output(socket, groups)
        return self.memo[key]

    def _output(self, socket, groups) -> np.ndarray:
        node = socket.node
        kind = node.type
        handler = getattr(self, f"node_{kind.lower()}", None)
        if handler is None:
            return self.note(node, node.bl_label or kind)
        return handler(node, socket, groups)

    # -- inputs and constants -------------------------------------------------------------
    def node_rgb(self, node, socket, groups):
        return _colour(tuple(socket.default_value))

    def node_value(self, node, socket, groups):
        return _float(socket.default_value)

    def node_uvmap(self, node, socket, groups):
        return self.uv(node, node.uv_map)

    def node_tex_coord(self, node, socket, groups):
        if socket.name != "UV":
            return self.note(node, f"Texture Coordinate {socket.name}")
        return self.uv(node, "")

    def uv(self, node, name: str) -> np.ndarray:
        uv = self.samples.uv(name, self.readers[-1] if self.readers else node.name)
        return np.concatenate([uv, np.zeros((len(uv), 1))], axis=1)

    # -- attributes -----------------------------------------------------------------------
    def node_vertex_color(self, node, socket, groups):
        values, _ = self.samples.attribute(node.layer_name, node.name)
        return values[:, 3:4] if socket.identifier == "Alpha" else values[:, :3]

    def node_attribute(self, node, socket, groups):
        if node.attribute_type != "GEOMETRY":
            return self.note(node, f"Attribute of the {node.attribute_type.lower()}")
        values, colour = self.samples.attribute(node.attribute_name, node.name)
        if socket.identifier == "Alpha":
            return values[:, 3:4]
        if socket.identifier == "Fac":  # a colour's or a vector's mean, as Cycles gives it
            # (its name is "Factor" from Blender 5.0 on)
            return values[:, :3].mean(axis=1, keepdims=True)
        return values[:, :3]

    def node_group(self, node, socket, groups):
        tree = node.node_tree
        outputs = [n for n in tree.nodes if n.type == "GROUP_OUTPUT"] if tree else []
        inner = next((n for n in outputs if n.is_active_output), outputs[0] if outputs else None)
        target = (next((s for s in inner.inputs if s.identifier == socket.identifier), None)
                  if inner is not None else None)
        if target is None:
            return np.zeros((1, 3))
        return self.source(source(target, groups + (node,)), socket.type)

    # -- textures -------------------------------------------------------------------------
    def node_tex_image(self, node, socket, groups):
        if node.image is None:
            return np.zeros((1, 3)) if socket.name == "Color" else np.zeros((1, 1))
        vector = node.inputs["Vector"]
        self.readers.append(node.name)
        try:
            uv = (self.input(node, "Vector", groups, "VECTOR")[:, :2] if vector.is_linked
                  else self.uv(node, "")[:, :2])
        finally:
            self.readers.pop()
        if uv.shape[0] != self.samples.count:
            uv = np.broadcast_to(uv, (self.samples.count, 2))
        rgba = self.samples.image(node.image, uv, node.extension)
        if socket.identifier == "Alpha" and node.image.alpha_mode != "NONE":
            # the reduced images keep colour only
            self.say(f"{node.name!r}'s Alpha (of image {node.image.name!r}) is not read: "
                     f"taken as 1")
        return rgba[:, 3:4] if socket.identifier == "Alpha" else rgba[:, :3]

    def node_mapping(self, node, socket, groups):
        vector = self.input(node, "Vector", groups, "VECTOR")
        location = self.input(node, "Location", groups, "VECTOR") \
            if "Location" in node.inputs else np.zeros((1, 3))
        rotation = self.input(node, "Rotation", groups, "VECTOR")
        scale = self.input(node, "Scale", groups, "VECTOR")
        if node.vector_type not in {"POINT", "TEXTURE"} or rotation.shape[0] != 1:
            return self.note(node, f"Mapping {node.vector_type}")
        x, y, z = rotation[0]
        cx, sx, cy, sy, cz, sz = (math.cos(x), math.sin(x), math.cos(y), math.sin(y),
                                  math.cos(z), math.sin(z))
        matrix = (np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
                  @ np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
                  @ np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]]))
        if node.vector_type == "POINT":
            return (vector * scale) @ matrix.T + location
        safe = np.where(np.abs(scale) > 1e-12, scale, 1.0)
        return ((vector - location) @ matrix) / safe

    # -- colour operations ----------------------------------------------------------------
    def node_mix(self, node, socket, groups):
        data = node.data_type
        if data == "FLOAT":
            t = self.input(node, "Factor_Float", groups, "VALUE")
            a = self.input(node, "A_Float", groups, "VALUE")
            b = self.input(node, "B_Float", groups, "VALUE")
        elif data == "VECTOR":
            uniform = getattr(node, "factor_mode", "UNIFORM") == "UNIFORM"
            t = self.input(node, "Factor_Float" if uniform else "Factor_Vector", groups,
                           "VALUE" if uniform else "VECTOR")
            a = self.input(node, "A_Vector", groups, "VECTOR")
            b = self.input(node, "B_Vector", groups, "VECTOR")
        elif data == "RGBA":
            t = self.input(node, "Factor_Float", groups, "VALUE")
            a = self.input(node, "A_Color", groups)
            b = self.input(node, "B_Color", groups)
        else:
            return self.note(node, f"Mix {data}")
        if node.clamp_factor:
            t = np.clip(t, 0.0, 1.0)
        if data != "RGBA":
            return a + t * (b - a)
        result = node_maths.blend(node.blend_type, t, a, b)
        if result is None:
            return self.note(node, f"Mix {node.blend_type}")
        return np.clip(result, 0.0, 1.0) if node.clamp_result else result

    def node_mix_rgb(self, node, socket, groups):
        t = np.clip(self.input(node, "Fac", groups, "VALUE"), 0.0, 1.0)
        result = node_maths.blend(node.blend_type, t, self.input(node, "Color1", groups),
                        self.input(node, "Color2", groups))
        if result is None:
            return self.note(node, f"MixRGB {node.blend_type}")
        return np.clip(result, 0.0, 1.0) if node.use_clamp else result

    def node_invert(self, node, socket, groups):
        t = self.input(node, "Fac", groups, "VALUE")
        colour = self.input(node, "Color", groups)
        return colour + t * (1.0 - 2.0 * colour)

    def node_gamma(self, node, socket, groups):
        colour = self.input(node, "Color", groups)
        gamma = self.input(node, "Gamma", groups, "VALUE")
        return np.where(colour > 0.0, np.abs(colour) ** gamma, colour)

    def node_brightcontrast(self, node, socket, groups):
        colour = self.input(node, "Color", groups)
        bright = self.input(node, "Bright", groups, "VALUE")
        contrast = self.input(node, "Contrast", groups, "VALUE")
        return np.maximum((1.0 + contrast) * colour + bright - 0.5 * contrast, 0.0)

    def node_hue_sat(self, node, socket, groups):
        colour = self.input(node, "Color", groups)
        t = self.input(node, "Fac", groups, "VALUE")
        hue = self.input(node, "Hue", groups, "VALUE")
        saturation = self.input(node, "Saturation", groups, "VALUE")
        value = self.input(node, "Value", groups, "VALUE")
        h, s, v = node_maths.rgb_to_hsv(colour)
        h = np.mod(h + hue[:, 0] - 0.5, 1.0)
        s = np.clip(s * saturation[:, 0], 0.0, 1.0)
        v = v * value[:, 0]
        shifted = node_maths.hsv_to_rgb(h, s, v)
        return colour + t * (shifted - colour)

    def node_curve_rgb(self, node, socket, groups):
        colour = self.input(node, "Color", groups)
        t = self.input(node, "Fac", groups, "VALUE")
        mapping = node.mapping
        # the C curve (one table over every channel's values), then each channel's own
        combined = _curve(mapping, mapping.curves[3], colour)
        curved = np.column_stack([_curve(mapping, mapping.curves[c], combined[:, c])
                                  for c in range(3)])
        return colour + t * (curved - colour)

    # -- view-dependent factors, averaged under uniform light -------------------------------
    def node_fresnel(self, node, socket, groups):
        return _fresnel_average(self.input(node, "IOR", groups, "VALUE"))

    def node_layer_weight(self, node, socket, groups):
        blend = np.clip(self.input(node, "Blend", groups, "VALUE"), 0.0, 1.0 - 1e-5)
        if socket.identifier == "Fresnel":  # Cycles: eta 1 / (1 - blend)
            return _fresnel_average(1.0 / np.maximum(1.0 - blend, 1e-5))
        # Facing: 1 - |cos|^b (b = 2 blend below 0.5, 0.5 / (1 - blend) above), whose average
        # over 2 cos dcos is 1 - 2 / (b + 2)
        power = np.where(blend < 0.5, 2.0 * blend, 0.5 / (1.0 - blend))
        return 1.0 - 2.0 / (power + 2.0)

    def node_valtorgb(self, node, socket, groups):
        t = np.clip(self.input(node, "Fac", groups, "VALUE")[:, 0], 0.0, 1.0)
        ramp = node.color_ramp
        positions = np.array([e.position for e in ramp.elements])
        colours = np.array([tuple(e.color) for e in ramp.elements])
        if ramp.interpolation == "CONSTANT":
            index = np.clip(np.searchsorted(positions, t, side="right") - 1, 0,
                            len(positions) - 1)
            out = colours[index]
        else:
            if ramp.interpolation != "LINEAR":
                self.notes.append(f"{node.name!r}: its {ramp.interpolation.lower()} "
                                  f"interpolation is read as linear")
            out = np.stack([np.interp(t, positions, colours[:, c]) for c in range(4)], axis=1)
        return out[:, 3:4] if socket.name == "Alpha" else out[:, :3]

    # -- arithmetic -----------------------------------------------------------------------
    def node_math(self, node, socket, groups):
        a = self.input(node, node.inputs[0].identifier, groups, "VALUE")
        b = self.input(node, node.inputs[1].identifier, groups, "VALUE")
        c = self.input(node, node.inputs[2].identifier, groups, "VALUE")
        result = node_maths.math_node(node.operation, a, b, c)
        if result is None:
            return self.note(node, f"Math {node.operation}")
        return np.clip(result, 0.0, 1.0) if node.use_clamp else result

    def node_vect_math(self, node, socket, groups):
        a = self.input(node, node.inputs[0].identifier, groups, "VECTOR")
        b = self.input(node, node.inputs[1].identifier, groups, "VECTOR")
        operation = node.operation
        if operation == "SCALE":
            scale = self.input(node, "Scale", groups, "VALUE")
            return a * scale
        if operation in {"DOT_PRODUCT", "LENGTH"}:
            value = (np.sum(a * b, axis=1, keepdims=True) if operation == "DOT_PRODUCT"
                     else np.linalg.norm(a, axis=1, keepdims=True))
            return value
        result = node_maths.math_node(operation, a, b, 0.0)
        return self.note(node, f"Vector Math {operation}") if result is None else result

    def node_clamp(self, node, socket, groups):
        value = self.input(node, "Value", groups, "VALUE")
        low = self.input(node, "Min", groups, "VALUE")
        high = self.input(node, "Max", groups, "VALUE")
        if node.clamp_type == "RANGE":
            low, high = np.minimum(low, high), np.maximum(low, high)
        return np.minimum(np.maximum(value, low), high)

    def node_map_range(self, node, socket, groups):
        if node.data_type != "FLOAT" or node.interpolation_type != "LINEAR":
            return self.note(node, f"Map Range {node.data_type} {node.interpolation_type}")
        value = self.input(node, "Value", groups, "VALUE")
        from_min, from_max, to_min, to_max = (self.input(node, key, groups, "VALUE")
                                              for key in ("From Min", "From Max", "To Min",
                                                          "To Max"))
        span = np.where(np.abs(from_max - from_min) > 1e-12, from_max - from_min, 1.0)
        t = (value - from_min) / span
        if node.clamp:
            t = np.clip(t, 0.0, 1.0)
        return to_min + t * (to_max - to_min)

    # -- channels -------------------------------------------------------------------------
    def node_separate_color(self, node, socket, groups):
        if getattr(node, "mode", "RGB") != "RGB":
            return self.note(node, f"Separate Color {node.mode}")
        colour = self.input(node, "Color", groups)
        return colour[:, "RGB".index(socket.name[0]):][:, :1]

    node_seprgb = node_separate_color

    def node_combine_color(self, node, socket, groups):
        if getattr(node, "mode", "RGB") != "RGB":
            return self.note(node, f"Combine Color {node.mode}")
        channels = [self.input(node, s.identifier, groups, "VALUE") for s in node.inputs[:3]]
        return np.concatenate(np.broadcast_arrays(*channels), axis=1)

    node_combrgb = node_combine_color

    def node_sepxyz(self, node, socket, groups):
        vector = self.input(node, "Vector", groups, "VECTOR")
        return vector[:, "XYZ".index(socket.name):][:, :1]

    def node_combxyz(self, node, socket, groups):
        channels = [self.input(node, key, groups, "VALUE") for key in ("X", "Y", "Z")]
        return np.concatenate(np.broadcast_arrays(*channels), axis=1)


def values(where: Source, samples: Samples, notes: list, kind: str = "RGBA") -> np.ndarray:
    """The values of an input whose value comes from ``where`` at the surface's ``samples``:
    ``(count or 1, 3)`` for a colour or vector ``kind``, ``(count or 1, 1)`` for ``"VALUE"``;
    what could not be evaluated is said in ``notes`` (sentences, each once)."""
    return _Evaluator(samples, notes).source(where, kind)


def mean(where: Source, samples: Samples, notes: list, kind: str = "RGBA"):
    """The mean over the surface of :func:`values`: an RGB array, or a float for
    ``"VALUE"``."""
    array = values(where, samples, notes, kind)
    weights = getattr(samples, "weights", None)
    if weights is not None and len(array) == len(weights) and len(array) > 1:
        result = (weights @ array) / weights.sum()
    else:
        result = array.mean(axis=0)
    return float(result[0]) if kind == "VALUE" else result
