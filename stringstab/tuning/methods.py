"""The repair methods by name: :func:`tune` dispatches to region growing or the projection."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..params import Box, parameter_model
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
    tau: Any,
    delta: Any,
    headway: Any,
    sample_time: float | None = None,
    reaction_delay: Any = 0.0,
    **options: Any,
) -> TuneResult:
    """Repair K0 with ``method`` (``"region-growing"`` or ``"projection"``).

    The projection repairs for any loop (``sample_time``, intervals for τ, δ, T*); region
    growing's candidate test is the Taylor Proposition 1 of the continuous loop at one
    τ, δ, T*, so it takes neither.

    Parameters
    ----------
    K0 : sequence of 3 floats or ndarray
        The gains to repair, (k_x [1/s²], k_v [1/s], k_a [-]) of IDL eq 4.
    method : {"projection", "region-growing"}
        :func:`stringstab.tuning.project` (nearest certified gains, any loop) or
        :func:`stringstab.tuning.region_growing` (the IDL paper's §3.3 search).
    tau : float or (lo, hi)
        Actuator lag τ of the follower (IDL eq 7), in s; an interval only for the projection.
    delta : float or (lo, hi)
        Communication delay δ on a_{i−1} (IDL eq 4), in s; an interval only for the projection.
    headway : float or (lo, hi)
        Desired time headway T* (IDL eq 3), in s; an interval only for the projection.
    sample_time : float, optional
        Sampling period H of the sampled-data loop, in s (projection only); None for the
        continuous loop.
    reaction_delay : float
        Reaction delay θ_r ≥ 0 on the whole command, in s (projection only; issue 25).
    **options
        Passed on to the method (for instance ``weights``, ``bounds``; ``r0``, ``grid`` for
        region growing; ``eps``, ``hurwitz_margin`` for the projection).

    Returns
    -------
    TuneResult
        The repaired gains, the exact certificate's verdict on them and the distance moved.

    Raises
    ------
    StringStabError
        On an unknown method, or region growing asked for a sampled or robust loop.

    Examples
    --------
    >>> tune([0.9, -0.5, 1.1], "projection", tau=0.1, delta=0.2, headway=1.1).certified
    True
    """
    if method == "region-growing":
        if sample_time is not None or isinstance(parameter_model(tau, delta, headway), Box):
            raise StringStabError(
                "region growing tests candidates with the Taylor Proposition 1 of the continuous "
                "loop at one τ, δ, T*; for a sample time or an interval use the projection")
        if Box.of(parameter_model(tau, delta, headway, reaction_delay)).reaction_delay[1]:
            raise StringStabError(
                "region growing tests candidates with the Taylor Proposition 1 of the loop "
                f"without reaction delay; for reaction_delay={reaction_delay!r} use the projection")
        return region_growing(K0, tau=tau, delta=delta, headway=headway, **options)
    if method == "projection":
        return project(K0, tau=tau, delta=delta, headway=headway, sample_time=sample_time,
                       reaction_delay=reaction_delay, **options)
    raise StringStabError(f"method must be one of {', '.join(METHODS)}; got {method!r}")

