"""Matrix balls: a computed matrix and a proven bound on its distance to the exact one.

The multi-rate certificate (:mod:`stringstab.certify.multirate`) builds the lifted link's
matrices (:mod:`stringstab.certify.lifting`) and evaluates its frequency response
(:mod:`stringstab.certify.lifted_frequency`) in floating point; every quantity carries a
radius that bounds the difference between the computed value and the value of the exact
model, so that every comparison is sound:

* :class:`Ball` — *entrywise* midpoint-radius arithmetic on stacks of real matrices
  (``mid`` and ``rad`` of one shape, ``|exact − mid| ≤ rad`` entry by entry): sums and
  products propagate the radii and add the round-off of the product itself,
  γ_k |A||B| (Higham, Thm 3.5: |fl(AB) − AB| ≤ γ_k |A||B| for an inner dimension k);
* :func:`gamma` — that γ_k, doubled (2(k + 2)u instead of ku/(1 − ku)), which also covers
  the rounding of the radii themselves (computed in round-to-nearest: each is a sum of
  a few non-negative products, so its relative error is a few u, far below the doubling);
* :func:`fro` — Frobenius norms of a stack (an upper bound of the spectral norm), the
  norm-wise radii of the frequency stage.

References
----------
S. M. Rump, "Fast and parallel interval arithmetic", *BIT* 39 (1999) 534-554 (midpoint-radius
matrix products).  N. J. Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed.,
SIAM (2002), §3.1 and Thm 3.5.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

__all__ = ["UNIT_ROUNDOFF", "Ball", "fro", "gamma"]

Array = npt.NDArray[np.float64]

#: The unit round-off u of IEEE double precision.
UNIT_ROUNDOFF = 2.0**-53


def gamma(k: int) -> float:
    """A generous γ_k: 2(k + 2)u ≥ ku/(1 − ku), the round-off factor of a length-k dot product.

    Parameters
    ----------
    k : int
        The inner dimension of the products (or the depth of a sum).

    Returns
    -------
    float
        2(k + 2)u; complex products (a multiplication is 4 real ones and 2 sums) use
        :func:`gamma` of 2k + 2.

    Examples
    --------
    >>> gamma(3) == 10 * 2.0**-53
    True
    """
    return 2.0 * (k + 2) * UNIT_ROUNDOFF


def fro(a: npt.ArrayLike) -> Array:
    """Frobenius norms of a stack of matrices (the last two axes), ≥ the spectral norms.

    Parameters
    ----------
    a : array_like
        Shape (..., r, c), real or complex.

    Returns
    -------
    ndarray
        Shape (...): sqrt(Σ |a_ij|²), each rounded up by a relative 4u (the sum's round-off).

    Examples
    --------
    >>> float(fro(np.eye(2)[None])[0]) >= 2**0.5
    True
    """
    x = np.abs(np.asarray(a))
    s = np.sqrt(np.einsum("...ij,...ij->...", x, x))
    return np.asarray(s * (1.0 + gamma(x.shape[-1] * x.shape[-2])))


@dataclass(frozen=True)
class Ball:
    """A stack of real matrices ``mid`` with entrywise radii ``rad``: |exact − mid| ≤ rad.

    Attributes
    ----------
    mid : ndarray, shape (..., r, c)
        The computed matrices.
    rad : ndarray, shape (..., r, c)
        Non-negative bounds on the error of each entry.
    """

    mid: Array
    rad: Array

    @staticmethod
    def exact(a: npt.ArrayLike) -> Ball:
        """A ball of radius 0 (the matrices are the exact ones, e.g. gains or 0/1 selectors).

        Parameters
        ----------
        a : array_like
            The exact matrices.

        Returns
        -------
        Ball
        """
        m = np.asarray(a, dtype=float)
        return Ball(m, np.zeros_like(m))

    @staticmethod
    def relative(a: npt.ArrayLike, mag: npt.ArrayLike, rel: float) -> Ball:
        """Computed matrices whose error is at most ``rel`` × ``mag`` entry by entry.

        Parameters
        ----------
        a : array_like
            The computed matrices.
        mag : array_like
            The magnitude companion of each entry (the same formula on absolute values).
        rel : float
            The relative error of the formula (e.g. :data:`~stringstab.certify.verdicts.ROUNDOFF_SLACK`).

        Returns
        -------
        Ball
        """
        m = np.asarray(a, dtype=float)
        return Ball(m, rel * np.abs(np.asarray(mag, dtype=float)) * np.ones_like(m))

    def __add__(self, o: Ball) -> Ball:
        s = self.mid + o.mid
        return Ball(s, self.rad + o.rad + gamma(1) * np.abs(s))

    def __sub__(self, o: Ball) -> Ball:
        s = self.mid - o.mid
        return Ball(s, self.rad + o.rad + gamma(1) * np.abs(s))

    def __matmul__(self, o: Ball) -> Ball:
        a, b = self.mid, o.mid
        aa, ab = np.abs(a), np.abs(b)
        rad = aa @ o.rad + self.rad @ (ab + o.rad) + gamma(a.shape[-1]) * (aa @ ab)
        return Ball(a @ b, rad)

    def scale(self, s: npt.ArrayLike) -> Ball:
        """Every matrix times an exact scalar (one per matrix of the stack, or one for all).

        Parameters
        ----------
        s : array_like
            Shape broadcastable to the stack's leading axes followed by (1, 1).

        Returns
        -------
        Ball
        """
        sv = np.asarray(s, dtype=float)
        m = self.mid * sv
        return Ball(m, self.rad * np.abs(sv) + gamma(0) * np.abs(m))

    def __getitem__(self, key: Any) -> Ball:
        return Ball(self.mid[key], self.rad[key])

    def norm_radius(self) -> Array:
        """The Frobenius norm of the radii: a bound on ‖exact − mid‖₂ for each matrix.

        Returns
        -------
        ndarray
            Shape of the stack's leading axes.
        """
        return fro(self.rad)

    def norm_bound(self) -> Array:
        """An upper bound of ‖exact‖₂ for each matrix: ‖mid‖_F + ‖rad‖_F.

        Returns
        -------
        ndarray
            Shape of the stack's leading axes.
        """
        return np.asarray(fro(self.mid) + fro(self.rad))
