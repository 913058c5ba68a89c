"""The HCFS CACC law (eq 11): what was printed, what was meant, and the acceleration law used.

Printed (HCFS eq 11)
    a_k = v_k_last + k1 e_x(k,k−1) + k2 e_v(k,k−1) + k3 e_x(k,0) + k4 e_v(k,0),

    "where v_k_last is the velocity of the kth vehicle at the last frame" and k1-k4 > 0.  This
    adds a speed (m/s) to an acceleration (m/s²): it cannot be an acceleration law as written.

What was meant
    The paper takes its CACC "similar to [4] and [5]"; [4] is the California PATH CACC
    (Milanés et al., IEEE T-ITS 2014), whose controller is a *speed reference* updated every
    frame, v_ref = v_last + k_p e + k_d ė.  Eq 11 has exactly this form: its right-hand side is
    the speed the vehicle should have one frame later.  Under the paper's own kinematics
    (§IV, v_{k+1} = v_k + a_k T) reaching that speed in one frame takes

        a_k = (v_ref − v_k) / T = (k1 ε_x + k2 ε_v + k3 ε_x0 + k4 ε_v0) / T,

    with v_k_last = v_k, the latest measured speed.  (Reading v_k_last as the speed one frame
    before that would give a_k = −a_{k−1} + (…)/T, a law that alternates sign every frame.)

Signs
    With the eq-1/eq-2 deviations (ego minus predecessor: e_x > 0 too close, e_v > 0 closing
    in) and k1-k4 > 0, eq 11 would *accelerate* when too close and closing in: the closed loop
    is unstable (spectral radius 1.67 for 8 followers at the default gains, against 0.947 for
    the law below; :func:`closed_loop_matrix`).  The errors in eq 11 must be predecessor minus
    ego, ε = −e, i.e. the law uses the negated eq-3 deviations:

        a_k = −(k1 e_x(k,k−1) + k2 e_v(k,k−1) + k3 e_x(k,0) + k4 e_v(k,0)) / T.

:func:`cacc_printed` keeps the printed form as a reference; :class:`CACC` is the law used.

References
----------
HCFS paper, §III-B eq 11.  V. Milanés, S. E. Shladover et al., "Cooperative adaptive cruise
control in real traffic situations", IEEE T-ITS 15(1) (2014) 296-305 (ref. [4] of HCFS).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from .constants import CACC_GAINS, DT

__all__ = ["CACC", "cacc_acceleration", "cacc_printed", "closed_loop_matrix"]

Array = npt.NDArray[np.float64]


def _gains(gains: Sequence[float]) -> tuple[float, float, float, float]:
    k = tuple(float(g) for g in gains)
    if len(k) != 4 or not all(np.isfinite(k)):
        raise StringStabError(f"CACC gains must be four finite numbers k1, k2, k3, k4; got {gains!r}")
    return k  # type: ignore[return-value]


def _state(state: npt.ArrayLike) -> Array:
    s = np.asarray(state, dtype=np.float64)
    if s.ndim < 1 or s.shape[-1] != 6:
        raise StringStabError(f"the HCFS state (eq 3) has 6 components per vehicle; got shape {s.shape}")
    return s


def cacc_acceleration(state: npt.ArrayLike, gains: Sequence[float] = CACC_GAINS, *,
                      dt: float = DT) -> Array:
    """The derived eq-11 law: a = −(k1 e_x + k2 e_v + k3 e_x0 + k4 e_v0) / T (no limits).

    Parameters
    ----------
    state : array_like (..., 6)
        The eq-3 state (:func:`stringstab.hcfs.mdp.state`).
    gains : (k1, k2, k3, k4)
        Gains of eq 11 (k1, k3 in 1/s; k2, k4 dimensionless).
    dt : float
        T, s.

    Returns
    -------
    array (...)
        Desired accelerations, m/s².

    References
    ----------
    HCFS paper, eq 11 (see the module docstring for the derivation).

    Examples
    --------
    >>> float(cacc_acceleration([1.0, 0.0, 0.0, 0.0, 10.0, 0.0], (0.1, 0.4, 0.05, 0.2), dt=0.2))
    -0.5
    """
    s = _state(state)
    k1, k2, k3, k4 = _gains(gains)
    return np.asarray(-(k1 * s[..., 0] + k2 * s[..., 1] + k3 * s[..., 2] + k4 * s[..., 3]) / dt)


def cacc_printed(state: npt.ArrayLike, gains: Sequence[float] = CACC_GAINS) -> Array:
    """Eq 11 exactly as printed: v_k_last + k1 e_x + k2 e_v + k3 e_x0 + k4 e_v0 (a reference only).

    Its value is a speed (m/s), the speed reference of the PATH CACC, not an acceleration.

    Parameters
    ----------
    state : array_like (..., 6)
        The eq-3 state [e_x(k,k−1), e_v(k,k−1), e_x(k,0), e_v(k,0), v_k, a_k]
        (:func:`stringstab.hcfs.mdp.state`); v_k (m/s) is read as v_k_last.
    gains : (k1, k2, k3, k4)
        Gains of eq 11 (k1, k3 in 1/s; k2, k4 dimensionless).

    Returns
    -------
    array (...)
        The printed right-hand side of eq 11, m/s (with the printed signs).

    Raises
    ------
    StringStabError
        If the state does not have 6 components or the gains are not four finite numbers.

    References
    ----------
    HCFS paper, eq 11.

    Examples
    --------
    >>> float(cacc_printed([1.0, 0.0, 0.0, 0.0, 10.0, 0.0], (0.1, 0.4, 0.05, 0.2)))
    10.1
    """
    s = _state(state)
    k1, k2, k3, k4 = _gains(gains)
    return np.asarray(s[..., 4] + k1 * s[..., 0] + k2 * s[..., 1] + k3 * s[..., 2] + k4 * s[..., 3])


def closed_loop_matrix(n_followers: int, gains: Sequence[float] = CACC_GAINS, *, dt: float = DT,
                       sign: float = 1.0) -> Array:
    """The discrete closed loop of N followers under the eq-11 law, about a constant-speed leader.

    State (positions relative to the desired ones, speeds relative to the leader's) of the
    N followers, stacked [x_1 … x_N, v_1 … v_N]; one frame of the §IV kinematics
    (x⁺ = x + v T + ½ a T², v⁺ = v + a T) with a = ``sign`` · (derived law), no delay, no
    limits.  ``sign=-1`` is the printed sign convention (positive gains on the ego-minus-
    predecessor deviations of eqs 1-2).

    Parameters
    ----------
    n_followers : int
        N ≥ 1.
    gains : (k1, k2, k3, k4)
        Gains of eq 11 (k1, k3 in 1/s; k2, k4 dimensionless).
    dt : float
        Frame length T, s.
    sign : float
        1 for the derived law (:func:`cacc_acceleration`), −1 for the printed signs.

    Returns
    -------
    array (2N, 2N)
        The linear map; the loop is internally stable iff its spectral radius is < 1.

    Raises
    ------
    StringStabError
        If N < 1 or the gains are not four finite numbers.

    Examples
    --------
    >>> rho = lambda A: float(max(abs(np.linalg.eigvals(A))))
    >>> round(rho(closed_loop_matrix(8)), 3), round(rho(closed_loop_matrix(8, sign=-1)), 3)
    (0.947, 1.665)
    """
    n = int(n_followers)
    if n < 1:
        raise StringStabError(f"n_followers must be >= 1; got {n_followers!r}")
    k1, k2, k3, k4 = _gains(gains)
    # deviations ego minus predecessor / leader: e_x = x_i − x_{i−1}, e_v = v_i − v_{i−1}
    D = np.eye(n) - np.eye(n, k=-1)  # row i: x_i − x_{i−1} (x_0 = 0 for the leader)
    E = np.eye(n)  # x_i − x_0
    Kx = -(k1 * D + k3 * E) / dt * sign
    Kv = -(k2 * D + k4 * E) / dt * sign
    eye = np.eye(n)
    top = np.hstack([eye + 0.5 * dt * dt * Kx, dt * eye + 0.5 * dt * dt * Kv])
    bottom = np.hstack([dt * Kx, eye + dt * Kv])
    return np.asarray(np.vstack([top, bottom]))


class CACC:
    """The eq-11 CACC as an acceleration policy on the eq-3 state (see the module docstring).

    Satisfies :class:`stringstab.hcfs.policy.AccelerationPolicy`.

    Parameters
    ----------
    gains : (k1, k2, k3, k4)
        Gains of eq 11 (default :data:`~stringstab.hcfs.constants.CACC_GAINS`).
    dt : float
        T, s.

    Examples
    --------
    >>> CACC()(np.zeros((2, 6))).tolist()
    [0.0, 0.0]
    """

    def __init__(self, gains: Sequence[float] = CACC_GAINS, *, dt: float = DT) -> None:
        self.gains = _gains(gains)
        self.dt = float(dt)
        self.label = f"CACC (eq 11, derived form, k1-k4 = {', '.join(f'{g:g}' for g in self.gains)})"

    def __call__(self, state: npt.ArrayLike) -> Array:
        """The eq-11 accelerations of a batch of states (:func:`cacc_acceleration`, no limits).

        Parameters
        ----------
        state : array_like (..., 6)
            The eq-3 state (:func:`stringstab.hcfs.mdp.state`), SI units.

        Returns
        -------
        array (...)
            Desired accelerations, m/s².
        """
        return cacc_acceleration(state, self.gains, dt=self.dt)
