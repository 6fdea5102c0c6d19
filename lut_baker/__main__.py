"""``python -m lut_baker``: the headless command line (see :mod:`lut_baker.offline.cli.main`)."""

import sys

from .offline.cli.main import main

sys.exit(main())
