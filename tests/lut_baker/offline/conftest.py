"""Fixtures of the offline tests: the paper's figures, drawn once for the session."""

import pytest

from lut_baker.offline import paper_figures


@pytest.fixture(scope="session")
def drawn():
    """Every figure drawn with its defaults (the paper's parameters), as {name: Figure}: read
    by tests/lut_baker/offline/test_paper_figures.py and written by the figures command's test
    (drawing them twice would double their cost, ~3 s)."""
    return {name: draw() for name, draw in paper_figures.FIGURES.items()}
