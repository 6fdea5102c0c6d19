"""Every name the add-on leaves in users' files and preferences, in one place (no bpy).

These strings are stored in .blend files (custom properties, datablock and node names), in the
user's presets folder, in keymaps and screen layouts (operator and panel idnames): changing one
orphans what older files hold.  Other modules import them from here; nothing below imports
anything.

Identifiers (``bl_idname``):

- :data:`OPERATOR_PREFIX` -- operators are ``makeup_skin.<name>`` (``bpy.ops.makeup_skin``).
- :data:`CLASS_PREFIX` -- class names ``MAKEUPSKIN_OT_*``, ``MAKEUPSKIN_PT_*``,
  ``MAKEUPSKIN_MT_*``; a panel's or menu's ``bl_idname`` is its class name.
- :data:`SETTINGS_ATTRIBUTE` -- ``Material.makeup_skin``, the panel's settings
  (:class:`makeup_skin_addon.properties.MakeupSkinSettings`); its ID properties are stored
  under this name.
- :data:`PRESET_SUBDIR` -- the folder under Blender's ``presets`` where parameter sets are saved.
- :data:`PAPER_FILM`, :data:`SLAB_FILM` -- the Film setting's values.
- :data:`SETTINGS_VERSION` -- what the settings mean, stamped on them (older files are
  upgraded when opened).

Custom properties of a material (JSON strings unless said otherwise):

- :data:`RECORD_KEY` -- the surface before Apply, for Revert (:mod:`.convert`).
- :data:`ERRORS_KEY` -- the tiers' errors at the settings of the last Apply (:mod:`.material`).
- :data:`CHOICE_KEY` -- the last Fit to Scene choice (:mod:`.tier_choice`).
- :data:`AUTO_KEY` -- the tier the last Apply chose for Tier = Auto, for the panel
  (:mod:`.material`).
- :data:`SAVED_SCALE_KEY`, :data:`SAVED_GLOSS_KEY` -- floats: the Subsurface Scale and Gloss
  before Fit to Scene set them to 0.

Custom properties of a node group:

- :data:`FIT_KEY` -- the group's record: bake, tier, fit summary, image hashes (:mod:`.nodes`).
- :data:`LEGACY_TABLES_REF` -- where older versions kept a whole tables image (removed on
  rebuild).

Datablock and node names (docs/addon.md, "Apply keeps the artist's material" and "The node
group"; Apply finds groups and images by name and reuses them):

- :data:`MATERIAL_NAME` -- the material Apply adds to an object that has none.
- :data:`GROUP_NODE` -- name and label of the group node in a made-up material's tree.
- :data:`FRAME_NAME`, :data:`FRAME_LABEL` -- the frame around the previous surface shader.
- :data:`FILM_NORMAL_NODE` -- the film's own Normal Map (or Bump) node, a weaker copy of the
  skin's, and :data:`BASE_STRENGTH_KEY`, the strength of the skin's it scales.
- :data:`OWNED_KEY` -- marks a node of the material's tree as the add-on's own (the skin under
  the film's nodes, copies of nodes from the artist's groups, the film's normal): Revert
  removes exactly these; :data:`SKIN_FRAME_NAME`, :data:`SKIN_FRAME_LABEL` -- their frame.
- :func:`group_name` -- ``Made-up Skin <Tier> [<method>] <key>`` (:data:`GROUP_PREFIX`,
  the tier's label, :data:`METHOD_LABELS`).
- :func:`view_image_name` -- ``MakeupSkin LUT <Tier> <key>`` (:data:`VIEW_IMAGE_PREFIX`).
"""

from __future__ import annotations

__all__ = [
    "OPERATOR_PREFIX",
    "CLASS_PREFIX",
    "SETTINGS_ATTRIBUTE",
    "PRESET_SUBDIR",
    "SETTINGS_VERSION",
    "PAPER_FILM",
    "SLAB_FILM",
    "RECORD_KEY",
    "ERRORS_KEY",
    "CHOICE_KEY",
    "AUTO_KEY",
    "SAVED_SCALE_KEY",
    "SAVED_GLOSS_KEY",
    "FIT_KEY",
    "LEGACY_TABLES_REF",
    "MATERIAL_NAME",
    "GROUP_NODE",
    "FRAME_NAME",
    "FRAME_LABEL",
    "FILM_NORMAL_NODE",
    "BASE_STRENGTH_KEY",
    "OWNED_KEY",
    "SKIN_FRAME_NAME",
    "SKIN_FRAME_LABEL",
    "OVER_LABEL",
    "GROUP_PREFIX",
    "METHOD_LABELS",
    "VIEW_IMAGE_PREFIX",
    "group_name",
    "view_image_name",
]

