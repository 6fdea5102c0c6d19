"""The nodes that feed the group the skin under the film (makeup_skin_addon.skin_nodes), on the
textured head: the film gets a copy of the skin's normal map at the panel's fraction of its
strength, unlinked and linked again with Film Follows Pores."""

import pytest
from support.addon_steps import apply_operator, group_node


def test_the_film_normal_follows_the_panel(head):
    """Film Follows Pores off unlinks the film's normal (a smooth film: the pores filled), on
    links it again; its strength is the panel's fraction of the skin's."""
    material = apply_operator(head)
    settings, group = material.makeup_skin, group_node(material)
    film = material.node_tree.nodes["Made-up Skin Film Normal"]
    base = material.node_tree.nodes["Normal Map"].inputs["Strength"].default_value
    settings.film_follows_pores = False
    assert not group.inputs["Film Normal"].is_linked
    settings.film_normal_strength = 0.25
    settings.film_follows_pores = True
    assert group.inputs["Film Normal"].links[0].from_node == film
    assert film.inputs["Strength"].default_value == pytest.approx(0.25 * base, rel=1e-6)
