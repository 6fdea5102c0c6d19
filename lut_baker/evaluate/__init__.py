"""The exact evaluator: the two-layer model of the paper's section 3 summed by quadrature, and
the made-up skin's reflection and albedos built on it (docs/model.md §3)."""