# --- identifiers ---------------------------------------------------------------------------
OPERATOR_PREFIX = "makeup_skin"
"""Operator ``bl_idname`` prefix: ``makeup_skin.apply`` and so on."""
CLASS_PREFIX = "MAKEUPSKIN"
"""Prefix of the add-on's class names, hence of its panels' and menus' ``bl_idname``."""
SETTINGS_ATTRIBUTE = "makeup_skin"
"""Name of the settings pointer on ``bpy.types.Material`` (the code reads it as
``material.makeup_skin``)."""
PRESET_SUBDIR = "makeup_skin"
"""Folder under Blender's ``presets`` where parameter sets are saved."""
PAPER_FILM = "PAPER"
"""The Film setting of the paper's model as published (its 150 um free film, paths 1 + 3)."""
SLAB_FILM = "SLAB"
"""The Film setting of the film as a slab at the Thickness setting."""
SETTINGS_VERSION = 4
"""What the settings mean, stamped on every change (``settings_version``).  1 (never stamped):
Shade By Colour was the colour the pigment passes (1 - absorption), Film Roughness a width in
degrees under Override Film, Coverage 1 and Shade By Absorption the defaults; 2: Colour is the
colour seen (the thick layer), Film and Skin Roughness are Blender roughness; 3: the Film
setting (the paper's film as published, the default, or the film at a Thickness): every
material of versions 1 and 2 had the paper's film; 4: the film at a Thickness is the default
(a version-3 file that stores no Film had the paper's)."""

# --- custom properties of a material ---------------------------------------------------------
RECORD_KEY = "makeup_skin_previous_surface"
"""Material custom property (JSON): the previous surface's node, its output socket, its parent
and location, and the output node, for :func:`makeup_skin_addon.convert.revert`."""
ERRORS_KEY = "makeup_skin_errors"
"""Material custom property: the tiers' errors at the settings of the last Apply (JSON): per
tier its angular ``rms`` and ``albedo`` errors, ``gloss_omission`` (per light angle, what
Gloss 0 changes in a sphere's image, :func:`lut_baker.auto_tier.gloss_omissions`), the
``coverage``, ``absorption`` and bake ``key`` they were measured for."""
CHOICE_KEY = "makeup_skin_scene_fit"
"""Material custom property: the last Fit to Scene choice (JSON), shown in the panel."""
AUTO_KEY = "makeup_skin_auto_tier"
"""Material custom property: what the last Apply chose for Tier = Auto (JSON: ``tier``, the
predicted ``error``, the ``engine`` it was chosen for), shown in the panel (which never
computes)."""
SAVED_SCALE_KEY = "makeup_skin_saved_subsurface_scale"
"""Material custom property: the Subsurface Scale before Fit to Scene set it to 0."""
SAVED_GLOSS_KEY = "makeup_skin_saved_gloss"
"""Material custom property: the Gloss before Fit to Scene set it to 0."""

# --- custom properties of a node group -------------------------------------------------------
FIT_KEY = "makeup_skin_fit"
"""Custom property of a group: its tables key, tier and the fit's summary (JSON)."""
LEGACY_TABLES_REF = "makeup_skin_tables"
"""Custom property by which older versions kept a whole tables image in the file; removed when
the group is rebuilt."""

# --- datablock and node names ------------------------------------------------------------------
MATERIAL_NAME = "Made-up Skin"
"""Name of the material Apply adds to an object without one."""
GROUP_NODE = "Made-up Skin"
"""Name of the group node in a made-up material's node tree."""
FRAME_NAME = "Made-up Skin: previous surface"
"""Name of the frame around the previous surface shader."""
FRAME_LABEL = "Before Made-up Skin (Revert restores it)"
"""Label of that frame."""
FILM_NORMAL_NODE = "Made-up Skin Film Normal"
"""Name and label of the Normal Map (or Bump) node Apply adds for the film: a copy of the one
feeding the skin's Normal, at a fraction of its strength (Revert removes it)."""
BASE_STRENGTH_KEY = "makeup_skin_base_strength"
"""Float custom property of that node: the skin's own strength, which the panel's Film Normal
strength multiplies."""
OWNED_KEY = "makeup_skin_owned"
"""Int custom property (1) of a node the add-on added to a material's tree (Revert removes the
nodes that have it, and only those)."""
SKIN_FRAME_NAME = "Made-up Skin: skin under the film"
"""Name of the frame around the nodes that give the group the skin under the film."""
SKIN_FRAME_LABEL = "Made-up Skin: the skin under the film (from the shader)"
"""Label of that frame."""
GROUP_PREFIX = "Made-up Skin"
"""Start of every node group name (:func:`group_name`)."""
METHOD_LABELS = {"BURLEY": "Burley", "RANDOM_WALK": "RW", "RANDOM_WALK_SKIN": "RW Skin"}
"""A forced subsurface method's part of a group name."""
VIEW_IMAGE_PREFIX = "MakeupSkin LUT "
"""Start of every view-angle image name (:func:`view_image_name`). Stored in files: it keeps
the word the add-on used for these images from the start, so the images of files made before
are still found (and reused, or removed with their group)."""


OVER_LABEL = "over Shader"
"""The part of a group's name that says it goes over the artist's shader (the bare skin is
its Skin Shader input), not over the skin preset's closures."""


def group_name(tier_label: str, key: str, method: str | None = None,
               over_shader: bool = False) -> str:
    """``Made-up Skin <Tier> [<method>] [over Shader] <key>`` (``tier_label``: the tier's
    label, :attr:`lut_baker.closures.tier_registry.Tier.label`); no method: the fit's own
    choice; ``over_shader``: a group whose bare skin is the artist's shader."""
    label = f" {METHOD_LABELS[method]}" if method else ""
    over = f" {OVER_LABEL}" if over_shader else ""
    return f"{GROUP_PREFIX} {tier_label}{label}{over} {key[:8]}"


def view_image_name(key: str, tier_label: str) -> str:
    """``MakeupSkin LUT <Tier> <key>``: the name of a tier's view-angle image."""
    return f"{VIEW_IMAGE_PREFIX}{tier_label} {key[:16]}"
