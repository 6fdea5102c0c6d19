"""The run-time fits are determined by their data: perturb their inputs by 1e-9 relative and
every output that ships moves by less than 1e-6, and no discrete choice (a Glossy
distribution, the subsurface method, keeping a specular lobe, the grids' node counts, the
Auto tier's candidate) flips; the margins of those choices are far above 1e-6.

The cases are the paper preset, a hand shade (medium beige on Jensen's Skin 1) and the four
measured products, at preview resolution (tests/support/fit_audit.py).  ``python
bench/fit_stability.py`` prints the figures of docs/stability.md, "How far the fits move"."""

import dataclasses

import numpy as np
import pytest
from support import fit_audit
from support.perturbation import LIMIT, PERTURBATION, movement, perturbed

from lut_baker import auto_tier
from lut_baker.closures import lobes, profiles
from lut_baker.closures.view_grid import lobe_widths_deg, view_grid
from lut_baker.model import presets, thick_layer

MARGIN = 1e-4
"""Smallest margin a discrete choice may have: 100 times the rule's 1e-6, 1e5 times the
perturbation."""


# --------------------------------------------------------------------------------------------
# The harness
# --------------------------------------------------------------------------------------------
def test_perturbed_moves_every_parameter_by_at_most_the_perturbation_and_stays_valid():
    skin = presets.made_up_skin("medium_beige", "jensen_skin1")  # coverage 1: at its bound
    moved = perturbed(skin, seed=3)
    assert moved.coverage < 1.0 and 1.0 - moved.coverage <= PERTURBATION
    for layer in ("film", "film_transmission", "skin_reflection", "dipole"):
        for field in dataclasses.fields(getattr(skin, layer)):
            before = np.asarray(getattr(getattr(skin, layer), field.name))
            after = np.asarray(getattr(getattr(moved, layer), field.name))
            assert np.all(np.abs(after - before) <= PERTURBATION * np.abs(before))
            assert np.all((after != before) | (before == 0.0))
    assert not any(c.moved for c in movement(moved, perturbed(skin, seed=3)).values())
    assert any(c.moved for c in movement(moved, perturbed(skin, seed=4)).values())


def test_perturbed_tables_keep_their_grids(paper_tables):
    moved = perturbed(paper_tables, seed=1)
    for name in ("theta_deg", "phi_deg", "radius_mm"):
        np.testing.assert_array_equal(getattr(moved, name), getattr(paper_tables, name))
    changes = movement(paper_tables, moved)
    assert 0.0 < changes["path3_gloss"].rel <= PERTURBATION
    # the surfaces' gloss is a closed form of the parameters: they are perturbed too
    assert 0.0 < changes["parameters/film/n"].rel <= PERTURBATION
    assert changes["theta_deg"].abs == 0.0


# --------------------------------------------------------------------------------------------
# Fast: single fits, the absorption solve, the Auto tier on the paper's traits
# --------------------------------------------------------------------------------------------
def test_the_glossy_and_profile_fits_move_less_than_the_limit(paper_tables):
    theta = np.asarray(paper_tables.theta_deg)
    grid = view_grid(lobe_widths_deg(paper_tables)["film_gloss"])

    def fits(tables):
        target = tables.surface_gloss("film_gloss", *grid.directions)
        return {"glossy": lobes.fit_glossy(grid, target, np.asarray(tables.film_gloss_albedo),
                                             theta, companion=True),
                "profile": profiles.fit_profile(tables, "BURLEY")}

    reference = fits(paper_tables)
    for seed in (0, 1):
        for name, change in movement(reference, fits(perturbed(paper_tables, seed=seed))).items():
            moved = change.abs if fit_audit.criterion(name) == "abs" else change.rel
            assert moved < LIMIT, (name, moved)


def test_solve_absorption_is_determined_by_its_targets():
    """The measured presets' absorption (bisection to 2^-80) from their stack reflectances."""
    exchange = thick_layer.paper_film_exchange()
    targets = np.array([[0.7091498284963302, 0.5294756633239771, 0.4113938637765513],
                        [0.55, 0.4, 0.3]])
    absorption, clamped = thick_layer.solve_absorption(targets, exchange)
    assert not np.any(clamped)
    for seed in range(3):
        moved, _ = thick_layer.solve_absorption(perturbed(targets, seed=seed),
                                                perturbed(exchange, seed=seed))
        assert np.max(np.abs(moved - absorption) / absorption) < LIMIT


def test_the_auto_tier_keeps_its_choices_for_the_paper_traits():
    traits = auto_tier.paper_traits()
    for label, scene in fit_audit.SCENES.items():
        choice = auto_tier.choose(scene, traits)
        margins = fit_audit.choice_margins(choice, scene, traits)
        assert min(margins.values()) > MARGIN, (label, margins)
        for seed in range(3):
            moved = auto_tier.choose(perturbed(scene, seed=seed), perturbed(traits, seed=seed))
            assert moved.candidate == choice.candidate, label
            assert abs(moved.chosen.error - choice.chosen.error) < LIMIT * choice.chosen.error


# --------------------------------------------------------------------------------------------
# Slow: every case, the whole closure fit, from the skin through the bake and from the tables
# --------------------------------------------------------------------------------------------
@pytest.mark.slow  # 5-60 s a case: three closure fits
@pytest.mark.parametrize("case", list(fit_audit.CASES))
def test_what_the_fits_ship_moves_less_than_the_limit(case):
    worst = fit_audit.fit_movement(case, seeds=(0,))
    assert any(name.startswith("fit_of_tables/") for name in worst)
    too_far = {name: value for name, value in worst.items() if value >= LIMIT}
    assert not too_far, too_far


@pytest.mark.slow  # 2-6 s a case
@pytest.mark.parametrize("case", list(fit_audit.CASES))
def test_the_fits_discrete_choices_are_far_from_flipping(case):
    skin, tables = fit_audit.case_tables(case)
    margins = fit_audit.decision_margins(tables, skin)
    small = {name: value for name, value in margins.items() if not value > MARGIN}
    assert not small, small


@pytest.mark.slow  # a closure fit and the gloss omissions
@pytest.mark.parametrize("case", list(fit_audit.CASES))
def test_the_auto_tier_choices_do_not_flip(case):
    _, tables, fit = fit_audit.case_fit(case)
    traits = auto_tier.traits_from_tables(tables, fit)
    for label, scene in fit_audit.SCENES.items():
        choice = auto_tier.choose(scene, traits)
        margins = fit_audit.choice_margins(choice, scene, traits)
        assert min(margins.values()) > MARGIN, (label, margins)
        moved = auto_tier.choose(perturbed(scene, seed=5), perturbed(traits, seed=5))
        assert moved.candidate == choice.candidate, label
