"""The film's surface as an interface of its vehicle (docs/model.md, "The film as a slab"): its
share of the measured gloss, and what a film at a thickness does to a fair and a dark skin
relative to the bare skin (a benchmark that prints figures).

    python bench/film_surface.py [--share]

Printed:

- the vehicle's interface (Fresnel under uniform light and at normal incidence), the measured
  gloss under uniform light and the share ``k`` the surface keeps, per preset's surface;
- for a fair and a dark skin (the lighter and the darker head of docs/addon.md, "Match Skin",
  as diffuse albedos under Jensen's skin 1 gloss, with the shades those heads were matched
  with), at 2, 9.6, 50 and 150 um: made-up skin against bare skin at the first polar node
  (about normal incidence) and under uniform light, at the fixed shade; then with the shade
  matched at that thickness (Match Skin, exact), the absorption, the skin under the film, and
  the made-up skin's light at normal incidence without the film surface's gloss against the
  bare skin's (what a key light shows outside the film's highlights);
- the measured products' absorptions re-derived as the slab's thick limit;
- the gloss under uniform light that ``k`` divides (``--share``: only this): its integral
  through the half vector (:data:`lut_baker.model.film_slab.SHARE_LEVEL`,
  :data:`~lut_baker.model.film_slab.SHARE_NODES`) against the Fourier grid's order 0 at 48
  incidences (within about 1e-5 of converged), for lobes 2 to 60 degrees wide, with their CPU
  times.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from lut_baker.model import film_slab as FS  # noqa: E402
from lut_baker.model import presets  # noqa: E402
from lut_baker.model import slab_skin as SS  # noqa: E402
from lut_baker.model.albedo import bihemispherical, reflection_albedo  # noqa: E402
from lut_baker.model.layers import ReflectionLayer  # noqa: E402
from lut_baker.model.microfacet import fresnel_reflectance  # noqa: E402
from lut_baker.numerics.quadrature import hemisphere_panels  # noqa: E402

THICKNESSES_UM = (2.0, FS.DEFAULT_THICKNESS_UM, 50.0, 150.0)
SKINS = {
    "fair (the lighter head; paper_natural 0 / 0.317 / 0.508)":
        ((0.791, 0.478, 0.369), "paper_natural", (0.0, 0.317, 0.508)),
    "dark (the darker head; clarins_103 0.374 / 0.664 / 0.766)":
        ((0.299, 0.151, 0.103), "clarins_103", (0.374, 0.664, 0.766)),
}


def percent(values) -> str:
    return " / ".join(f"{100.0 * v:+.1f}%" for v in np.ravel(values))


def _cpu(function):
    start = time.process_time()
    value = float(np.ravel(function())[0])
    return value, time.process_time() - start


def share_accuracy() -> None:
    """The share's gloss integral against the Fourier grid's (module docstring)."""
    print("\n## The gloss under uniform light (what k divides): half vector against Fourier")
    print("| lobe (deg) | eta | Fourier, 48 incidences | s | half vector | s | relative |")
    print("|---|---|---|---|---|---|---|")
    for width in (2.0, 6.0, 10.0, 20.0, 30.0, 45.0, 60.0):
        for eta in (1.1, 1.19, 1.5):
            lobe = ReflectionLayer(P_d=0.0, P_s=1.0, n=1.0 / width, eta=eta)
            fourier, fourier_s = _cpu(lambda lobe=lobe: bihemispherical(
                lambda t: reflection_albedo(t, lobe)))
            FS._SHARES.clear()
            half, half_s = _cpu(lambda lobe=lobe: FS._unit_gloss_albedo(lobe))
            print(f"| {width:g} | {eta:g} | {fourier:.6f} | {fourier_s:.3f} | {half:.6f} | "
                  f"{half_s:.3f} | {half / fourier - 1.0:+.1e} |")


def main() -> int:
    if "--share" in sys.argv[1:]:
        share_accuracy()
        return 0
    grid = hemisphere_panels(3, 10, 33)  # the bake's default quadrature
    base = presets.paper()
    interface = FS.interface_albedo(FS.VEHICLE_INDEX)
    print(f"vehicle index {FS.VEHICLE_INDEX}: interface reflects {interface:.4f} under uniform "
          f"light, {float(fresnel_reflectance(1.0, FS.VEHICLE_INDEX)):.4f} at normal incidence")
    for name in ("paper_natural", "clarins_105", "clarins_112"):
        film = presets.foundation_film(name)
        measured = float(np.ravel(bihemispherical(
            lambda t, f=film: reflection_albedo(t, f.scaled(P_d=0.0))))[0])
        print(f"  {name}: measured gloss {measured:.4f}, k = {float(FS.surface_share(film)):.4f}")

    skin_layer, _ = presets.skin_layers("jensen_skin1")
    gloss = skin_layer.scaled(P_d=0.0)
    node = float(np.degrees(grid.theta[0]))
    bare_gloss_0 = float(np.ravel(reflection_albedo(node, gloss))[0])
    bare_gloss_u = float(np.ravel(bihemispherical(lambda t: reflection_albedo(t, gloss)))[0])
    print(f"\n(normal incidence: the first polar node, {node:.2f} degrees)")
    for label, (albedo, foundation, shade) in SKINS.items():
        film = presets.foundation_film(foundation)
        face = FS.face_albedo(film, grid)
        a = np.array(albedo)
        bare_0, bare_u = a + bare_gloss_0, a + bare_gloss_u
        print(f"\n## {label}")
        print("| um | fixed shade: normal | uniform | matched A | skin under | "
              "matched: normal | normal, surface gloss left out |")
        print("|---|---|---|---|---|---|---|")
        for um in THICKNESSES_UM:
            x = FS.relative_thickness(um)
            parts = SS.slab_skin_parts(SS.foundation_slab(film, base.film_transmission, grid,
                                                          shade), x, skin_layer, face)
            fixed = SS.parts_albedo(parts, a, grid)[:, 0] / bare_0 - 1.0
            fixed_u = SS.parts_colour(parts, a, grid) / bare_u - 1.0
            shade_m, under, _, _ = SS.matching_shade(bare_u, film, base.film_transmission,
                                                     skin_layer, a, um, grid)
            matched = SS.slab_skin_parts(SS.foundation_slab(
                film, base.film_transmission, grid, shade_m), x, skin_layer, face)
            direct = SS.parts_albedo(matched, under, grid)[:, 0]
            print(f"| {um:.1f} | {percent(fixed)} | {percent(fixed_u)} | "
                  f"{' / '.join(f'{v:.3f}' for v in shade_m)} | "
                  f"{' / '.join(f'{v:.3f}' for v in under / a)} | {percent(direct / bare_0 - 1)} "
                  f"| {percent((direct - matched.face[:, 0]) / bare_0 - 1.0)} |")

    print("\n## The measured products' absorptions as the slab's thick limit")
    stored = json.loads(presets.MEASURED_FOUNDATIONS_FILE.read_text())["foundations"]
    for name, entry in stored.items():
        target = np.array(entry["target"])
        paper_face, clamped = FS.solve_thick_absorption(target, base.film,
                                                        base.film_transmission, grid)
        own = FS.face_albedo(presets.foundation_film(name), grid)
        own_face, _ = FS.solve_thick_absorption(target, base.film, base.film_transmission,
                                                grid, face=own)
        print(f"  {name}: stored {np.round(entry['absorption'], 3)}, under the paper film's "
              f"surface {np.round(paper_face, 3)} (out of reach: {clamped.tolist()}), under "
              f"its own {np.round(own_face, 3)}")
    share_accuracy()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
