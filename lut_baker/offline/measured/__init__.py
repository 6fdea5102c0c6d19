"""Measurements: the paper's protocols, measurement files (CSV), their synthesis, and the
least-squares fits of the layer parameters to them."""
