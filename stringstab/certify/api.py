"""The one way in to the certificates: :func:`certify`, :func:`certify_batch`, :func:`check`.

Whatever the caller gives — gains as numbers or arrays, τ, δ, T* as numbers, ``(lo, hi)``
pairs or ``"LO:HI"`` strings, a sample time or none — is checked and normalised here,
*once*: :meth:`Loop.of` turns τ, δ, T*, the sample time and the predecessor's lag into a
:class:`Loop` (point :class:`~stringstab.params.Params` or a :class:`~stringstab.params.Box`,
the sample time H or None) and decides which certificate answers, :attr:`Loop.kind`:

* ``"continuous"`` — point parameters, no sample time
  (:mod:`stringstab.certify.continuous`);
* ``"sampled"`` — point parameters and a sample time (:mod:`stringstab.certify.sampled`);
* ``"robust"`` — any interval, with or without a sample time (:mod:`stringstab.certify.robust`);
* ``"multirate"`` — point parameters, a sample time H and a V2V message period N·H with
  N ≥ 2 (:mod:`stringstab.certify.multirate`); N = 1 is the sampled loop, answered by the
  sampled certificate (the same loop: messages every control step).

The gains are broadcast, checked finite and within range, and flattened once
(:func:`gains`).  The kernels of the three certificates (``certify_kernel`` and
``check_kernel`` of :mod:`~stringstab.certify.continuous`, :mod:`~stringstab.certify.sampled`
and :mod:`~stringstab.certify.robust`) are then called with these arrays and checked values
and check nothing again.  The command line builds its :class:`Loop` from
the values it has already checked (with its own flag names in the messages) and asks it
directly (:meth:`Loop.certify_batch`), so a parameter is checked once on every path.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal, overload

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..params import Box, Params, as_gains, parameter_model, positive
from ..params import sample_time as checked_sample_time
from ..ranges import RANGES
from . import continuous
from .continuous import Certificate, CertificateBatch
from .verdicts import Check, one_triple

if TYPE_CHECKING:
    from collections.abc import Sequence

    from .multirate import MultirateCertificate, MultirateCertificateBatch
    from .robust import RobustCertificate, RobustCertificateBatch
    from .sampled import SampledCertificate, SampledCertificateBatch
    from .string_certificate import StringCertificate

__all__ = ["Loop", "LoopKind", "certify", "certify_batch", "certify_string", "check", "gains"]

Array = npt.NDArray[np.float64]
#: Which certificate answers: the continuous-time loop, the sampled-data loop, or a box.
LoopKind = Literal["continuous", "sampled", "robust", "multirate"]
#: The methods of :func:`certify_batch`: the exact certificate, or it plus the Padé cross-check.
METHODS = ("exact", "pade")


def gains(k_x: Any, k_v: Any, k_a: Any) -> tuple[Array, Array, Array]:
    """The gains broadcast, checked and flattened: what every kernel takes.

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains of IDL eq 4 (k_x in 1/s², k_v in 1/s, k_a dimensionless), broadcast together.

    Returns
    -------
    k_x, k_v, k_a : ndarray of float64
        One-dimensional, contiguous, finite, of one length.

    Raises
    ------
    StringStabError
        On non-numeric, non-broadcastable, non-finite or out-of-range gains
        (:func:`stringstab.params.as_gains`).
    """
    kx, kv, ka = as_gains(k_x, k_v, k_a)
    return (np.ascontiguousarray(kx, dtype=float).ravel(),
            np.ascontiguousarray(kv, dtype=float).ravel(),
            np.ascontiguousarray(ka, dtype=float).ravel())


@dataclass(frozen=True)
class Loop:
    """The loop to certify, checked: parameters, sample time, and so which certificate.

    Build it with :meth:`Loop.of` from what a caller gives (every value checked there), or
    directly from values already checked (a :class:`~stringstab.params.Params` or
    :class:`~stringstab.params.Box` is checked on construction; ``sample_time`` by
    :func:`stringstab.params.sample_time` or the command line's own check).  Construction
    refuses the combinations no certificate answers (``tau_prev`` without a sampled point
    loop, ``method="pade"`` beyond the continuous point loop), so every :class:`Loop` can be
    certified.

    Attributes
    ----------
    model : Params or Box
        τ, δ, T* (a point) or their box.
    sample_time : float or None
        The sampling period H (s) of the sampled-data loop; None for continuous time.
    tau_prev : float or None
        The predecessor's lag (s), sampled point loop only (None: τ).
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranges over the τ box independently.
    method : {"exact", "pade"}
        ``"pade"`` adds python-control's cross-check (continuous point loop only).
    message_steps, message_phase, fallback : int or None, int, (float, float) or None
        The multi-rate loop (N ≥ 2; None or 1: the sampled loop): V2V messages every N steps
        at phase φ, and the fallback (ACC) gains, default each triple's own (docs/sampled.md §9).
    """

    model: Params | Box
    sample_time: float | None = None
    tau_prev: float | None = None
    heterogeneous: bool = True
    method: str = "exact"
    message_steps: int | None = None
    message_phase: int = 0
    fallback: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        box, H = isinstance(self.model, Box), self.sample_time
        if self.tau_prev is not None and (H is None or box):
            raise StringStabError(
                "tau_prev (the predecessor's lag) is for the sampled loop at point parameters; "
                f"got it with {'a box' if box else 'sample_time=None'}")
        if self.method not in METHODS:
            raise StringStabError(f"method must be 'exact' or 'pade'; got {self.method!r}")
        if self.method == "pade" and (H is not None or box):
            raise StringStabError(
                "method='pade' (python-control's cross-check) is for the continuous loop at one "
                f"τ, δ, T*; got {'sample_time=' + repr(H) if H is not None else 'a parameter box'}")
        # -- the reaction delay θ_r (issue 25): over a box, in continuous time (item 4)
        if isinstance(self.model, Box) and self.model.reaction_delay != (0.0, 0.0) and H is not None:
            from .robust_reaction import sampled_box_refusal

            raise StringStabError(sampled_box_refusal(self.model, H))
        theta = Box.of(self.model).reaction_delay[1]
        if theta and H is not None:
            from .lifting_reaction import check_reaction_sampled

            check_reaction_sampled(theta, H)
        if theta and self.method == "pade":
            raise StringStabError(
                "method='pade' (python-control's cross-check) has no reaction delay; expected "
                f"reaction_delay=0 with it; got reaction_delay={theta:g}")
        if self.message_steps is not None or self.fallback is not None:  # issue 26
            from .message import check_message_loop

            check_message_loop(self.message_steps, H, box, self.tau_prev, self.fallback)

    @classmethod
    def of(cls, tau: Any, delta: Any, headway: Any, sample_time: Any = None,
           tau_prev: Any = None, heterogeneous: bool = True, method: str = "exact",
           reaction_delay: Any = 0.0, message_period: Any = None, message_phase: Any = None,
           fallback_gains: Any = None) -> Loop:
        """The loop a caller asks for, every value checked (the one place they are).

        Parameters
        ----------
        tau, delta, headway : float, (lo, hi) or "LO:HI"
            τ > 0, δ ≥ 0, T* ≥ 0 (s): numbers make a point, any interval a box
            (:func:`stringstab.params.parameter_model`).
        sample_time : float, optional
            H > 0 (s) for the sampled-data loop.
        tau_prev : float, optional
            The predecessor's lag (s), > 0; sampled point loop only.
        heterogeneous : bool
            Sampled box only: independent predecessor lag.
        method : {"exact", "pade"}
            The method of :func:`certify_batch`.
        reaction_delay : float
            θ_r ≥ 0 (s), the delay on the whole command (issue 25): certified in continuous
            time and with ``sample_time`` (with a message period too; not with a box and a sample time).
        message_period, message_phase, fallback_gains : optional
            The multi-rate loop, checked by :func:`stringstab.certify.message.message_schedule`.

        Returns
        -------
        Loop

        Raises
        ------
        StringStabError
            On a value out of its range or a malformed interval, or a combination no
            certificate answers.

        Examples
        --------
        >>> Loop.of(0.1, 0.2, 1.1, sample_time=0.1).kind
        'sampled'
        >>> Loop.of("0.1:0.3", 0.2, 1.1).kind
        'robust'
        >>> Loop.of(0.1, 0.2, 1.1, sample_time=0.01, message_period=0.1).kind
        'multirate'
        """
        model = parameter_model(tau, delta, headway, reaction_delay)
        H = None if sample_time is None else checked_sample_time(sample_time)
        N, phase, fb = None, 0, None
        if message_period is not None or message_phase is not None or fallback_gains is not None:
            from .message import message_schedule

            N, phase, fb = message_schedule(H, message_period, message_phase, fallback_gains)
        loop = cls(model, H, tau_prev, heterogeneous, method, N, phase, fb)
        if tau_prev is None:
            return loop
        tp = positive("tau_prev (predecessor's actuator lag)", tau_prev, unit=" s")
        return dataclasses.replace(loop, tau_prev=tp)

    @property
    def predecessor_lag(self) -> float:
        """The predecessor's lag τ_p (s) of a sampled point loop: ``tau_prev``, or τ."""
        if isinstance(self.model, Box):
            raise StringStabError("a box of parameters has no single predecessor lag")
        return self.model.tau if self.tau_prev is None else self.tau_prev

    @property
    def kind(self) -> LoopKind:
        """Which certificate answers: ``"continuous"``, ``"sampled"``, ``"robust"`` or ``"multirate"``."""
        if isinstance(self.model, Box):
            return "robust"
        if self.message_steps is not None and self.message_steps >= 2:
            return "multirate"
        return "continuous" if self.sample_time is None else "sampled"

    def certify_batch(
        self, k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike, *, pade_order: int = 5,
        progress: bool = False, chunk: int = 4096, n_grid: int | None = None,
        max_rounds: int = 30, max_intervals: int = 1024,
    ) -> (CertificateBatch | SampledCertificateBatch | RobustCertificateBatch
          | MultirateCertificateBatch):
        """Certify many gain triples on this loop (:func:`certify_batch` with a checked loop).

        Parameters
        ----------
        k_x, k_v, k_a : array_like
            Gains, broadcast together and flattened (checked here, once).
        pade_order, progress, chunk, n_grid, max_rounds, max_intervals
            As for :func:`certify_batch`.

        Returns
        -------
        CertificateBatch, SampledCertificateBatch, RobustCertificateBatch or MultirateCertificateBatch
            By :attr:`kind`.
        """
        return _certify(self, *gains(k_x, k_v, k_a), pade_order=pade_order, progress=progress,
                        chunk=chunk, n_grid=n_grid, max_rounds=max_rounds,
                        max_intervals=max_intervals)

    def check(
        self, k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike, *,
        n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
    ) -> Check:
        """The verdicts alone on this loop (:func:`check` with a checked loop).

        Parameters
        ----------
        k_x, k_v, k_a : array_like
            Gains, broadcast together and flattened (checked here, once).
        n_grid, max_rounds, max_intervals : int
            As for :func:`certify_batch`.

        Returns
        -------
        Check
            By :attr:`kind` (:class:`stringstab.certify.sampled.SampledCheck` when sampled).
        """
        return _check(self, *gains(k_x, k_v, k_a), n_grid=n_grid, max_rounds=max_rounds,
                      max_intervals=max_intervals)

    def check_rows(
        self, K: npt.NDArray[np.float64], *, n_grid: int | None = None, max_rounds: int = 30,
        max_intervals: int = 1024,
    ) -> Check:
        """:meth:`check` of the rows (k_x, k_v, k_a) of one float64 array.

        The way in of an internal caller whose rows are already finite floats (the training
        repair, :class:`stringstab.tuning.GainRepair`): one comparison of max |K| with the
        gain range (:data:`stringstab.ranges.RANGES`, false for NaN) replaces
        :func:`gains`' per-array checks; rows failing it take :meth:`check`'s way (and its
        error).  The kernel is given the same numbers, so the verdicts are :meth:`check`'s.

        Parameters
        ----------
        K : ndarray of float64, shape (n, 3)
            Gain triples of IDL eq 4.
        n_grid, max_rounds, max_intervals : int
            As for :meth:`check` (the same defaults).

        Returns
        -------
        Check
            As :meth:`check` of ``K[:, 0], K[:, 1], K[:, 2]``.
        """
        K = np.asarray(K, dtype=np.float64)
        if K.ndim != 2 or K.shape[1] != 3:
            raise StringStabError(f"check_rows expects gains of shape (n, 3); got {K.shape}")
        if not np.abs(K).max(initial=0.0) <= RANGES["gain"][1]:
            return self.check(K[:, 0], K[:, 1], K[:, 2], n_grid=n_grid, max_rounds=max_rounds,
                              max_intervals=max_intervals)
        return _check(self, np.ascontiguousarray(K[:, 0]), np.ascontiguousarray(K[:, 1]),
                      np.ascontiguousarray(K[:, 2]), n_grid=n_grid, max_rounds=max_rounds,
                      max_intervals=max_intervals)


# ---------------------------------------------------------------------------
# The dispatch: checked loop and gains in, the kernel of the loop's kind called
# ---------------------------------------------------------------------------
def _check(loop: Loop, kx: Array, kv: Array, ka: Array, *, n_grid: int | None,
           max_rounds: int, max_intervals: int) -> Check:
    model, H = loop.model, loop.sample_time
    if loop.kind == "multirate":
        from . import multirate

        return multirate.check_kernel(kx, kv, ka, model, H, loop.message_steps,  # type: ignore[arg-type]
                                      n_grid=n_grid, max_rounds=max_rounds, max_intervals=max_intervals)
    if isinstance(model, Box):
        from . import robust

        return robust.check_of(robust.certify_kernel(
            kx, kv, ka, model, H, heterogeneous=loop.heterogeneous, n_grid=n_grid,
            max_rounds=max_rounds, max_intervals=max_intervals))
    if H is not None and model.reaction_delay:  # θ_r > 0 sampled (issue 25 item 3)
        from . import sampled_reaction

        return sampled_reaction.check_kernel(
            kx, kv, ka, model, H, loop.predecessor_lag, n_grid=n_grid, max_rounds=max_rounds,
            max_intervals=max_intervals)
    if H is not None:
        from . import sampled

        return sampled.check_kernel(kx, kv, ka, model, H, loop.predecessor_lag, n_grid=n_grid,
                                    max_rounds=max_rounds, max_intervals=max_intervals)
    if model.reaction_delay:  # θ_r > 0 (issue 25): the quasi-polynomial certificate
        from . import reaction

        return reaction.check_kernel(kx, kv, ka, model, n_grid=n_grid or 64,
                                     max_rounds=max_rounds, max_intervals=max_intervals)
    return continuous.check_kernel(kx, kv, ka, model, n_grid=n_grid or 64,
                                   max_rounds=max_rounds, max_intervals=max_intervals)


def _certify(
    loop: Loop, kx: Array, kv: Array, ka: Array, *, pade_order: int, progress: bool, chunk: int,
    n_grid: int | None, max_rounds: int, max_intervals: int,
) -> CertificateBatch | SampledCertificateBatch | RobustCertificateBatch | MultirateCertificateBatch:
    model, H = loop.model, loop.sample_time
    if loop.kind == "multirate":
        from . import multirate

        return multirate.certify_kernel(
            kx, kv, ka, model, H, loop.message_steps, phase=loop.message_phase,  # type: ignore[arg-type]
            fallback=loop.fallback, progress=progress, n_grid=n_grid, max_rounds=max_rounds,
            max_intervals=max_intervals)
    if isinstance(model, Box):
        from . import robust

        return robust.certify_kernel(
            kx, kv, ka, model, H, heterogeneous=loop.heterogeneous, progress=progress,
            chunk=chunk, n_grid=n_grid, max_rounds=max_rounds, max_intervals=max_intervals)
    if H is not None and model.reaction_delay:  # θ_r > 0 sampled (issue 25 item 3)
        from . import sampled_reaction

        return sampled_reaction.certify_kernel(
            kx, kv, ka, model, H, loop.predecessor_lag, progress=progress, n_grid=n_grid,
            max_rounds=max_rounds, max_intervals=max_intervals)
    if H is not None:
        from . import sampled

        return sampled.certify_kernel(
            kx, kv, ka, model, H, loop.predecessor_lag, progress=progress, chunk=chunk,
            n_grid=n_grid, max_rounds=max_rounds, max_intervals=max_intervals)
    if model.reaction_delay:  # θ_r > 0 (issue 25): the quasi-polynomial certificate
        from . import reaction

        return reaction.certify_kernel(kx, kv, ka, model, progress=progress, chunk=chunk,
                                       n_grid=n_grid or 64, max_rounds=max_rounds,
                                       max_intervals=max_intervals)
    batch = continuous.certify_kernel(kx, kv, ka, model, progress=progress, chunk=chunk,
                                      n_grid=n_grid or 64, max_rounds=max_rounds,
                                      max_intervals=max_intervals)
    if loop.method == "pade":
        from .pade import cross_check

        # warn at the caller of certify_batch (or of Loop.certify_batch)
        return cross_check(batch, pade_order, stacklevel=4)
    return batch


# ---------------------------------------------------------------------------
# The façade's functions
# ---------------------------------------------------------------------------
def check(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: Any, delta: Any, headway: Any, sample_time: float | None = None,
    tau_prev: float | None = None, heterogeneous: bool = True,
    n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
    reaction_delay: Any = 0.0,
    message_period: float | None = None, message_phase: int | None = None,
) -> Check:
    """The certificate's verdicts alone, for inner loops (e.g. gain repair).

    The same sound decision as :func:`certify_batch` (same branch and bound, same
    verdicts) without the reporting extras — no peak search, no Taylor criteria, no pole
    margins — so one triple costs a fraction of a millisecond in continuous time.

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains, broadcast together and flattened.
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        Actuator lag τ > 0, delay δ ≥ 0, desired headway T* ≥ 0 (seconds).  A number is a
        point; an interval (a ``(lo, hi)`` pair or a ``"LO:HI"`` string, see
        :func:`stringstab.params.parameter_model`) asks for the robust certificate over the
        box of every such member (:mod:`stringstab.certify.robust`).
    sample_time : float, optional
        H > 0 (s): certify the sampled-data loop (zero-order hold, every vehicle sampling
        with period H; :mod:`stringstab.certify.sampled`) instead of the continuous-time one.
    tau_prev : float, optional
        Sampled, point parameters only: the predecessor's lag (default τ).
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranges over the τ box independently of the
        follower's (default; a platoon of different vehicles), or equals it.
    reaction_delay : float, (float, float) or str
        θ_r ≥ 0 (s): the vehicle applies its whole command θ_r late (issue 25; symbol θ_r,
        docs/conventions.md).  0 (default) is today's model and code, bit for bit; > 0 is
        certified exactly in continuous time (:mod:`stringstab.certify.reaction`) and, at a
        point of τ, δ, T*, with a sample time (:mod:`stringstab.certify.sampled_reaction`); an
        interval ``(lo, hi)`` or ``"LO:HI"``, or a point θ_r with intervals of τ, δ, T*, is the
        box certificate (:mod:`stringstab.certify.robust_reaction`), in continuous time only;
        with a message period too (:mod:`stringstab.certify.multirate`, docs/sampled.md §10.5).
    n_grid, max_rounds, max_intervals : int
        As for :func:`certify_batch`.
    message_period, message_phase
        As for :func:`certify_batch`.

    Returns
    -------
    Check
        With ``sample_time`` and ``witness_theta`` when sampled
        (:class:`stringstab.certify.sampled.SampledCheck`), and the witness member
        (``witness_tau``, ``witness_delta``, ...) over a box.

    Examples
    --------
    >>> check([1.5, 0.9], [0.3, -0.5], [-0.1, 1.1], tau=0.1, delta=0.2, headway=1.1).verdict.tolist()
    ['certified', 'not_certified']
    >>> c = check([1.2, 0.9], [0.5, -0.5], [0.6, 1.1], tau=0.1, delta=0.2, headway=1.1,
    ...           sample_time=0.1)
    >>> c.verdict.tolist(), c.sample_time
    (['certified', 'not_certified'], 0.1)
    """
    loop = Loop.of(tau, delta, headway, sample_time, tau_prev, heterogeneous,
                   reaction_delay=reaction_delay, message_period=message_period,
                   message_phase=message_phase)
    return _check(loop, *gains(k_x, k_v, k_a), n_grid=n_grid, max_rounds=max_rounds,
                  max_intervals=max_intervals)


@overload
def certify_batch(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: float, delta: float, headway: float, sample_time: None = None,
    method: str = "exact", pade_order: int = 5, progress: bool = False, chunk: int = 4096,
    n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
    tau_prev: None = None, heterogeneous: bool = True, reaction_delay: Any = 0.0,
) -> CertificateBatch: ...


@overload
def certify_batch(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: Any, delta: Any, headway: Any, sample_time: float | None = None,
    method: str = "exact", pade_order: int = 5, progress: bool = False, chunk: int = 4096,
    n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
    tau_prev: float | None = None, heterogeneous: bool = True, reaction_delay: Any = 0.0,
    message_period: float | None = None, message_phase: int | None = None,
    fallback_gains: tuple[float, float] | None = None,
) -> (CertificateBatch | SampledCertificateBatch | RobustCertificateBatch
      | MultirateCertificateBatch): ...


def certify_batch(
    k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
    *, tau: Any, delta: Any, headway: Any, sample_time: float | None = None,
    method: str = "exact", pade_order: int = 5, progress: bool = False, chunk: int = 4096,
    n_grid: int | None = None, max_rounds: int = 30, max_intervals: int = 1024,
    tau_prev: float | None = None, heterogeneous: bool = True, reaction_delay: Any = 0.0,
    message_period: float | None = None, message_phase: int | None = None,
    fallback_gains: tuple[float, float] | None = None,
) -> CertificateBatch | SampledCertificateBatch | RobustCertificateBatch | MultirateCertificateBatch:
    """Certify many gain triples at once (exact delay, sound; see :mod:`stringstab.certify.continuous`).

    With point parameters and no sample time this is the continuous-time certificate of
    stringstab.certify.continuous; ``sample_time`` certifies the sampled-data loop
    (:func:`stringstab.certify.sampled.certify_kernel`) and any interval the whole box
    (:func:`stringstab.certify.robust.certify_kernel`), with the same three verdicts.

    Parameters
    ----------
    k_x, k_v, k_a : array_like
        Gains, broadcast together and flattened.
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        Actuator lag τ > 0, delay δ ≥ 0, desired headway T* ≥ 0 (seconds).  A number is a
        point; an interval (a ``(lo, hi)`` pair or a ``"LO:HI"`` string, see
        :func:`stringstab.params.parameter_model`) asks for the robust certificate over the
        box of every such member (:mod:`stringstab.certify.robust`).
    sample_time : float, optional
        H > 0 (s): certify the sampled-data loop (zero-order hold, every vehicle sampling
        with period H; :mod:`stringstab.certify.sampled`) instead of the continuous-time one.
    tau_prev : float, optional
        Sampled, point parameters only: the predecessor's lag (default τ).
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranges over the τ box independently of the
        follower's (default; a platoon of different vehicles), or equals it.
    reaction_delay : float, (float, float) or str
        θ_r ≥ 0 (s): the vehicle applies its whole command θ_r late (issue 25; symbol θ_r,
        docs/conventions.md).  0 (default) is today's model and code, bit for bit; > 0 is
        certified exactly in continuous time (:mod:`stringstab.certify.reaction`) and, at a
        point of τ, δ, T*, with a sample time (:mod:`stringstab.certify.sampled_reaction`); an
        interval ``(lo, hi)`` or ``"LO:HI"``, or a point θ_r with intervals of τ, δ, T*, is the
        box certificate (:mod:`stringstab.certify.robust_reaction`), in continuous time only;
        with a message period too (:mod:`stringstab.certify.multirate`, docs/sampled.md §10.5).
    method : {"exact", "pade"}
        ``"pade"`` additionally runs the python-control cross-check
        (:func:`stringstab.certify.pade.certify_pade`) per triple and warns where it disagrees; the
        verdict is always the exact one (continuous loop, point parameters only).
    pade_order : int
        Padé order for the cross-check.
    progress : bool
        Show a tqdm progress bar over chunks.
    chunk : int
        Triples per vectorised chunk (bounds memory).
    n_grid, max_rounds, max_intervals : int
        Initial intervals on [0, Ω] (default 64; sampled: on [0, π], 64 + 8m), refinement
        rounds, and the cap on undecided intervals *per triple* beyond which that triple is
        declared inconclusive (per triple, so a verdict never depends on the rest of the
        batch).
    message_period, message_phase, fallback_gains : optional
        With ``sample_time``: V2V messages every P = N·H s, used at step φ and held, and the
        fallback (ACC) gains: the multi-rate certificate (:mod:`stringstab.certify.multirate`).

    Returns
    -------
    CertificateBatch, SampledCertificateBatch, RobustCertificateBatch or MultirateCertificateBatch
        The last three carry ``sample_time`` and the parameter box in their columns, rows and
        summary (the multi-rate batch also the message schedule and the fallback columns).

    Raises
    ------
    StringStabError
        On non-finite gains, parameters out of range, a malformed interval (lo > hi, a
        negative end, τ reaching 0), or a sample time that is not a finite number > 0.

    Examples
    --------
    >>> b = certify_batch([1.5, 0.9], [0.3, -0.5], [-0.1, 1.1], tau=0.1, delta=0.2, headway=1.1)
    >>> b.verdict.tolist()
    ['certified', 'not_certified']
    >>> b.summary()["certified_row_share"]
    0.5
    >>> r = certify_batch([1.2, 0.9], [0.5, -0.5], [0.6, 1.1], tau=(0.1, 0.3), delta="0.1:0.3",
    ...                   headway=1.1)
    >>> r.verdict.tolist(), r.summary()["box"]["tau"]
    (['certified', 'not_certified'], [0.1, 0.3])
    """
    loop = Loop.of(tau, delta, headway, sample_time, tau_prev, heterogeneous, method,
                   reaction_delay, message_period, message_phase, fallback_gains)
    return _certify(loop, *gains(k_x, k_v, k_a), pade_order=pade_order, progress=progress,
                    chunk=chunk, n_grid=n_grid, max_rounds=max_rounds,
                    max_intervals=max_intervals)


@overload
def certify(
    k_x: float, k_v: float, k_a: float, *, tau: float, delta: float, headway: float,
    sample_time: None = None, method: str = "exact", pade_order: int = 5,
    tau_prev: None = None, heterogeneous: bool = True, reaction_delay: Any = 0.0,
) -> Certificate: ...


@overload
def certify(
    k_x: float, k_v: float, k_a: float, *, tau: Any, delta: Any, headway: Any,
    sample_time: float | None = None, method: str = "exact", pade_order: int = 5,
    tau_prev: float | None = None, heterogeneous: bool = True, reaction_delay: Any = 0.0,
    message_period: float | None = None, message_phase: int | None = None,
    fallback_gains: tuple[float, float] | None = None,
) -> Certificate | SampledCertificate | RobustCertificate | MultirateCertificate: ...


def certify(
    k_x: float, k_v: float, k_a: float, *, tau: Any, delta: Any, headway: Any,
    sample_time: float | None = None, method: str = "exact", pade_order: int = 5,
    tau_prev: float | None = None, heterogeneous: bool = True, reaction_delay: Any = 0.0,
    message_period: float | None = None, message_phase: int | None = None,
    fallback_gains: tuple[float, float] | None = None,
) -> Certificate | SampledCertificate | RobustCertificate | MultirateCertificate:
    """Certify one gain triple K = [k_x, k_v, k_a] (exact delay, sound).

    Parameters
    ----------
    k_x, k_v, k_a : float
        The gains.
    tau, delta, headway : float, (lo, hi) or "LO:HI"
        Actuator lag τ > 0, delay δ ≥ 0, desired headway T* ≥ 0 (seconds).  A number is a
        point; an interval (a ``(lo, hi)`` pair or a ``"LO:HI"`` string, see
        :func:`stringstab.params.parameter_model`) asks for the robust certificate over the
        box of every such member (:mod:`stringstab.certify.robust`).
    sample_time : float, optional
        H > 0 (s): certify the sampled-data loop (zero-order hold, every vehicle sampling
        with period H; :mod:`stringstab.certify.sampled`) instead of the continuous-time one.
    tau_prev : float, optional
        Sampled, point parameters only: the predecessor's lag (default τ).
    heterogeneous : bool
        Sampled box only: the predecessor's lag ranges over the τ box independently of the
        follower's (default; a platoon of different vehicles), or equals it.
    reaction_delay : float, (float, float) or str
        θ_r ≥ 0 (s): the vehicle applies its whole command θ_r late (issue 25; symbol θ_r,
        docs/conventions.md).  0 (default) is today's model and code, bit for bit; > 0 is
        certified exactly in continuous time (:mod:`stringstab.certify.reaction`) and, at a
        point of τ, δ, T*, with a sample time (:mod:`stringstab.certify.sampled_reaction`); an
        interval ``(lo, hi)`` or ``"LO:HI"``, or a point θ_r with intervals of τ, δ, T*, is the
        box certificate (:mod:`stringstab.certify.robust_reaction`), in continuous time only;
        with a message period too (:mod:`stringstab.certify.multirate`, docs/sampled.md §10.5).
    method, pade_order, message_period, message_phase, fallback_gains
        As for :func:`certify_batch`.

    Returns
    -------
    Certificate, SampledCertificate, RobustCertificate or MultirateCertificate
        The continuous, sampled-data, robust or multi-rate certificate of the triple.

    Examples
    --------
    >>> c = certify(1.5, 0.3, -0.1, tau=0.1, delta=0.2, headway=1.1)
    >>> c.verdict, c.sup_gain
    ('certified', 1.0)
    >>> c = certify(0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1)
    >>> c.verdict, c.type, c.taylor_printed["sign"]
    ('not_certified', 'IV', 'stable')
    >>> s = certify(0.9, -0.5, 1.1, tau=0.1, delta=0.2, headway=1.1, sample_time=0.1)
    >>> s.verdict, round(s.sup_gain, 4), round(s.peak_omega, 3), round(s.peak_theta, 4)
    ('not_certified', 1.0911, 1.379, 0.1379)
    >>> m = certify(1.2, 0.5, 0.6, tau=0.1, delta=0.2, headway=1.1, sample_time=0.01,
    ...             message_period=0.1)
    >>> m.verdict, m.message_steps, m.fallback_verdict
    ('certified', 10, 'certified')
    """
    one_triple("certify", "certify_batch", k_x=k_x, k_v=k_v, k_a=k_a)
    loop = Loop.of(tau, delta, headway, sample_time, tau_prev, heterogeneous, method,
                   reaction_delay, message_period, message_phase, fallback_gains)
    return _certify(loop, *gains([k_x], [k_v], [k_a]), pade_order=pade_order, progress=False,
                    chunk=4096, n_grid=None, max_rounds=30, max_intervals=1024)[0]


def certify_string(
    vehicles: Sequence[Any], *, sample_time: float | None = None, leader_tau: float | None = None,
    substrings: bool = True, n_grid: int | None = None, max_rounds: int = 30,
    max_intervals: int = 4096,
) -> StringCertificate:
    """Certify a heterogeneous string head to tail: every vehicle stable and sup ∏|Γ_i| ≤ 1.

    The sound certificate of :mod:`stringstab.certify.head_to_tail` (the telescoping margin,
    the one branch and bound, exact delays), each vehicle's own certificate, and the worst
    sub-string (:mod:`stringstab.certify.string_certificate`).

    Parameters
    ----------
    vehicles : sequence of Vehicle or mapping
        The followers in order from the head (the leader is position 0, not listed), each
        with its own k_x, k_v, k_a, tau, delta, headway (optional reaction_delay θ_r, name).
    sample_time : float, optional
        H > 0 (s): the sampled-data loop (every vehicle sampling with period H).
    leader_tau : float, optional
        Sampled loop only: the leader's lag (the first follower's predecessor), default the
        first follower's.
    substrings : bool
        Also certify every run of consecutive vehicles (the worst sub-string).
    n_grid, max_rounds, max_intervals : int
        The branch and bound's initial intervals (default 64 + 8N), rounds and cap on
        undecided intervals per string.

    Returns
    -------
    StringCertificate

    Raises
    ------
    StringStabError
        On fewer than 2 vehicles, a missing, non-finite or out-of-range parameter (the message
        names the vehicle), or a bad sample time.

    Examples
    --------
    >>> acc = {"k_x": 0.1, "k_v": 0.3, "k_a": 0.0, "tau": 0.5, "delta": 0.0, "headway": 1.5}
    >>> cav = {"k_x": 0.5, "k_v": 1.0, "k_a": 0.6, "tau": 0.2, "delta": 0.2, "headway": 2.0}
    >>> c = certify_string([acc, cav])
    >>> c.verdict, c.certificates[0].verdict, round(c.certificates[0].sup_gain, 4)
    ('certified', 'not_certified', 1.1243)
    >>> c.worst_substring.first, c.worst_substring.last, c.worst_substring.verdict
    (1, 1, 'not_certified')
    """
    from .string_certificate import certify_string_kernel, check_vehicles

    vs, H, lt = check_vehicles(vehicles, sample_time=sample_time, leader_tau=leader_tau)
    return certify_string_kernel(vs, sample_time=H, leader_tau=lt, substrings=substrings,
                                 n_grid=n_grid, max_rounds=max_rounds, max_intervals=max_intervals)
