"""The made-up skin model: the layer types and their formulas (paper eqs. 1-6), the made-up
skin with its normalisation and its one mixing rule, the presets and the parameter files.
Described in docs/model.md."""
