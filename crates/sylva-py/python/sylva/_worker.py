"""A local island worker: ``python -m sylva._worker`` (started by :func:`sylva.islands`)."""

import signal

# Ctrl-C is the driver's (it ends its workers): ignored from the start, so a worker still
# importing Sylva prints no traceback either.
signal.signal(signal.SIGINT, signal.SIG_IGN)

from sylva.islands import _serve  # noqa: E402

if __name__ == "__main__":
    _serve()
