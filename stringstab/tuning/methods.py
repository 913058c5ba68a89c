"""The repair methods by name: :func:`tune` dispatches to region growing or the projection."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from .projection import project
from .region_growing import region_growing
from .result import TuneResult

__all__ = ["METHODS", "tune"]

#: The repair methods, as named on the command line.
METHODS: tuple[str, str] = ("region-growing", "projection")


def tune(
    K0: Sequence[float] | npt.NDArray[np.float64],
    method: str = "projection",
    *,
    tau: float,
    delta: float,
    headway: float,
    **options: Any,
) -> TuneResult:
    """Repair K0 with ``method`` (``"region-growing"`` or ``"projection"``).

    Examples
    --------
    >>> tune([0.9, -0.5, 1.1], "projection", tau=0.1, delta=0.2, headway=1.1).certified
    True
    """
    if method == "region-growing":
        return region_growing(K0, tau=tau, delta=delta, headway=headway, **options)
    if method == "projection":
        return project(K0, tau=tau, delta=delta, headway=headway, **options)
    raise StringStabError(f"method must be one of {', '.join(METHODS)}; got {method!r}")

