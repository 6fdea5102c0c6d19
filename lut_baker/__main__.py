"""``python -m lut_baker``: the headless command line (see :mod:`lut_baker.cli`)."""

import sys

from .cli import main

sys.exit(main())
