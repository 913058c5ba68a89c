"""The data's own verdict: how a follower's speed responds to its predecessor's, without a model.

* **Empirical transfer** Ĝ(ω) = P_xy(ω)/P_xx(ω) from the predecessor's speed x to the follower's
  speed y (Welch's averaged cross- and auto-spectra, :func:`scipy.signal.csd` and
  :func:`scipy.signal.welch`, linear detrending, Hann windows), with the magnitude-squared
  coherence C(ω) = |P_xy|²/(P_xx P_yy).  For a linear follower Ĝ estimates the speed transfer,
  which equals Γ(jω) (accelerations and speeds share it), so |Ĝ| is set beside the fitted
  model's |Γ(jω)|.  Spectra are averaged over the clean segments (weighted by their Welch
  segment counts); frequencies where C < 0.5 are noise, not dynamics, and are left out of the
  empirical peak, as are those above :data:`OMEGA_MAX`.
* **Its uncertainty**: the normalised random error of a gain estimate from n_d independent
  spectral averages, ε = √(1 − C)/(√C √(2 n_d)) (Bendat & Piersol, *Random Data*, 4th ed.,
  eq 9.90), with n_d counted conservatively as non-overlapping segments; the data say
  "amplifies" where |Ĝ|(1 − 2ε) > 1 at a coherent frequency, "does not amplify" where
  |Ĝ|(1 + 2ε) ≤ 1.05 at every coherent frequency (Γ(0) = 1, so the lowest frequencies sit at
  |Ĝ| ≈ 1 for any car: :data:`AMPLIFY_TOLERANCE`), and are undecided otherwise.
* **Peak-to-peak amplification**: the follower's speed range over the predecessor's, on the
  samples used.
* **Energy amplification**: √(∫ ω² S_ff / ∫ ω² S_pp) over 0 < ω ≤ :data:`OMEGA_MAX`, the
  acceleration energy ratio of follower to predecessor (the square root of the IDL paper's m_p,
  eq 29, on measured data) in the band where the spectra describe the cars, not the GPS noise
  (differencing raw 10 Hz speeds would be dominated by that noise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from ..io.platoon_logs import Segment

__all__ = ["COHERENCE_MIN", "Empirical", "empirical_transfer"]

Array = npt.NDArray[np.float64]

#: Coherence below which a frequency is not used for the empirical peak.
COHERENCE_MIN = 0.5
#: Γ(0) = 1 for every follower that keeps its spacing policy, so the lowest resolved frequencies
#: sit at |Ĝ| ≈ 1 whatever the car: "does not amplify" means no coherent |Ĝ|(1 + 2ε) above
#: 1 + this tolerance.
AMPLIFY_TOLERANCE = 0.05

#: Highest frequency of the empirical peak, rad/s.  On the OpenACC logs |Ĝ| sits near 1 with
#: coherence near 1 from ~1 rad/s up to the Nyquist frequency, where any plausible lag would
#: attenuate a car's response by 10-100x: the GPS speed errors of receivers a few metres apart
#: are common-mode, so that band measures the sensors, not the cars.  String instability of car
#: following peaks well below it (the fitted peaks: 0.1-0.6 rad/s).
OMEGA_MAX = 1.0


@dataclass
class Empirical:
    """The empirical transfer of one follower.

    Attributes
    ----------
    omega : array
        Frequencies, rad/s.
    transfer : complex array
        Ĝ(jω), follower speed over predecessor speed.
    coherence : array
        C(ω) in [0, 1].
    gain : float
        max |Ĝ| where C ≥ :data:`COHERENCE_MIN` (NaN if nowhere).
    gain_omega : float
        Its frequency, rad/s.
    peak_to_peak, energy : float
        Peak-to-peak speed and acceleration-energy amplification (module docstring).
    nperseg : int
        Welch segment length, samples.
    gain_error : float
        ε at the peak (module docstring).
    amplifies : str
        ``"yes"``, ``"no"`` or ``"undecided"`` (module docstring).
    error : array or None
        ε at every frequency (the normalised random error of |Ĝ|, module docstring; NaN or inf
        where the coherence is 0), for error bars.
    """

    omega: Array
    transfer: npt.NDArray[np.complex128]
    coherence: Array
    gain: float
    gain_omega: float
    peak_to_peak: float
    energy: float
    nperseg: int
    gain_error: float = math.nan
    amplifies: str = "undecided"
    error: Array | None = None


def empirical_transfer(v_pred: Array, v: Array, segments: tuple[Segment, ...] | list[Segment], dt: float,
                       *, nperseg: int | None = None) -> Empirical:
    """Welch estimate of the predecessor-speed → follower-speed transfer and the amplifications.

    Parameters
    ----------
    v_pred, v : array (T,)
        Predecessor's and follower's speeds, m/s.
    segments : sequence of Segment
        Clean segments (spectra are computed within each, never across a gap).
    dt : float
        Step, s.
    nperseg : int, optional
        Welch segment length; default the power of two nearest to 60 s, at most the shortest
        segment.

    Returns
    -------
    Empirical
    """
    from scipy.signal import csd, welch

    shortest = min(len(s) for s in segments)
    n = nperseg or int(2 ** round(math.log2(max(60.0 / dt, 16))))
    n = max(min(n, shortest), 16)
    fs = 1.0 / dt
    pxx = pyy = 0.0
    pxy: complex | npt.NDArray[np.complex128] = 0.0
    f: Array = np.zeros(1)
    wsum = 0.0
    for s in segments:
        x = v_pred[s.start:s.stop]
        y = v[s.start:s.stop]
        if x.size < n:
            continue
        k = 1 + (x.size - n) // (n // 2)  # Welch segments in this piece
        f, sxx = welch(x, fs=fs, nperseg=n, detrend="linear")
        _, syy = welch(y, fs=fs, nperseg=n, detrend="linear")
        _, sxy = csd(x, y, fs=fs, nperseg=n, detrend="linear")
        pxx = pxx + k * sxx
        pyy = pyy + k * syy
        pxy = pxy + k * sxy
        wsum += k
    omega = 2 * np.pi * np.asarray(f)
    with np.errstate(divide="ignore", invalid="ignore"):
        G = np.asarray(pxy / pxx, dtype=np.complex128)
        C = np.asarray(np.abs(pxy) ** 2 / (pxx * pyy), dtype=float)
    C = np.nan_to_num(C, nan=0.0)
    n_d = max(sum(len(s) for s in segments if len(s) >= n) / n, 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        eps = np.sqrt(np.clip(1 - C, 0, None)) / (np.sqrt(C) * math.sqrt(2 * n_d))
    good = (C >= COHERENCE_MIN) & (omega > 0) & (omega <= OMEGA_MAX) & np.isfinite(np.abs(G))
    amplifies = "undecided"
    if good.any():
        i = int(np.flatnonzero(good)[np.argmax(np.abs(G[good]))])
        gain, gw, err = float(abs(G[i])), float(omega[i]), float(eps[i])
        mag = np.abs(G[good])
        if (mag * (1 - 2 * eps[good]) > 1).any():
            amplifies = "yes"
        elif (mag * (1 + 2 * eps[good]) <= 1 + AMPLIFY_TOLERANCE).all():
            amplifies = "no"
    else:
        gain, gw, err = math.nan, math.nan, math.nan
    xs = np.concatenate([v_pred[s.start:s.stop] for s in segments])
    ys = np.concatenate([v[s.start:s.stop] for s in segments])
    p2p = float(np.ptp(ys) / np.ptp(xs)) if np.ptp(xs) > 0 else math.nan
    band = (omega > 0) & (omega <= OMEGA_MAX)
    ex = float(np.sum(omega[band] ** 2 * np.asarray(pxx)[band]))
    ey = float(np.sum(omega[band] ** 2 * np.asarray(pyy)[band]))
    energy = math.sqrt(ey / ex) if ex > 0 else math.nan
    return Empirical(omega, G, C, gain, gw, p2p, energy, n, err, amplifies, np.asarray(eps, dtype=float))
