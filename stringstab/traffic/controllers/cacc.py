"""The CACC of van Arem, van Driel & Visser (2006): :class:`CACCController`, the IDL baseline.

The IDL paper's model-based baseline (§4.1.4), with the predecessor's acceleration received
δ late.

References
----------
.. [Arem2006] B. van Arem, C. J. G. van Driel, R. Visser, "The impact of cooperative adaptive
   cruise control on traffic-flow characteristics", IEEE Trans. ITS 7(4) (2006) 429-436.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt

from ...constants import SPEED_MAX
from ...params import DEFAULT_HEADWAY, positive
from .base import DEFAULT_STANDSTILL, Controller, Observation

__all__ = ["CACCController"]

Array = npt.NDArray[np.float64]


class CACCController(Controller):
    """The CACC of van Arem et al. (2006), the IDL paper's model-based baseline (§4.1.4).

    u = min(a_v, a_d), a_v = k (v_int − v),
    a_d = k_a a_{i−1}(t − δ) + k_v (v_{i−1} − v) + k_d (gap − r_ref),
    r_ref = max(r_min, t_system v).

    Their safe distance r_safe = v²/2 (1/d_{i−1} − 1/d_i) vanishes for equal braking
    capabilities and is omitted.  As in the IDL paper, the predecessor's acceleration arrives δ
    late.  In car following (a_d < a_v and t_system v > r_min) this is eq 4 with
    (k_x, k_v, k_a) = (k_d, k_v, k_a) and T* = t_system, which is what :meth:`gains` reports
    for M_fss.

    Parameters
    ----------
    k_a, k_v, k_d, k : float
        Gains; van Arem et al.'s values 1.0, 0.58 s⁻¹, 0.1 s⁻² and 0.3 s⁻¹ by default.
    t_system : float
        Time gap, s.  Van Arem et al. used 0.5 s; the default is the IDL paper's T* = 1.1 s so
        that the baseline and the IDL controller keep the same spacing policy (the IDL paper
        reports 1.44 s mean headway for its CACC, incompatible with 0.5 s).
    r_min : float
        Minimum distance, m.
    speed_intended : float
        Cruise speed v_int of the speed-control mode, m/s (IDL Table 2 v_max).

    Examples
    --------
    >>> CACCController().gains(None).tolist()
    [0.1, 0.58, 1.0]
    """

    def __init__(self, *, k_a: float = 1.0, k_v: float = 0.58, k_d: float = 0.1, k: float = 0.3,
                 t_system: float = DEFAULT_HEADWAY, r_min: float = DEFAULT_STANDSTILL,
                 speed_intended: float = SPEED_MAX) -> None:
        self.k_a, self.k_v, self.k_d, self.k = (float(k_a), float(k_v), float(k_d), float(k))
        self.t_system = positive("t_system", t_system, allow_zero=True)
        self.r_min = positive("r_min", r_min, allow_zero=True)
        self.speed_intended = float(speed_intended)
        self._K = np.array([self.k_d, self.k_v, self.k_a])

    @property
    def headway(self) -> float:
        """T* of the equivalent eq-4 law: the time gap ``t_system``, s."""
        return self.t_system

    def command(self, obs: Observation) -> Array:
        """u = min(a_v, a_d) of van Arem et al. (2006) (see the class docstring).

        Parameters
        ----------
        obs : Observation
            What every follower knows at this step.

        Returns
        -------
        array
            u, m/s²: the smaller of the speed-control and the gap-control accelerations.
        """
        r_ref = self.equilibrium_gap(obs.speed)  # max(r_min, t_system v)
        a_d = (self.k_a * obs.pred_accel_delayed + self.k_v * obs.rel_speed
               + self.k_d * (obs.gap - r_ref))
        return np.minimum(self.k * (self.speed_intended - obs.speed), a_d)

    def equilibrium_gap(self, speed: npt.ArrayLike) -> Array:
        """r_ref = max(r_min, t_system v), the gap where a_d = 0 behind an equal-speed leader.

        Parameters
        ----------
        speed : array_like
            Cruise speed v, m/s.

        Returns
        -------
        array
            The equilibrium gap, m.
        """
        return np.maximum(self.r_min, self.t_system * np.asarray(speed, dtype=np.float64))

    def gains(self, obs: Observation | None) -> Array:
        """(k_d, k_v, k_a): the eq-4 gains of the gap-control mode (with T* = t_system).

        Parameters
        ----------
        obs : Observation or None
            Ignored.

        Returns
        -------
        array (3,)
            K = (k_x, k_v, k_a) = (k_d, k_v, k_a).  It holds only in car following
            (a_d < a_v and t_system v > r_min), which is not checked.
        """
        return self._K

    def describe(self) -> dict[str, Any]:
        """A JSON-ready description of the CACC and its parameters.

        Returns
        -------
        dict
            ``controller`` (``"cacc (van Arem et al. 2006)"``), the gains ``k_a``, ``k_v``,
            ``k_d``, ``k``, ``t_system`` (s), ``r_min`` (m) and ``speed_intended`` (m/s).
        """
        return {"controller": "cacc (van Arem et al. 2006)", "k_a": self.k_a, "k_v": self.k_v,
                "k_d": self.k_d, "k": self.k, "t_system": self.t_system, "r_min": self.r_min,
                "speed_intended": self.speed_intended}
