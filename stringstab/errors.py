"""The project's one exception type.

Every error raised on bad input is a :class:`StringStabError`, a subclass of
:class:`ValueError`, whose message says what was expected and what was found.
The command-line interface turns it into a one-line message and exit code 2.
"""

from __future__ import annotations

__all__ = ["StringStabError"]


class StringStabError(ValueError):
    """Bad input or an undecidable request: what was expected, and what was found.

    Examples
    --------
    >>> raise StringStabError("tau must be > 0 s; got -0.1")
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: tau must be > 0 s; got -0.1
    """
