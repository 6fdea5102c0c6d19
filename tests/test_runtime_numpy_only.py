"""The run-time path inside Blender (presets -> bake -> closure fit -> table I/O) needs numpy
only: Blender's bundled Python has no scipy.  Checked in a subprocess where importing scipy
fails."""

import subprocess
import sys
import textwrap
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_bake_and_closure_fit_run_without_scipy():
    script = textwrap.dedent("""
        import sys
        sys.modules["scipy"] = None  # any 'import scipy...' now raises ImportError
        from lut_baker import bake
        from lut_baker.closures import fitting
        from lut_baker.model import presets
        tables = bake.bake(presets.made_up_skin("medium_beige", "jensen_skin1"), "preview")
        fitting.fit_closures(tables)
        print("ok", presets.paper().K)
    """)
    done = subprocess.run([sys.executable, "-c", script], cwd=ROOT, capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.startswith("ok")
