"""The certificates: whether a gain triple is string stable, with the exact delay.

One way in (:mod:`~stringstab.certify.api`) — :func:`certify` (one triple, the full
report), :func:`certify_batch` (many triples, one row each) and :func:`check` (the verdict
only, for inner loops) — checks the arguments once and chooses the certificate from them
(:class:`~stringstab.certify.api.Loop`): the continuous loop
(:mod:`~stringstab.certify.continuous`), the sampled-data loop when a sample time is given
(:mod:`~stringstab.certify.sampled`), or a box of parameters when τ, δ or T* is an interval
(:mod:`~stringstab.certify.robust`, with :mod:`~stringstab.certify.robust_continuous` and
:mod:`~stringstab.certify.robust_sampled`, whose split form and search are
:mod:`~stringstab.certify.sampled_split`, :mod:`~stringstab.certify.sampled_split_cells` and
:mod:`~stringstab.certify.robust_split`).  The sampled-data loop is built from the ZOH
discretisation (:mod:`~stringstab.certify.zoh`), the Schur test
(:mod:`~stringstab.certify.schur`), H(e^{jθ}) and its margin
(:mod:`~stringstab.certify.sampled_frequency`, :mod:`~stringstab.certify.sampled_excess`), on
the interval arithmetic the robust boxes share (:mod:`~stringstab.certify.interval`).  Every
certificate answers with the verdicts of
:mod:`~stringstab.certify.verdicts` and is sound by construction: "certified" means
internally stable and ‖Γ‖_H∞ ≤ 1 with the exact delay.

With a reaction delay θ_r > 0 on the whole command (issue 25) the continuous loop is certified
by :mod:`~stringstab.certify.reaction`: the exact root count of the quasi-polynomial
denominator (:mod:`~stringstab.certify.quasipolynomial`), the branch and bound on the margin
with θ_r (:mod:`~stringstab.certify.margin_reaction`), its results
(:mod:`~stringstab.certify.reaction_results`) and the reporting estimate of the rightmost root
(:mod:`~stringstab.certify.rightmost`).

Also here: the Padé cross-check (:mod:`~stringstab.certify.pade`, never a verdict), the
branch and bound (:mod:`~stringstab.certify.branch_bound`), the margin g(ω) and its tail
bound (:mod:`~stringstab.certify.margin`), the Taylor and Hurwitz criteria
(:mod:`~stringstab.certify.criteria`), |Γ(jω)| (:mod:`~stringstab.certify.frequency`) and
sup |Γ| − 1 (:mod:`~stringstab.certify.excess`), the "surely not certifiable" screens
(:mod:`~stringstab.certify.screen`), the certified points of a grid of gains
(:mod:`~stringstab.certify.grid`) and the certificates over cells of gains
(:mod:`~stringstab.certify.gain_cells`, the repair's proven cells).  Strings of different
vehicles are certified head to tail (:func:`~stringstab.certify.api.certify_string`:
:mod:`~stringstab.certify.head_to_tail`, :mod:`~stringstab.certify.head_to_tail_sampled`,
:mod:`~stringstab.certify.string_decision`, :mod:`~stringstab.certify.string_certificate`, on the
interval jets of :mod:`~stringstab.certify.interval_jets`).

The function :func:`certify` and this subpackage share a name: ``stringstab.certify`` is the
function (the façade binds it); import the modules with ``from stringstab.certify import
sampled``.
"""

from .api import Loop, certify, certify_batch, check
from .continuous import Certificate, CertificateBatch
from .pade import PadeResult, certify_pade

__all__ = [
    "Certificate",
    "CertificateBatch",
    "Loop",
    "PadeResult",
    "certify",
    "certify_batch",
    "certify_pade",
    "check",
]
