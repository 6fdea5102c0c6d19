"""The add-on's way into lut_baker's runtime: ordinary import statements (no bpy).

Installed as an extension, ``lut_baker`` sits beside this package, inside the extension's own
package (``bl_ext.<repo>.makeup_skin.lut_baker``), and is imported relatively; run from a
source checkout (the tests, the tools, ``bench/``), ``makeup_skin_addon`` is a top-level package
and so is ``lut_baker``.  :data:`.package.INSTALLED` tells which, by the package's own name, and
every module of the add-on imports lut_baker's modules from here, so that a reader, a type
checker or a rename follows each name from the panel into the bake.  Only the runtime is
imported (numpy only); nothing of ``lut_baker.offline`` ships.
"""

from .package import INSTALLED

if INSTALLED:
    from ..lut_baker import auto_tier, bake
    from ..lut_baker.closures import (
        closure_fit,
        cycles,
        fitting,
        principled_albedo,
        profiles,
        tier_formulas,
        tier_registry,
        tiers,
        view_image,
    )
    from ..lut_baker.model import (
        albedo,
        film_slab,
        params_file,
        presets,
        roughness,
        slab_shade,
        slab_skin,
        thick_layer,
    )
    from ..lut_baker.numerics import cache, quadrature
    from ..lut_baker.tables import codec, slab_tables, table_set, uniform_light
else:
    from lut_baker import auto_tier, bake
    from lut_baker.closures import (
        closure_fit,
        cycles,
        fitting,
        principled_albedo,
        profiles,
        tier_formulas,
        tier_registry,
        tiers,
        view_image,
    )
    from lut_baker.model import (
        albedo,
        film_slab,
        params_file,
        presets,
        roughness,
        slab_shade,
        slab_skin,
        thick_layer,
    )
    from lut_baker.numerics import cache, quadrature
    from lut_baker.tables import codec, slab_tables, table_set, uniform_light

__all__ = ["albedo", "auto_tier", "bake", "cache", "closure_fit", "codec", "cycles", "film_slab",
           "fitting", "params_file", "presets", "principled_albedo", "profiles", "quadrature",
           "roughness", "slab_shade", "slab_skin", "slab_tables", "table_set", "thick_layer",
           "tier_formulas", "tier_registry", "tiers", "uniform_light", "view_image"]
