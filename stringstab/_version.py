"""The package's one version string (``pyproject.toml`` reads it here; ``stringstab`` re-exports it).

It lives in a module of its own, below every layer, so that the layers that record the version
(the output manifests, the region files, the saved policies, the CLI's ``--version``) read it
without importing the package ``__init__`` that re-exports them.
"""

__version__ = "0.1.0"
