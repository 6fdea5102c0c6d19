"""What a layer fit returns (lut_baker.offline.measured.fit_results): the record of its starts
in words and as plain data, a fit's result as plain data that JSON writes and that holds the
fitted layer, and its warnings read back by parameter."""

import json

import pytest

from lut_baker.model.presets import paper_layers
from lut_baker.offline.measured import fit_results
from lut_baker.offline.measured import layer_fit as F
from lut_baker.offline.measured import measurements as M

FILM = paper_layers()[0]


def test_starts_say_how_they_ended():
    every = fit_results.Starts(count=4, reached=4, best_cost=0.5, spread=2e-9, next_excess=None)
    assert every.summary() == ("4 of 4 starts reached the best cost (parameters within 2e-09)")
    assert "next_excess" not in every.as_dict()
    some = fit_results.Starts(count=4, reached=3, best_cost=0.5, spread=2e-9, next_excess=0.31)
    assert some.summary().endswith("; the next end lies 31% higher)")
    assert some.as_dict()["next_excess"] == 0.31
    close = fit_results.Starts(count=4, reached=3, best_cost=0.5, spread=0.0, next_excess=2e-5)
    assert "lies 2e-05 (relative) higher" in close.summary()


def test_a_result_as_plain_data_holds_the_fitted_layer():
    data = M.synthesize_reflection(FILM, noise=0.02, rng=3)
    result = F.fit_reflection(data)
    plain = json.loads(json.dumps(result.as_dict()))
    assert plain["kind"] == "reflection" and plain["free"] == ["P_d", "P_s", "n", "eta"]
    for name, value in plain["params"].items():
        assert value == pytest.approx(float(getattr(result.params, name)), rel=1e-15)
    assert plain["starts"] == result.starts.as_dict()
    assert len(plain["correlation"]) == len(result.free)
    assert result.ok == (not plain["warnings"])


def test_warnings_read_back_by_parameter():
    data = M.synthesize_reflection(FILM, noise=0.02, rng=3)
    result = F.fit_reflection(data)
    stuck = fit_results.FitResult(**{**vars(result), "warnings": [
        "n ended at its bound (10): the data do not determine it"]})
    assert not stuck.ok and stuck.at_bound("n") and not stuck.at_bound("eta")
    assert fit_results.DEFAULT_LIMITS == fit_results.Limits()
