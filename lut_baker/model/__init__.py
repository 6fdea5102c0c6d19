"""The made-up skin model: the layer types (``layers``) and their formulas (``microfacet``: paper
eqs. 2, 4; ``dipole``: eqs. 5, 6), the made-up skin with its normalisation and its one mixing
rule (``made_up_skin``), the presets and the parameter files.  Described in docs/model.md."""
