"""Baked tables, closure fits and measurement fits are bit-identical to the recorded digests
(tests/data/golden_digests.json; tests/support/digests.py computes them, ``python
bench/golden_digests.py`` prints them item by item and ``--write`` records new ones)."""

import pytest
from support import digests

pytestmark = pytest.mark.slow  # ~5 s: three skins baked at two resolutions and fitted


def test_every_digest_equals_the_recorded_one():
    golden = digests.golden()
    current = digests.compute()
    assert sorted(current) == sorted(golden)
    different = [key for key in sorted(golden) if current[key] != golden[key]]
    assert not different, f"{len(different)} of {len(golden)} digests differ: {different}"
