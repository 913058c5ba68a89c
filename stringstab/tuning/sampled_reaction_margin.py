r"""The sampled margin with a reaction delay θ_r > 0 as a quadratic form in the gains (issue 25).

The gain repair (:mod:`stringstab.tuning.constraints`) needs every constraint as a polynomial
of degree ≤ 2 in K = (k_x, k_v, k_a).  The sampled link with θ_r (docs/sampled.md §10; the
certificate's model :func:`stringstab.certify.lifting_reaction.lift_reaction`, used here as it
is) is, in the z-domain,

.. math::
    H(z) = \frac{N(z)}{D(z)},\qquad
    D(z) = 1 - k_x P^{s}_{p}(z) - k_v P^{s}_{v}(z),\qquad
    N(z) = k_x P^{p}_{p}(z) + k_v P^{p}_{v}(z) + k_a Q(z),

the open-loop responses P of Δp and Δv to the follower's own commands (s) and to the
predecessor's (p), and Q of the sampled, delayed a_{i−1}: N and D are **affine in K**.  With
χ_f(z; K) = det(zI − A_f(K)) the characteristic polynomial of the follower's block (3 + L
states, :func:`stringstab.certify.lifting_reaction.follower_block`), the matrix determinant
lemma gives D(z) = χ_f(z; K)/χ_f(z; 0), χ_f(z; 0) = (z − 1)²(z − e^{−H/τ})z^L, and the
Rosenbrock system matrix of the whole link gives

.. math::
    R(z; K) = \det S(z) = \det(zI - A)\,H(z) = χ_o(z)\,χ_f(z; 0)\,N(z),\qquad
    S(z) = [zI - A,\ B;\ -C,\ D_0],

χ_o(z) = det(zI − A_oo) the predecessor's and the buffer's block (independent of K).  Hence

.. math::
    g_{H,θ_r}(θ; K) = \frac{τ^2\,\left(|χ_f(z; K)|^2 - |R(z; K)/χ_o(z)|^2\right)}
                           {H^4\,|z - 1|^2\,(1 + τ^2 ω_H^4)},
    \qquad z = e^{jθ},\quad ω_H = |z - 1|/H,

is a polynomial of degree 2 in K, equal to τ²|χ_f(z; K)|²(1 − |H(e^{jθ})|²) divided by the
positive H⁴|z − 1|²(1 + τ²ω_H⁴): **≥ 0 iff |H(e^{jθ})| ≤ 1** wherever χ_f(z; K) ≠ 0.  As
H → 0 it tends to g_θ(ω)/(1 + τ²ω⁴) at θ = ωH, g_θ the continuous margin of
:func:`stringstab.certify.margin_reaction.g` (|χ_f(z; K)| ≈ H³|D_c(jω)|/τ, |z − 1| ≈ ωH).
The weight 1/(1 + τ²ω_H⁴) (independent of K, so the sign and the degree are kept) keeps the
margin bounded at high frequency: without it the values reach 10⁴-10⁵ at θ = π
(τ = 0.5 s, H = 0.1 s) and IPOPT, started at a feasible point 0.4 from K0, stopped at a local
solution 1.1 away.  At θ = 0 (0/0: G(1) = 1) it is taken at :data:`THETA_FLOOR` (an even
function of θ: the error is O(θ²), far below the constraint's ε).

The internal-stability constraints are two necessary conditions for χ_f to be Schur,
normalised: χ_f(1; K)/c = k_x (only k_x reaches z = 1: c > 0 is the coefficient of k_x) and
(−1)^{3+L}χ_f(−1; K)/((−1)^{3+L}χ_f(−1; 0)) (1 at K = 0).  Necessary, not sufficient: the
certificate (:func:`stringstab.certify.api.check`, Stein inertia and the lifted branch and
bound) decides every output of the repair, and these numbers only steer the NLP.  Nothing here
is a proof: determinants of the computed (mid-point) matrices, with round-off.

References
----------
H. H. Rosenbrock, *State-space and Multivariable Theory*, Nelson (1970) (the system matrix);
docs/sampled.md §10; IDL paper, eq 4.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from ..certify.lifting_reaction import held_steps, lift_reaction
from ..params import Params

__all__ = ["THETA_FLOOR", "follower_polynomial", "sampled_reaction_margin",
           "stability_conditions"]

Array = npt.NDArray[np.float64]

#: θ (rad/sample) at which the margin is taken for θ below it (θ = 0 is a 0/0).
THETA_FLOOR = 1e-3


def _link_parts(k_x: Array, k_v: Array, k_a: Array, p: Params, H: float, tau_prev: float
                ) -> tuple[Array, Array, Array, Array, npt.NDArray[np.intp], npt.NDArray[np.intp]]:
    """A, B, C, D (mid-points) of the certificate's link and the follower's/other indices."""
    link = lift_reaction(k_x, k_v, k_a, p, H, 1, tau_prev)
    _, _, L = held_steps(p.reaction_delay, H)
    f = np.r_[0:3, 4:4 + L]
    o = np.setdiff1d(np.arange(link.order), f)
    return link.A.mid, link.B.mid, link.C.mid, link.D.mid, f, o


def follower_polynomial(z: npt.ArrayLike, k_x: npt.ArrayLike, k_v: npt.ArrayLike,
                        k_a: npt.ArrayLike, p: Params, H: float,
                        tau_prev: float | None = None) -> npt.NDArray[np.complex128]:
    """χ_f(z; K) = det(zI − A_f(K)), the follower block's characteristic polynomial, at z.

    Parameters
    ----------
    z : array_like of complex, shape (k,)
        Points of the complex plane.
    k_x, k_v, k_a : array_like, shape (n,)
        Gains of IDL eq 4 (1/s², 1/s, -).
    p : Params
        τ, δ, T* and θ_r > 0 (s).
    H : float
        The sample time, s.
    tau_prev : float, optional
        The predecessor's lag τ_p (default τ; it does not enter χ_f).

    Returns
    -------
    ndarray of complex, shape (n, k)
        χ_f at each z for each triple.

    Examples
    --------
    >>> p = Params(0.5, 0.0, 1.5, reaction_delay=0.15)
    >>> c = follower_polynomial([1.0], [0.0], [0.0], [0.0], p, 0.1)
    >>> abs(complex(c[0, 0])) < 1e-12  # χ_f(z; 0) = (z − 1)²(z − e^{−H/τ})z^L
    True
    """
    kx, kv, ka = (np.atleast_1d(np.asarray(v, dtype=float)) for v in (k_x, k_v, k_a))
    zz = np.atleast_1d(np.asarray(z, dtype=complex))
    A, _, _, _, f, _ = _link_parts(kx, kv, ka, p, H, p.tau if tau_prev is None else tau_prev)
    Af = A[:, f][:, :, f]
    W = zz[None, :, None, None] * np.eye(len(f)) - Af[:, None]
    return np.asarray(np.linalg.det(W))


def sampled_reaction_margin(theta: npt.ArrayLike, k_x: npt.ArrayLike, k_v: npt.ArrayLike,
                            k_a: npt.ArrayLike, p: Params, H: float,
                            tau_prev: float | None = None) -> Array:
    """g_{H,θ_r}(θ; K) of the module docstring: ≥ 0 iff |H(e^{jθ})| ≤ 1, quadratic in K.

    Parameters
    ----------
    theta : array_like, shape (k,)
        θ = ωH, rad/sample (taken at :data:`THETA_FLOOR` below it).
    k_x, k_v, k_a : array_like, shape (n,)
        Gains of IDL eq 4 (1/s², 1/s, -).
    p : Params
        τ, δ, T* and θ_r > 0 (s).
    H : float
        The sample time, s.
    tau_prev : float, optional
        The predecessor's lag τ_p (default τ).

    Returns
    -------
    ndarray, shape (n, k)
        The margin at each θ for each triple.

    Examples
    --------
    >>> p = Params(0.5, 0.0, 1.5, reaction_delay=0.15)
    >>> g = sampled_reaction_margin([0.05, 1.0, 3.0], [0.2], [0.6], [0.0], p, 0.1)
    >>> bool(np.all(g > 0))  # certified gains (certify_kernel's example)
    True
    """
    kx, kv, ka = (np.atleast_1d(np.asarray(v, dtype=float)) for v in (k_x, k_v, k_a))
    th = np.maximum(np.abs(np.atleast_1d(np.asarray(theta, dtype=float))), THETA_FLOOR)
    z = np.exp(1j * th)
    A, B, C, D, f, o = _link_parts(kx, kv, ka, p, H, p.tau if tau_prev is None else tau_prev)
    n = A.shape[-1]
    eye = np.eye(n)
    # the Rosenbrock system matrix [[zI − A, B], [−C, D]] of every triple at every z
    S = np.zeros((A.shape[0], z.size, n + 1, n + 1), dtype=complex)
    S[..., :n, :n] = z[None, :, None, None] * eye - A[:, None]
    S[..., :n, n:] = B[:, None]
    S[..., n:, :n] = -C[:, None]
    S[..., n:, n:] = D[:, None]
    R = np.linalg.det(S)
    Af, Aoo = A[:, f][:, :, f], A[:1, o][:, :, o]  # A_oo does not depend on K
    chi_f = np.linalg.det(z[None, :, None, None] * np.eye(len(f)) - Af[:, None])
    chi_o = np.linalg.det(z[None, :, None, None] * np.eye(len(o)) - Aoo[:, None])
    num = np.abs(chi_f) ** 2 - np.abs(R / chi_o) ** 2
    wH2 = (np.abs(z - 1.0) / H) ** 2
    return np.asarray(p.tau**2 * num / (H**4 * np.abs(z - 1.0) ** 2 * (1.0 + p.tau**2 * wH2**2)))


def stability_conditions(k_x: npt.ArrayLike, k_v: npt.ArrayLike, k_a: npt.ArrayLike,
                         p: Params, H: float) -> Array:
    """The two normalised necessary Schur conditions of χ_f (module docstring), affine in K.

    Parameters
    ----------
    k_x, k_v, k_a : array_like, shape (n,)
        Gains of IDL eq 4 (1/s², 1/s, -).
    p : Params
        τ, δ, T* and θ_r > 0 (s).
    H : float
        The sample time, s.

    Returns
    -------
    ndarray, shape (2, n)
        χ_f(1; K)/c (= k_x) and (−1)^{3+L}χ_f(−1; K) normalised to 1 at K = 0; both > 0 when
        χ_f is Schur.

    Examples
    --------
    >>> p = Params(0.5, 0.0, 1.5, reaction_delay=0.15)
    >>> np.round(stability_conditions([0.2], [0.0], [0.0], p, 0.1)[0], 9).tolist()
    [0.2]
    """
    kx = np.atleast_1d(np.asarray(k_x, dtype=float))
    kv, ka = (np.broadcast_to(np.asarray(v, dtype=float), kx.shape) for v in (k_v, k_a))
    ref = follower_polynomial([1.0, -1.0], [1.0, 0.0], [0.0, 0.0], [0.0, 0.0], p, H).real
    c1, m1 = ref[0, 0], ref[1, 1]  # χ_f(1; e_x) = c·1, χ_f(−1; 0)
    v = follower_polynomial([1.0, -1.0], kx, kv, ka, p, H).real
    return np.stack([v[:, 0] / c1, v[:, 1] / m1])  # the signs (−1)^{3+L} cancel
