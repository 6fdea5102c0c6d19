"""The Auto tier: model no more than the scene needs.

From a description of the scene (camera, resolution, the object's size in mm, its distance or
pixel footprint, the lights, the engine, the samples) this module predicts, for every
:class:`Candidate` way of shading made-up skin, its error against the exact model and its
render cost, and picks the cheapest one whose error is within a tolerance of the best.

Error of a candidate (relative RMS over the object's pixels, one render against the converged
exact image)::

    E = sqrt(e_angle^2 + e_subsurface^2 + e_gloss^2 + noise^2)

- ``e_angle``: the tier's angular error against the tables
  (:func:`lut_baker.closures.tiers.tier_errors`, relative RMS of ``f cos(theta_i)``);
- ``e_subsurface``: without the subsurface closure, the light the skin spreads under the
  surface stays where it entered; how much that changes the image is the pixel-footprint blur
  argument, computed by :func:`subsurface_omission_error` (the profile's blur of a sphere's
  shading, averaged over each pixel).  A spread under half a pixel changes no pixel by much.
  With the closure, what is left is the closure's profile mismatch times that;
- ``e_gloss``: without gloss lobes (the group's Gloss input at 0), the change of a sphere's
  image under the scene's lights, from the tier's own replica with and without them
  (:func:`gloss_omission_error`; without a closure fit, the tables' gloss share of
  :func:`gloss_and_skin_shares`);
- ``noise``: the Monte Carlo noise of one render, ``k / sqrt(samples)`` with ``k`` measured
  per candidate and coverage (:data:`NOISE_K`); 0 with a denoiser (its bias is not
  modelled) and in EEVEE.

So a gloss below the noise of the fullest tier costs little to leave out, a subsurface
radius under half a pixel leaves ``e_subsurface`` near 0, and each engine admits the tiers
made for it (:data:`ENGINE_TIERS`: Cycles the Principled and Layered tiers, EEVEE the EEVEE
tier).  :func:`choose` takes the cheapest candidate (costs: :data:`RELATIVE_COST`, measured at
coverage 1 and 0 and interpolated by the material's share of skin light; in EEVEE
:data:`EEVEE_RELATIVE_COST`) whose ``E`` is at most ``min E + tolerance`` (default 2%).

Modules
-------
- :mod:`.candidates` -- the candidates, their measured costs and noise.
- :mod:`.scene` -- what the tier needs of a scene (:class:`SceneDescription`).
- :mod:`.material` -- what it needs of a material (:class:`MaterialTraits`).
- :mod:`.blur` -- the pixel-footprint blur argument.
- :mod:`.choice` -- the prediction and the choice (:func:`choose`).
- :mod:`.measured` -- the measured constants, in ``measured.json`` (rewritten by the
  benchmarks that measure them).

The names below are the package's interface, from those modules.
"""

from .blur import blur_kernel, subsurface_omission_error
from .candidates import (
                         CANDIDATES,
                         COST_COMMAND,
                         COST_SKIN_SHARE,
                         DEFAULT_TOLERANCE,
                         EEVEE_CANDIDATES,
                         EEVEE_COST_COMMAND,
                         EEVEE_RELATIVE_COST,
                         ENGINE_TIERS,
                         ENGINES,
                         FULLEST,
                         NOISE_K,
                         RELATIVE_COST,
                         Candidate,
                         candidates,
                         noise,
                         relative_cost,
)
from .choice import Choice, Prediction, choose, needs_subsurface, predict
from .material import (
                         PAPER_GLOSS_OMISSION,
                         PAPER_GLOSS_SHARE,
                         PAPER_MISMATCH,
                         PAPER_SKIN_SHARE,
                         PAPER_TIER_ERRORS,
                         SHARE_LIGHTS_DEG,
                         SPHERE_PX,
                         TRAITS_COMMAND,
                         MaterialTraits,
                         gloss_and_skin_shares,
                         gloss_omission_error,
                         gloss_omissions,
                         paper_traits,
                         profile_mean_radius_mm,
                         profile_mismatch,
                         traits_from_tables,
)
from .scene import SceneDescription, pixel_footprint_mm

__all__ = [
    "Candidate", "candidates", "CANDIDATES", "EEVEE_CANDIDATES", "FULLEST", "ENGINES",
    "ENGINE_TIERS",
    "RELATIVE_COST", "EEVEE_RELATIVE_COST", "NOISE_K", "COST_SKIN_SHARE", "relative_cost",
    "DEFAULT_TOLERANCE", "SceneDescription", "pixel_footprint_mm", "MaterialTraits",
    "paper_traits", "PAPER_TIER_ERRORS", "PAPER_SKIN_SHARE", "PAPER_GLOSS_SHARE",
    "PAPER_MISMATCH", "traits_from_tables", "profile_mean_radius_mm", "gloss_and_skin_shares",
    "gloss_omission_error", "gloss_omissions", "PAPER_GLOSS_OMISSION", "profile_mismatch",
    "blur_kernel", "subsurface_omission_error", "noise", "Prediction", "predict", "Choice",
    "needs_subsurface", "choose", "TRAITS_COMMAND", "SHARE_LIGHTS_DEG", "SPHERE_PX", "COST_COMMAND",
    "EEVEE_COST_COMMAND",
]
