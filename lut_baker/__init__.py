"""lut_baker: the made-up skin model (Baba, Mukaigawa, Yagi), evaluated exactly, fitted and
baked into lookup tables.  Nothing here knows about Blender.

Runtime (numpy only, shipped inside the extension), lowest layer first -- a module imports only
from its own layer or those below it:

- :mod:`.numerics` -- quadrature, geometry, optimisation;
- :mod:`.model` -- the layers, their formulas, the made-up skin, presets, parameter files;
- :mod:`.evaluate` -- the exact two-layer evaluator;
- :mod:`.tables` -- the baked table set and its codec;
- :mod:`.bake` -- the bake;
- :mod:`.closures` -- Cycles' closures and the two tiers fitted to the tables;
- :mod:`.auto_tier` -- the Auto tier: the cheapest tier a scene needs.

Offline (:mod:`.offline`, may use scipy, matplotlib, OpenImageIO; never shipped): validation,
measurements and their fits, the paper's figures, the command line.  ``tools/check_imports.py``
enforces these rules.
"""

__version__ = "0.1.0"
