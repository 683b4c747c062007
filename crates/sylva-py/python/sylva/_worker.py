"""A local island worker: ``python -m sylva._worker`` (started by :func:`sylva.islands`)."""

from sylva.islands import _serve

if __name__ == "__main__":
    _serve()
