"""The layer records of lut_baker.model.layers: out-of-range parameters are refused with the
field and its range named."""

import pytest

from lut_baker.model.layers import Dipole, ReflectionLayer, TransmissionLayer


# --- validation ----------------------------------------------------------------------------
@pytest.mark.parametrize("kind, field, value, message", [
    (ReflectionLayer, "eta", 0.0, r"eta must lie in \(0, inf\)"),
    (ReflectionLayer, "eta", -1.3, r"eta must lie in \(0, inf\)"),
    (ReflectionLayer, "n", 0.0, r"n must lie in \(0, inf\)"),
    (ReflectionLayer, "P_d", -1.0, r"P_d must lie in \[0, inf\)"),
    (ReflectionLayer, "P_s", float("nan"), r"P_s must lie in \[0, inf\)"),
    (ReflectionLayer, "P_s", (1.0, -2.0, 3.0), r"P_s must lie in \[0, inf\)"),
    (ReflectionLayer, "n", float("inf"), r"n must lie in \(0, inf\)"),
    (ReflectionLayer, "P_d", (1.0, 2.0), r"P_d must be a float or an RGB triple"),
    (TransmissionLayer, "P_t", -0.5, r"P_t must lie in \[0, inf\)"),
    (TransmissionLayer, "eta", (1.2, 0.0, 1.3), r"eta must lie in \(0, inf\)"),
    (TransmissionLayer, "n", -3.0, r"n must lie in \(0, inf\)"),
])
def test_layer_validation(kind, field, value, message):
    values = {"P_d": 1.0, "n": 0.04, "eta": 1.3}
    values["P_s" if kind is ReflectionLayer else "P_t"] = 1.0
    values[field] = value
    with pytest.raises(ValueError, match=message):
        kind(**values)


@pytest.mark.parametrize("field, value, message", [
    ("sigma_s", -1.0, r"sigma_s must lie in \[0, inf\)"),
    ("sigma_a", -1e-3, r"sigma_a must lie in \[0, inf\)"),
    ("sigma_a", float("nan"), r"sigma_a must lie in \[0, inf\)"),
    ("g", 1.0, r"g must lie in \(-1, 1\)"),
    ("eta", 0.9, r"eta must lie in \[1, inf\)"),
    ("eta", 0.0, r"eta must lie in \[1, inf\)"),
])
def test_dipole_validation(field, value, message):
    values = {"sigma_s": 1.0, "sigma_a": 0.1, "g": 0.0, "eta": 1.3}
    values[field] = value
    with pytest.raises(ValueError, match=message):
        Dipole(**values)
    with pytest.raises(ValueError, match=r"sigma_s \* \(1 - g\) \+ sigma_a must be > 0"):
        Dipole(sigma_s=0.0, sigma_a=0.0)
