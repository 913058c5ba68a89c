"""The project's one exception type.

Every error raised on bad input is a :class:`StringStabError`, a subclass of
:class:`ValueError`, whose message says what was expected and what was found.
The command-line interface turns it into a one-line message and exit code 2.
"""

from __future__ import annotations

__all__ = ["StringStabError", "show"]


class StringStabError(ValueError):
    """Bad input or an undecidable request: what was expected, and what was found.

    Examples
    --------
    >>> raise StringStabError("tau must be > 0 s; got -0.1")
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: tau must be > 0 s; got -0.1
    """


def show(value: object) -> str:
    """``value`` as a person would write it in an error message.

    NumPy scalars print as plain numbers (NumPy 2's ``repr`` gives ``np.float64(0.5)``), strings
    keep their quotes, sequences and arrays print their elements the same way.

    Parameters
    ----------
    value : object
        The value found (a number, string, NumPy scalar or array, list or tuple).

    Returns
    -------
    str
        Its rendering for the message.

    Examples
    --------
    >>> import numpy as np
    >>> show(np.float64(0.5)), show("x"), show([np.int64(1), 2.5]), show(np.array([1.0, np.nan]))
    ('0.5', "'x'", '[1, 2.5]', '[1.0, nan]')
    """
    import numpy as np  # local: errors.py is imported by everything and stays light

    if isinstance(value, np.ndarray):
        return show(value.tolist())
    if isinstance(value, np.generic):
        return show(value.item())
    if isinstance(value, (list, tuple)):
        inner = ", ".join(show(v) for v in value)
        return f"[{inner}]" if isinstance(value, list) else f"({inner}{',' if len(value) == 1 else ''})"
    return repr(value)
