"""Helpers shared by the tests, the benchmarks (bench/) and the development scripts (tools/).

Tests import them as ``from support import ...`` (pytest puts ``tests`` on ``sys.path``, see
pyproject.toml); the scripts put ``tests`` on ``sys.path`` themselves.  Nothing here changes
``sys.path``, and no module imports ``bpy`` at module level: bpy is imported inside the
functions that need it, after the caller has set ``BLENDER_USER_RESOURCES``.

- :mod:`support.reference_impl` -- an independent implementation of the model's formulas
  (docs/model.md §2-§4), written without ``lut_baker``.
- :mod:`support.quantities` -- results as named quantities, and how far one moved.
- :mod:`support.golden_values` -- the golden set, its stored reference
  (``tests/data/golden_values.npz``, ``.json``) and the tolerance of each quantity.
- :mod:`support.perturbation` -- inputs perturbed by 1e-9 relative, and what moved.
- :mod:`support.fit_audit` -- the run-time fits audited: their movement under perturbation,
  the margins of their discrete choices and of the Auto tier's.
- :mod:`support.sphere_scene` -- the reference sphere scene (camera, sun, black world, Cycles
  settings), the add-on registered for a ``with`` block, made-up materials, renders.
- :mod:`support.bench_scene` -- that scene made to match
  :func:`lut_baker.offline.validation.reference.sphere_image` pixel for pixel, and a
  :class:`~support.bench_scene.Stage` built once and changed between renders.
- :mod:`support.character` -- an artist's textured head (albedo texture, pore normal map).
- :mod:`support.panel_layout` -- a stand-in ``UILayout`` that records what a panel draws.
- :mod:`support.subsurface_edge` -- Cycles' subsurface blur of a shadow edge, and its replica.
- :mod:`support.process_exit` -- a script that imports bpy run in its own process, which must
  end.
"""
