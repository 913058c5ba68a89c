"""The toolkit's version, in a module of its own so any module can read it without importing
the package façade (:mod:`stringstab` re-exports it as ``stringstab.__version__``)."""

__version__ = "0.1.0"
