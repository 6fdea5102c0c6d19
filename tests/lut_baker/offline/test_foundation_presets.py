"""Foundation presets from measured thick layers (lut_baker.offline.foundation_presets,
docs/model.md §4): the gloss per finish, the stored presets against their targets (the thick
layer of lut_baker.model.thick_layer, tested in tests/lut_baker/model/test_thick_layer.py), and
the stored preset file re-derived from the measurements."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from support import measured_presets

from lut_baker.model import presets, thick_layer
from lut_baker.model.albedo import bihemispherical, reflection_albedo
from lut_baker.model.layers import ReflectionLayer
from lut_baker.offline import foundation_presets as FP

DATA = Path(__file__).parents[3] / "data" / "lanza2024"
PRODUCTS = ("clarins_103", "clarins_105", "clarins_108", "clarins_112")


@pytest.fixture(scope="module")
def exchange():
    return thick_layer.paper_film_exchange()


def test_the_gloss_per_finish():
    layers = [ReflectionLayer(P_d=0.2, P_s=ps, n=n, eta=eta)
              for ps, n, eta in ((10.0, 0.1, 1.1), (20.0, 0.2, 1.2), (30.0, 0.3, 1.3))]
    dewy = FP.preset_gloss(layers, "dewy")
    weights = FP.LUMINANCE_WEIGHTS
    assert weights.sum() == pytest.approx(1.0)
    assert dewy == pytest.approx({"P_s": weights @ [10, 20, 30], "n": weights @ [0.1, 0.2, 0.3],
                                  "eta": weights @ [1.1, 1.2, 1.3]}, rel=1e-14)
    film = presets.paper().film
    assert FP.preset_gloss(layers, "matte") == {"P_s": 0.0, "n": float(film.n),
                                                "eta": float(film.eta)}
    with pytest.raises(ValueError, match="finish"):
        FP.preset_gloss(layers, "satin")
    with pytest.raises(ValueError, match="three"):
        FP.derive_preset("x_1", "matte", layers[:2])


def test_the_stored_presets_reproduce_their_targets(exchange):
    """The thick-layer limit of each stored preset's film reflects its target per channel
    (to 1e-6) unless clamped, where the target lies above the lossless stack."""
    stored = FP.read_presets()
    assert tuple(stored) == PRODUCTS
    for name, entry in stored.items():
        absorption = np.array(entry["absorption"])
        stack = thick_layer.stack_reflectance(absorption, exchange)
        target = np.array(entry["target"])
        clamped = np.array(entry["clamped"])
        np.testing.assert_allclose(stack, entry["stack"], rtol=1e-12)
        np.testing.assert_allclose(stack[~clamped], target[~clamped], rtol=0, atol=1e-6)
        assert np.all(target[clamped] > thick_layer.stack_reflectance(0.0, exchange))
        assert np.all(absorption[clamped] == 0.0)
        assert np.all((absorption >= 0) & (absorption <= 1))
        assert presets.FOUNDATIONS[name]["absorption"] == tuple(absorption)
    # Only 105's red exceeds what the paper's film can reflect stacked.
    assert [n for n, e in stored.items() if any(e["clamped"])] == ["clarins_105"]


TOLERANCE = 1e-6
"""A shipped preset value may move by this much (relative; absolute where it is 0) between
derivations: machines, thread counts, 1e-9 perturbations of the measurements.  They move by
about 1e-9 (the fits are polished to their optimum; tests/support/measured_presets.py)."""


@pytest.mark.slow  # four products fitted in their well-posed forms and derived (~60 s)
def test_the_stored_presets_are_rederived_from_the_measurements():
    from lut_baker.offline.foundations import PRODUCTS as FILES
    from lut_baker.offline.measured.inplane import read_inplane
    from lut_baker.offline.measured.inplane_fit import well_posed

    fits = {}
    for name, (filename, finish) in FILES.items():
        data = read_inplane(DATA / filename)
        layers = well_posed(data.theta_i_deg, data.theta_o_deg, data.rgb).fit.layers
        fits[name] = (finish, layers)
    derived = FP.derive_presets(fits)
    move, where = measured_presets.largest_move(derived, FP.read_presets())
    assert move < TOLERANCE, where
    for name, entry in derived.items():
        # The target is the fitted layers' reflectance under uniform light.
        layers = fits[name][1]
        assert entry["target"][1] == pytest.approx(float(bihemispherical(
            lambda t, layer=layers[1]: reflection_albedo(t, layer))), rel=1e-12)
        # Matte: a fit without lobe, whose target is pi P_d; dewy: a lobe in every channel.
        lobes = [float(layer.P_s) > 0.0 for layer in layers]
        assert lobes == [entry["finish"] == "dewy"] * 3, name
        if entry["finish"] == "matte":
            np.testing.assert_allclose(entry["target"], [np.pi * float(layer.P_d)
                                                         for layer in layers], rtol=1e-12)


def _variant(environment: dict, perturbation: float = 0.0) -> subprocess.Popen:
    """``python -m support.measured_presets`` in a subprocess with ``environment`` added."""
    root = Path(__file__).parents[3]
    env = {**os.environ, **environment,
           "PYTHONPATH": os.pathsep.join([str(root), str(root / "tests")])}
    return subprocess.Popen([sys.executable, "-m", "support.measured_presets",
                             repr(perturbation)], cwd=root, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


ONE_THREAD = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"}
TWO_THREADS = {"OMP_NUM_THREADS": "2", "OPENBLAS_NUM_THREADS": "2"}
WITHOUT_AVX512 = {**ONE_THREAD, "OPENBLAS_CORETYPE": "Haswell",
                  "NPY_DISABLE_CPU_FEATURES": "AVX512F AVX512CD AVX512_SKX AVX512_CLX "
                                              "AVX512_CNL AVX512_ICL AVX512VL AVX512BW "
                                              "AVX512DQ"}


@pytest.mark.slow  # four derivations in subprocesses, two at a time (~2-3 min)
def test_the_stored_presets_are_determined_by_their_data():
    """The shipped presets move by less than 1e-6 when the measurements move by 1e-9 (a fixed
    +-1 pattern), with one or two BLAS threads, and, where this CPU has AVX-512, without it
    (numpy's and OpenBLAS's AVX2 kernels: the last bits of sums differ)."""
    variants = {"measurements x (1 +- 1e-9)": (ONE_THREAD, 1e-9), "1 thread": (ONE_THREAD, 0.0),
                "2 threads": (TWO_THREADS, 0.0)}
    has_avx512 = bool(np.core._multiarray_umath.__cpu_features__.get("AVX512F"))
    if has_avx512:
        variants["without AVX-512"] = (WITHOUT_AVX512, 0.0)
    stored = FP.read_presets()
    names = list(variants)
    results = {}
    for pair in (names[:2], names[2:]):
        running = {name: _variant(*variants[name]) for name in pair}
        for name, process in running.items():
            out, err = process.communicate(timeout=900)
            assert process.returncode == 0, err
            results[name] = json.loads(out)
    for name, result in results.items():
        move, where = measured_presets.largest_move(result["presets"], stored)
        print(f"{name}: largest move {move:.2g} ({where})")
        assert move < TOLERANCE, (name, move, where)
    if has_avx512:  # the emulation took effect
        assert not results["without AVX-512"]["avx512f"] and results["1 thread"]["avx512f"]


def test_write_and_read_round_trip(tmp_path):
    entries = FP.read_presets()
    path = FP.write_presets(entries, tmp_path / "p.json")
    assert FP.read_presets(path) == entries


def _fit(n=0.15, relative_n=0.03, warnings=(), free=("P_d", "P_s", "n", "eta")):
    from types import SimpleNamespace

    return SimpleNamespace(free=free, warnings=list(warnings),
                           params=ReflectionLayer(P_d=0.2, P_s=50.0, n=n, eta=1.1),
                           relative_stderr={"n": relative_n})


def test_auto_finish_asks_for_a_determined_lobe_in_every_channel():
    assert FP.auto_finish([_fit(), _fit(), _fit()])[0] == "dewy"
    assert FP.lobe_determined(_fit(relative_n=FP.LOBE_STDERR_LIMIT))[0]
    bound = _fit(n=1e-4, relative_n=0.01,
                 warnings=["n ended at its bound (0.0001): the data do not determine it"])
    for odd, why in ((_fit(relative_n=0.15), "standard error of 15%"),
                     (_fit(relative_n=float("nan")), "standard error of nan%"),
                     (bound, "n ended at its bound"),
                     (_fit(free=("P_d", "P_s", "eta")), "n was not fitted")):
        finish, reason = FP.auto_finish([_fit(), odd, _fit()])
        assert finish == "matte" and why in reason.split("; ")[1]
