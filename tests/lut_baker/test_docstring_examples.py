"""The examples in the runtime's docstrings (``>>>``, colour-science style) run as doctests:
every module of the runtime, so that an example that no longer holds fails here.  Examples
print rounded values (``round``, ``np.round``), which hold on every machine."""

import doctest
import importlib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
RUNTIME = sorted(
    ".".join(path.relative_to(ROOT).with_suffix("").parts)
    for path in (ROOT / "lut_baker").rglob("*.py")
    if "offline" not in path.parts and path.name not in ("__init__.py", "__main__.py"))

FORMULAS_WITH_EXAMPLES = {
    "lut_baker.model.microfacet": ["fresnel_reflectance", "fresnel_transmittance",
                                   "distribution_term", "attenuation_term"],
    "lut_baker.model.dipole": ["fresnel_diffuse_reflectance", "dipole_profile",
                               "dipole_total_reflectance"],
    "lut_baker.model.albedo": ["reflection_albedo", "transmission_albedo", "bihemispherical"],
    "lut_baker.model.thick_layer": ["stack_reflectance", "solve_absorption"],
    "lut_baker.model.roughness": ["lobe_width_deg", "roughness_for_width"],
    "lut_baker.model.made_up_skin": ["coverage_weights", "combine"],
    "lut_baker.tables.uniform_light": ["made_up_colour", "matching_absorption"],
    "lut_baker.closures.view_image": ["sample_row"],
    "lut_baker.closures.principled_albedo": ["base_color_for_body"],
    "lut_baker.numerics.adding_doubling": ["add_layers", "double_slab", "slab", "thick_slab"],
    "lut_baker.model.film_slab": ["thickness_from_mass", "body", "made_up_albedo",
                                  "solve_thick_absorption"],
    "lut_baker.model.slab_shade": ["thick_limit_curve"],
}
"""The formulas whose docstrings must show an example (docs/model.md's equations)."""

NUMPY_PRINTING = {"legacy": False, "sign": "-", "precision": 8, "floatmode": "maxprec",
                  "suppress": False, "linewidth": 75, "threshold": 1000, "edgeitems": 3}
"""numpy's default printing, which the examples are written in: colour-science switches the
process to numpy 1.13's when it is imported (the offline part imports it), so the examples
run under these whatever ran before them."""


@pytest.mark.parametrize("name", RUNTIME)
def test_docstring_examples_hold(name):
    module = importlib.import_module(name)
    with np.printoptions(**NUMPY_PRINTING):
        result = doctest.testmod(module, optionflags=doctest.NORMALIZE_WHITESPACE
                                 | doctest.ELLIPSIS, report=True, verbose=False)
    assert result.failed == 0, f"{result.failed} of {result.attempted} examples fail in {name}"


@pytest.mark.parametrize("name, functions", FORMULAS_WITH_EXAMPLES.items())
def test_the_formulas_show_examples(name, functions):
    module = importlib.import_module(name)
    finder = doctest.DocTestFinder()
    bare = [f for f in functions
            if not any(test.examples for test in finder.find(getattr(module, f), f))]
    assert not bare, f"{name}: no example in the docstrings of {bare}"
