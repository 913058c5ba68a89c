"""The repair of a training config or of a saved policy: :func:`repair_for`, the one way to rebuild it.

The repair itself (:class:`stringstab.tuning.repair.GainRepair`, IDL §3.3: every executed gain
triple certified) and its certified lattice (:mod:`stringstab.tuning.lattice`) live in
:mod:`stringstab.tuning` (issue 32 item 3); the environment applies it as an action wrapper
(:class:`stringstab.rl.envs.RepairedGains`).  This module reads its settings from a
:class:`~stringstab.rl.config.TD3Config` or a policy's ``policy.json``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..errors import StringStabError
from ..tuning.repair import GainRepair
from .config import TD3Config

__all__ = ["REPAIR_KEYS", "REPAIR_REACTION_KEY", "repair_for"]


#: The keys of a saved repair (:meth:`GainRepair.describe`, ``policy.json``'s ``"repair"``).
REPAIR_KEYS = ("method", "tau", "delta", "headway", "bounds", "resolution", "refine",
               "sample_time")
#: The optional key of a saved repair: θ_r (s), written only when > 0 (issue 25).
REPAIR_REACTION_KEY = "reaction_delay"


def repair_for(saved: TD3Config | Mapping[str, Any], *, where: str = "policy info") -> GainRepair | None:
    """The repair of a config or of a saved policy's settings: the one way to rebuild it.

    From a :class:`~stringstab.rl.config.TD3Config` (training): its ``repair`` method, τ, δ,
    T*, ``gain_bounds``, ``repair_resolution``, ``repair_refine`` and, with
    ``repair_sampled``, the sampled-data certificate at ``dt``, and its ``reaction_delay``.  From a policy's info (the
    ``policy.json`` document, or :attr:`~stringstab.rl.policy.Policy.info`): its ``"repair"``
    entry, the :meth:`GainRepair.describe` output saved by training, every key of
    :data:`REPAIR_KEYS` required (no defaults).

    Parameters
    ----------
    saved : TD3Config or mapping
        The training config, or a policy's info with ``"action"`` and ``"repair"``.
    where : str
        What ``saved`` was read from, for the error messages.

    Returns
    -------
    GainRepair or None
        The repair of a gain policy (``"gains"`` actions); None for acceleration actions.

    Raises
    ------
    StringStabError
        If a key is missing from the policy's info or its repair settings, or a setting is
        invalid.

    Examples
    --------
    >>> from stringstab.rl import config_for
    >>> rep = repair_for(config_for("idl", repair_resolution=0.25))
    >>> repair_for({"action": "gains", "repair": rep.describe()}).describe() == rep.describe()
    True
    >>> repair_for(config_for("td3")) is None
    True
    """
    if isinstance(saved, TD3Config):
        if saved.action != "gains":
            return None
        return GainRepair(saved.repair, tau=saved.tau, delta=saved.delta, headway=saved.headway,
                          bounds=saved.gain_bounds, resolution=saved.repair_resolution,
                          refine=saved.repair_refine,
                          sample_time=saved.dt if saved.repair_sampled else None,
                          reaction_delay=saved.reaction_delay)
    for key in ("action", "repair"):
        if key not in saved:
            raise StringStabError(f"expected key {key!r} in {where}, found keys {sorted(saved)}")
    if saved["action"] != "gains":
        return None
    r = saved["repair"]
    if not isinstance(r, Mapping):
        raise StringStabError(f"{where}: expected the repair settings of a gain policy under "
                              f"'repair' (a JSON object); found {r!r}")
    for key in REPAIR_KEYS:
        if key not in r:
            raise StringStabError(f"expected key {key!r} in {where}'s repair settings, found "
                                  f"keys {sorted(r)}")
    bounds = r["bounds"]
    if not isinstance(bounds, (list, tuple)) or len(bounds) != 2:
        raise StringStabError(f"{where}: repair bounds must be [low, high]; found {bounds!r}")
    return GainRepair(r["method"], tau=r["tau"], delta=r["delta"], headway=r["headway"],
                      bounds=(bounds[0], bounds[1]), resolution=r["resolution"],
                      refine=r["refine"], sample_time=r["sample_time"],
                      reaction_delay=r.get(REPAIR_REACTION_KEY, 0.0))
