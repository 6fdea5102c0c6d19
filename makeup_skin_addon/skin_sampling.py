"""The mean of an image over a material's surface, read as its texture node reads it there (the
skin's own colour of Match Skin, Lighter / Darker and the first Apply: :mod:`.skin_colour`),
and the points at which the artist's shader is evaluated (:mod:`.artist_skin`).

The points are area-weighted and stratified on the faces of the material's slots
(:mod:`.surface_points`, cached per mesh), the image is read box-filtered small
(:mod:`.image_texels`, cached per image); a cold mesh or image reports its progress
(:func:`.progress.report`).

- :func:`surface_mean` -- the mean (:class:`SurfaceMean`): its standard error, the faces it
  covers, what was said about it, or why there is none.
- :func:`surface_samples` -- the points for evaluating the artist's shader
  (:class:`SurfaceSamples`), counted by what the camera sees.
- :func:`image_rgb` -- an image at UVs as its texture node reads it, a UDIM image tile by
  tile.
- :func:`rendered_users` -- the objects read: those that use the material and render in the
  scene (:func:`rendering`); :func:`in_edit_mode` -- why an object in Edit Mode is not.
- :func:`clear_cache` -- forget the points and the reduced images (the add-on's unregister
  calls it).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import bpy
import numpy as np

from . import image_texels, mesh_attributes, pages, surface_points, surface_values
from .progress import Report, report, reporting

__all__ = ["SurfaceMean", "surface_mean", "SurfaceSamples", "surface_samples", "image_rgb",
           "in_edit_mode", "rendered_users", "rendering", "clear_cache"]


@dataclass
class SurfaceMean:
    """The mean of an image over a material's faces: ``rgb`` (linear, or None when there is
    none, ``problem`` says why), its standard error ``error`` per channel (of the points'
    sampling; the box filter's bias is apart, docs/addon.md), the material's faces counted
    ``faces``, the objects read ``objects`` and ``notes`` (sentence ends: a colour space read as
    sRGB, an object left out)."""

    rgb: np.ndarray | None
    error: np.ndarray | None
    faces: int
    objects: tuple = ()
    notes: list = field(default_factory=list)
    problem: str = ""


def _uv_layer(mesh, uv_map: str):
    if uv_map:
        return mesh.uv_layers.get(uv_map)
    return next((layer for layer in mesh.uv_layers if layer.active_render), None)


def rendering(scene) -> set:
    """The objects ``scene`` renders (their ``session_uid``): in a collection of a view layer
    it renders, not excluded there, no collection on the way disabled in renders, the object
    itself not disabled in renders."""
    out: set = set()

    def walk(layer_collection) -> None:
        if layer_collection.exclude or layer_collection.collection.hide_render:
            return
        out.update(obj.session_uid for obj in layer_collection.collection.objects
                   if not obj.hide_render)
        for child in layer_collection.children:
            walk(child)

    for view_layer in scene.view_layers:
        if view_layer.use:
            walk(view_layer.layer_collection)
    return out


def rendered_users(material, scene=None) -> tuple[list, list[str]]:
    """``(objects, notes)``: the mesh objects that use ``material`` and render in ``scene``
    (default the current one, :func:`rendering`), the others left out and said so; when none
    renders, every object that uses it, and a note saying so."""
    users = surface_points.users(material)
    scene = scene if scene is not None else getattr(bpy.context, "scene", None)
    if scene is None or not users:
        return users, []
    renders = rendering(scene)
    rendered = [obj for obj in users if obj.session_uid in renders]
    if not rendered:
        return users, [f"no object in scene {scene.name!r} renders {material.name!r}: every "
                       f"object that uses it counts"]
    return rendered, [f"{obj.name!r} does not render in scene {scene.name!r}: left out"
                      for obj in users if obj not in rendered]


def in_edit_mode(obj) -> str:
    """Why an object in Edit Mode is not read (else ""): Blender gives Python none of a mesh's
    UVs (nor its attributes) while it is edited, even after ``update_from_editmode``."""
    return (f"{obj.name!r} is in Edit Mode, where Blender gives Python no UVs"
            if obj.mode == "EDIT" else "")


def _missing_uv(obj, uv_map: str, reader: str) -> str:
    by = f" (read by {reader!r})" if reader else ""
    return f"{obj.name!r} has no UV map {uv_map!r}{by}" if uv_map else \
        f"{obj.name!r} has no UV map{by}"


@pages.ordinary()
def surface_mean(image: Any, material: Any, *, uv_map: str = "", extension: str = "REPEAT",
                 reader: str = "", budget: int = surface_points.BUDGET,
                 size: int = image_texels.IMAGE_SIZE) -> SurfaceMean:
    """The mean of ``image`` over the faces that use ``material`` on every mesh object, weighted
    by their area in the world: ``budget`` points split between the objects by area
    (:func:`.surface_points.object_points`), read at the UV map ``uv_map`` (the active render
    map when empty) in the image box-filtered to ``size`` (:func:`.image_texels.reduced_image`)
    with the texture's ``extension``.  ``reader``: the texture node's name, for the messages.
    An object without that UV map is left out (said in ``notes``); with no face left, ``rgb``
    is None and ``problem`` says why."""
    objects, notes = rendered_users(material)
    if not objects:
        return SurfaceMean(None, None, 0, problem=f"no mesh object uses {material.name!r}")
    missing, readable = [], []
    for obj in objects:
        layer = None if in_edit_mode(obj) else _uv_layer(obj.data, uv_map)
        if layer is None:
            missing.append(in_edit_mode(obj) or _missing_uv(obj, uv_map, reader))
        else:
            readable.append((obj, layer))
    if not readable:
        return SurfaceMean(None, None, 0, problem="; ".join(missing))
    notes += [f"{text}: left out" for text in missing]
    slow = not image_texels.is_cached(image, size)
    reduced = None  # a UDIM image whose tiles are files is read tile by tile (image_rgb)
    if not image_texels.tile_files(image):
        # read first: its decoder's peak is the call's
        reduced = image_texels.reduced_image(image, size)
        if reduced.pixels is None:
            return SurfaceMean(None, None, 0, notes=notes, problem=reduced.problem)
    surfaces = [surface_points.Surface(obj, material, layer) for obj, layer in readable]
    cold = [surface for surface in surfaces if surface.cached is None]
    for step, surface in enumerate(cold):
        report(0.6 + 0.4 * step / len(cold), f"Reading the faces of {surface.obj.name!r}")
        surface.areas()
    counts = surface_points.shares([surface.area() for surface in surfaces], budget)
    every = [(surface.obj, surface.points(n)) for surface, n in zip(surfaces, counts,
                                                                    strict=True)]
    faces = sum(points.faces for _, points in every)
    picked = [(obj, points) for obj, points in every if len(points.uv)]
    if not picked:
        why = (f"the {faces} faces that use {material.name!r} have no area" if faces else
               f"no face uses {material.name!r}")
        return SurfaceMean(None, None, faces, notes=notes, problem=why)
    total = sum(points.area for _, points in picked)
    rgb, variance = np.zeros(3), np.zeros(3)
    said: list[str] = []

    def say(sentence: str) -> None:
        if sentence not in said:
            said.append(sentence)

    for _, points in picked:
        values = image_rgb(image, points.uv, extension, say, reduced)
        share = points.area / total
        rgb += share * values.mean(axis=0)
        variance += share ** 2 * values.var(axis=0) / len(values)
    if slow or cold:
        report(1.0, "")
    return SurfaceMean(rgb, np.sqrt(variance), faces, tuple(obj.name for obj, _ in picked),
                       said + notes)



# -- points for evaluating the artist's shader ---------------------------------------------------

class SurfaceSamples:
    """The points of a material's surface as :mod:`.surface_values` evaluates the artist's
    shader at them (:class:`.surface_values.Samples`): the same points (faces and places in
    them: the seed and the areas fix them) at every UV map, ``weights`` (each point's share of
    the area), ``picked`` (the objects and their points, in the weights' order), image values
    read from the reduced image (:func:`.image_texels.reduced_image`).

    An object without a UV map a texture reads is left out for that map (said in ``notes``);
    with no face to read (``problem`` says why: no object, no face of the material, no UV
    map), one point at UV (0, 0) stands for the surface."""

    def __init__(self, material, budget: int = surface_points.BUDGET, scene=None):
        self.material = material
        self.scene = scene
        self.camera = scene.camera if scene is not None else None
        self.objects, self.notes = rendered_users(material, scene)
        self._uv: dict = {}
        self._attributes: dict = {}
        self.budget = budget
        self.count = 0
        self.weights: np.ndarray | None = None
        self.faces = 0
        self.seen_by = ""
        self.picked: list = []
        self.problem = "" if self.objects else f"no mesh object uses {material.name!r}"

    def _note(self, sentence: str) -> None:
        if sentence and sentence not in self.notes:
            self.notes.append(sentence)

    def uv(self, name: str, reader: str = "") -> np.ndarray:
        """``(count, 2)`` UVs of the map ``name`` (``""``: each mesh's active render map);
        the objects without it are left out (noted)."""
        if name in self._uv:
            return self._uv[name]
        surfaces, missing = [], []
        for obj in self.objects:
            layer = None if in_edit_mode(obj) else _uv_layer(obj.data, name)
            if layer is None:
                missing.append(in_edit_mode(obj) or _missing_uv(obj, name, reader))
            else:
                surfaces.append(surface_points.Surface(obj, self.material, layer))
        counts = surface_points.shares([surface.area() for surface in surfaces], self.budget)
        picked = [(surface.points(n), n) for surface, n in zip(surfaces, counts, strict=True)
                  if n > 0]
        if not picked:
            faces = sum(surface.areas()[1] for surface in surfaces)
            if missing and not surfaces:
                self._note(f"{'; '.join(missing)}: read at UV (0, 0)")
            elif self.objects:
                self.problem = (f"no face uses {self.material.name!r}" if not faces else
                                f"the {faces} faces that use {self.material.name!r} have no "
                                f"area")
            return self._remember(name, np.zeros((1, 2)), np.ones(1))
        for sentence in missing:
            self._note(f"{sentence}: left out")
        uv = np.concatenate([points.uv for points, _ in picked]).astype(float)
        weights = np.concatenate([np.full(len(points.uv), points.area / n)
                                  for points, n in picked])
        used = [(surface.obj, points) for surface, (points, _) in zip(
            [s for s, n in zip(surfaces, counts, strict=True) if n > 0], picked, strict=True)]
        if self.weights is None:
            self.faces = sum(points.faces for points, _ in picked)
            self.picked = used
        if self.camera is not None and self.weights is None:
            seen = np.concatenate([_seen(obj, points, self.camera, self.scene)
                                   for obj, points in used])
            if np.any(seen > 0.0):
                weights = weights * seen
                self.seen_by = self.camera.name
            else:
                self._note(f"the camera {self.camera.name!r} sees none of it: the whole "
                           f"surface counts")
        return self._remember(name, uv, weights)

    def _remember(self, name: str, uv, weights):
        if self.weights is None:
            self.weights, self.count = weights, len(uv)
        elif len(uv) != self.count:  # the objects left out differ between maps
            uv = np.broadcast_to(uv.mean(axis=0), (self.count, 2))
            self._note(f"UV map {name!r} read at its mean (not every object has it)")
        self._uv[name] = uv
        return uv

    def attribute(self, name: str, reader: str = "") -> tuple[np.ndarray, bool]:
        """``((count, 4) values, colour)``: the mesh attribute ``name`` ("": the colour
        attribute to render) at the points, as an Attribute or Color Attribute node reads it
        (:func:`.mesh_attributes.at_points`), and whether it holds colours; an object without
        it gives 0, as Blender renders it, and is noted."""
        if name in self._attributes:
            return self._attributes[name]
        if self.weights is None:
            self.uv("")  # the points, the same at every UV map
        parts, colour = [], False
        for obj, points in self.picked:
            found = mesh_attributes.at_points(obj, name, points)
            if found.values is None:
                self._note(f"{found.problem} (read by {reader!r}): taken as 0")
                parts.append(np.zeros((len(points.uv), 4)))
            else:
                parts.append(found.values)
                colour = colour or found.colour
        values, bad = image_texels.finite_values(np.concatenate(parts) if parts
                                                 else np.zeros((1, 4)))
        if bad:
            self._note(f"attribute {name!r} (read by {reader!r}) is not finite at {bad} points: "
                       f"taken as the mean of the others")
        if len(values) != self.count:
            values = np.broadcast_to(values.mean(axis=0), (self.count, 4))
        self._attributes[name] = (values, colour)
        return values, colour

    def image(self, image, uv: np.ndarray, extension: str) -> np.ndarray:
        """``(count, 4)`` linear RGBA of ``image`` at ``uv`` (alpha 1): :func:`image_rgb`."""
        rgb = image_rgb(image, uv, extension, self._note)
        return np.concatenate([rgb, np.ones((len(rgb), 1))], axis=1)


def image_rgb(image, uv: np.ndarray, extension: str, note: Callable[[str], None],
              reduced: image_texels.ReducedImage | None = None) -> np.ndarray:
    """``(n, 3)`` linear RGB of ``image`` at ``uv`` as its texture node reads it (the reduced
    image, :mod:`.image_texels`, or ``reduced`` if read already); a tiled (UDIM) image whose
    tiles are files read tile by tile (:func:`_tiles`); what was assumed said by ``note``
    (without pixels, neither black nor Blender's magenta but a neutral guess)."""
    tiles = image_texels.reduced_tiles(image) if image.source == "TILED" else {}
    if tiles:
        return _tiles(image, tiles, uv, note)
    return _texels(reduced or image_texels.reduced_image(image), uv, extension, note)


def _texels(reduced, uv: np.ndarray, extension: str, note) -> np.ndarray:
    if reduced.pixels is None:
        note(f"{reduced.problem}: taken as {surface_values.NEUTRAL:g}")
        return np.full((len(uv), 3), surface_values.NEUTRAL)
    if reduced.note:
        note(reduced.note)
    return image_texels.read_texels(reduced.pixels, uv, extension)


def _tiles(image, tiles: dict, uv: np.ndarray, note) -> np.ndarray:
    """``(n, 3)``: each UV read in the tile it falls in (tile ``1001 + u + 10 v`` of the
    whole parts, at the fractional parts); a UV outside every tile (Blender renders it
    without the image) taken as neutral, noted."""
    whole = np.floor(uv)
    number = 1001 + whole[:, 0] + 10 * whole[:, 1]
    inside = (whole[:, 0] >= 0) & (whole[:, 0] < 10) & (whole[:, 1] >= 0)
    rgb = np.full((len(uv), 3), surface_values.NEUTRAL)
    for tile, reduced in tiles.items():
        at = inside & (number == tile)
        if np.any(at):
            rgb[at] = _texels(reduced, uv[at] - whole[at], "REPEAT", note)
    outside = ~inside | ~np.isin(number, list(tiles))
    if np.any(outside):
        note(f"{np.count_nonzero(outside) / len(uv):.1%} of the points fall outside the tiles "
             f"of image {image.name!r}: taken as {surface_values.NEUTRAL:g}")
    return rgb


def _seen(obj, points: surface_points.Points, camera, scene) -> np.ndarray:
    """How much of each point the camera sees: its area's projection towards the camera (the
    cosine between its face's normal and the direction to the camera, 0 facing away) where it
    falls inside the camera's frame and in front of it, else 0 (hidden surfaces are not
    looked for)."""
    matrix = np.array(obj.matrix_world, float)
    position = points.position @ matrix[:3, :3].T + matrix[:3, 3]
    normal = points.normal @ np.linalg.inv(matrix[:3, :3])  # the inverse transpose, by rows
    normal /= np.maximum(np.sqrt(_rows_dot(normal, normal)), 1e-30)[:, None]
    view = np.array(camera.matrix_world, float)
    local = (position - view[:3, 3]) @ view[:3, :3]  # in the camera's frame (looks down -z)
    frame = np.array([tuple(corner) for corner in camera.data.view_frame(scene=scene)])
    if camera.data.type == "ORTHO":
        towards = np.broadcast_to(view[:3, 2], position.shape)
        x, y = local[:, 0], local[:, 1]
        inside = np.ones(len(local), bool)
    else:
        towards = view[:3, 3] - position
        towards = towards / np.maximum(np.sqrt(_rows_dot(towards, towards)), 1e-30)[:, None]
        depth = -local[:, 2]
        inside = depth > 0.0
        scale = -frame[0, 2] / np.where(inside, depth, 1.0)
        x, y = local[:, 0] * scale, local[:, 1] * scale
    inside &= ((x >= frame[:, 0].min()) & (x <= frame[:, 0].max())
               & (y >= frame[:, 1].min()) & (y <= frame[:, 1].max()))
    return np.where(inside, np.maximum(_rows_dot(normal, towards), 0.0), 0.0)


def _rows_dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The dot product of each row of ``a`` and ``b`` (``(n, 3)``), summed in the order
    ``np.sum(a * b, axis=1)`` sums them, a column at a time (several times faster than that
    reduction over rows of three)."""
    return (a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]) + a[:, 2] * b[:, 2]


def surface_samples(material, progress: Report | None = None, scene=None) -> SurfaceSamples:
    """The points of ``material``'s surface for evaluating its shader
    (:class:`SurfaceSamples`; their UVs are read, and cached, when first asked for); with a
    ``scene`` that has a camera, each point counts by how much of it the camera sees
    (:func:`_seen`: the skin as the camera shows it), else by its area."""
    if scene is not None and scene.camera is not None and scene == bpy.context.scene:
        bpy.context.view_layer.update()  # matrices follow moves only after an update
    samples = SurfaceSamples(material, scene=scene)
    if progress is not None:
        with reporting(progress):
            samples.uv("")
    return samples


def clear_cache() -> None:
    """Forget the cached points and reduced images."""
    surface_points.clear_cache()
    image_texels.clear_cache()
