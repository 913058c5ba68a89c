"""Car-following controllers: the IDL linear law (eq 4), time-varying gains, CACC and IDM.

Every controller maps an :class:`Observation` of a batch of followers (arrays of any common
shape, typically ``(n_platoons, n_followers)``) to desired accelerations u (m/s²).  The
simulator (:mod:`stringstab.traffic.platoon`) then limits u to the acceleration bounds and
passes it through the vehicle's actuator lag.  One module per controller; every public name
is re-exported here:

* :mod:`~stringstab.traffic.controllers.base` — :class:`Observation` and the
  :class:`Controller` interface;
* :mod:`~stringstab.traffic.controllers.linear` — :func:`linear_law` and
  :class:`LinearController`, the IDL paper's eq 4, u = k_x Δp + k_v Δv + k_a a_{i−1}(t − δ)
  with Δp = gap − (T* v + l_0) (eq 3);
* :mod:`~stringstab.traffic.controllers.time_varying` — :class:`TimeVaryingLinearController`,
  the same law with gains that change over time, from a schedule array, a CSV file or a
  policy callable (the IDL agent outputs K each step, eq 17);
* :mod:`~stringstab.traffic.controllers.cacc` — :class:`CACCController`, the CACC of van Arem,
  van Driel & Visser (2006), the IDL paper's model-based baseline (§4.1.4), with the
  predecessor's acceleration received δ late;
* :mod:`~stringstab.traffic.controllers.idm` — :class:`IDMController`, the Intelligent Driver
  Model (Treiber, Hennecke & Helbing 2000), a stand-in for human-driven followers;
* :mod:`~stringstab.traffic.controllers.function` — :class:`FunctionController`, any callable
  (e.g. a pure-RL acceleration policy);
* :mod:`~stringstab.traffic.controllers.mixed` — :class:`MixedController`, different
  controllers at different positions of the platoon.

References
----------
.. [IDL] Z. Yi, M. Xu, S. Wang, Transportation Research Part C 184 (2026) 105541, eqs 3-4, 17.
.. [Arem2006] B. van Arem, C. J. G. van Driel, R. Visser, "The impact of cooperative adaptive
   cruise control on traffic-flow characteristics", IEEE Trans. ITS 7(4) (2006) 429-436.
.. [IDM] M. Treiber, A. Hennecke, D. Helbing, "Congested traffic states in empirical
   observations and microscopic simulations", Phys. Rev. E 62 (2000) 1805-1824.
"""

from __future__ import annotations

from .base import DEFAULT_STANDSTILL, Controller, Observation
from .cacc import CACCController
from .function import FunctionController
from .idm import IDMController
from .linear import LinearController, linear_law
from .mixed import MixedController
from .time_varying import TimeVaryingLinearController

__all__ = [
    "DEFAULT_STANDSTILL",
    "CACCController",
    "Controller",
    "FunctionController",
    "IDMController",
    "LinearController",
    "MixedController",
    "Observation",
    "TimeVaryingLinearController",
    "linear_law",
]
