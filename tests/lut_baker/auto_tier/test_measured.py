"""The Auto tier's measured constants (lut_baker.auto_tier.measured): the data file holds every
candidate of every table, the constants are what it says, and a benchmark's write replaces its
own section only, whole or not at all."""

import json
import shutil

import pytest

from lut_baker import auto_tier
from lut_baker.auto_tier import measured


def test_the_file_holds_every_candidate_and_the_constants_are_its_numbers():
    data = measured.load()
    for coverage, row in data["cycles_costs"]["relative_cost"].items():
        assert sorted(row) == sorted(c.name for c in auto_tier.CANDIDATES)
        assert row[auto_tier.FULLEST.name] == 1.0
        for candidate in auto_tier.CANDIDATES:
            assert auto_tier.RELATIVE_COST[float(coverage)][candidate] == row[candidate.name]
            assert 0.0 < auto_tier.NOISE_K[float(coverage)][candidate] < 1.0
    for row in data["eevee_costs"]["relative_cost"].values():
        assert sorted(row) == sorted(c.name for c in auto_tier.EEVEE_CANDIDATES)
    paper = data["paper_traits"]
    assert auto_tier.PAPER_TIER_ERRORS == paper["tier_errors"]
    assert set(paper["tier_errors"]) == {"PRINCIPLED", "LAYERED", "EEVEE"}
    assert auto_tier.PAPER_SKIN_SHARE[45.0] == paper["skin_share"]["45"]
    for section in measured.SECTIONS:
        assert data[section]["command"].startswith("python bench/")
        assert data[section]["command"].endswith("--write")


def test_a_write_replaces_its_section_only(tmp_path):
    path = tmp_path / "measured.json"
    shutil.copy(measured.PATH, path)
    before = measured.load(path)
    section = {**before["paper_traits"], "profile_mismatch": 0.5}
    measured.write_section("paper_traits", section, path)
    after = measured.load(path)
    assert after["paper_traits"]["profile_mismatch"] == 0.5
    assert after["cycles_costs"] == before["cycles_costs"]
    assert after["eevee_costs"] == before["eevee_costs"]
    assert [p.name for p in tmp_path.iterdir()] == ["measured.json"]  # no temporary left


def test_unknown_sections_and_missing_candidates_are_errors(tmp_path):
    path = tmp_path / "measured.json"
    shutil.copy(measured.PATH, path)
    with pytest.raises(ValueError, match="unknown section"):
        measured.write_section("costs", {}, path)
    data = json.loads(path.read_text())
    del data["eevee_costs"]
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match="lacks the section"):
        measured.load(path)
    table = {"1": {c.name: 1.0 for c in auto_tier.CANDIDATES[1:]}}
    with pytest.raises(ValueError, match="lacks"):
        measured.by_candidate(table, auto_tier.CANDIDATES)
