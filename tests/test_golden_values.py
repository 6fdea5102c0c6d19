"""The baked tables, closure fits and measurement fits stay within a stated tolerance of the
stored golden values (tests/data/golden_values.npz and .json; tests/support/golden_values.py
says what the set is, what is stored and how each tolerance was chosen from how far the
quantity moves between processors and thread counts).  ``python bench/golden_values.py``
prints the comparison quantity by quantity; ``--write`` regenerates the reference when a
change is intended."""

import math

import numpy as np
import pytest
from support import golden_values as gv


@pytest.fixture(scope="module")
def reference():
    return gv.read_reference()


def _check(current, reference, names):
    rows = gv.compare(current, reference, names)
    failed = [row for row in rows if not row.ok]
    assert not failed, gv.failure_message(failed, len(rows))


def test_the_paper_preview_tables_are_within_their_tolerances(reference):
    """The everyday tier's share: every value of the paper preset's preview tables."""
    names = [n for n in reference[0] if n.startswith("tables/paper/preview/")]
    assert len(names) > 15
    _check(gv.compute(parts=("tables",), skins=("paper",)), reference, names)


@pytest.mark.slow  # ~15 s: three skins baked at two resolutions, fitted, four measurement fits
def test_every_golden_value_is_within_its_tolerance(reference):
    _check(gv.compute(), reference, None)


def test_the_reference_is_small_and_states_every_tolerance(reference):
    values, metadata = reference
    size = gv.REFERENCE.stat().st_size + gv.METADATA.stat().st_size
    assert size < 2e6
    others = set(gv.CONFIGS) - {gv.BASELINE}
    parts = {gv.kind(name) for name in values}
    assert parts == {"tables", "closure_fit", "measurement_fit"}
    for name, entry in metadata["quantities"].items():
        assert set(entry["moved"]) == others, name
        if "rtol" not in entry:
            continue
        assert gv.FLOOR[gv.kind(name)] <= entry["rtol"] <= gv.CAP[gv.kind(name)], name
        assert entry["rule"] and entry["largest_movement"] == max(entry["moved"].values())


def test_a_moved_value_is_reported_with_its_change_tolerance_and_the_command(reference):
    values, metadata = reference
    numeric = next(n for n, e in metadata["quantities"].items() if "rtol" in e
                   and "closure_fit" in n and np.max(np.abs(values[n])) > 0)
    discrete = "closure_fit/paper/default/subsurface_method"
    current = dict(values)
    rtol = metadata["quantities"][numeric]["rtol"]
    current[numeric] = np.asarray(values[numeric]) * (1.0 + 10.0 * rtol)
    current[discrete] = "RANDOM_WALK" if values[discrete] != "RANDOM_WALK" else "BURLEY"
    rows = gv.compare(current, reference)
    failed = [row for row in rows if not row.ok]
    assert [row.name for row in failed] == sorted([numeric, discrete])
    moved = next(row for row in failed if row.name == numeric)
    assert moved.rel == pytest.approx(10.0 * rtol, rel=1e-3) and moved.rtol == rtol
    message = gv.failure_message(failed, len(rows))
    assert numeric in message and discrete in message and gv.REGENERATE in message
    assert f"{moved.rel:.3g}" in message and f"{rtol:.3g}" in message


def test_a_missing_or_new_quantity_fails(reference):
    values, _ = reference
    current = dict(values)
    gone = sorted(current)[0]
    del current[gone]
    current["tables/paper/preview/new_table"] = np.zeros(3)
    failed = [row for row in gv.compare(current, reference) if not row.ok]
    assert {row.name for row in failed} == {gone, "tables/paper/preview/new_table"}
    assert all(math.isinf(row.rel) for row in failed)
