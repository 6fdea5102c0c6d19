"""``python -m lut_baker``: the headless command line (see :mod:`lut_baker.offline.cli.main`).

SIGINT or SIGTERM at any moment from this module's first line on ends the process with one line,
``interrupted``, and exit code 128 + the signal number, never a traceback.  Both are held back
(where the system can) while the command line's module is imported, and
:func:`~lut_baker.offline.cli.main.command_line` installs its handlers and lets them through
before numpy, scipy or a command's module is imported.  (Before this module runs Python itself
is starting up, and a signal then is Python's business.)
"""

import sys

try:
    import signal

    if hasattr(signal, "pthread_sigmask"):  # released by command_line once its handlers are in
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    from .offline.cli.main import command_line
except KeyboardInterrupt:  # SIGINT before it could be held back: Python's own handler raised it
    print("interrupted", file=sys.stderr)
    sys.exit(130)  # 128 + SIGINT
sys.exit(command_line())
