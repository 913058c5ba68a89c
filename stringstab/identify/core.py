"""``identify(log)``: fit, certify and bootstrap each follower of a recorded platoon.

Per follower (a vehicle whose predecessor and gap are in the log):

1. its record (:func:`stringstab.identify.record.follower_record`): single missing samples
   bridged, the stretches where it does not follow its predecessor excluded (standstill, a
   cut-in or target change, no target in range, not driven by it), the clean segments;
2. the estimate (:func:`stringstab.identify.estimate.estimate`): the spacing policy from the
   quasi-steady parts, the closed-loop simulation-error fit (with θ_r on request), the
   certificate through the façade, the multi-start moving-block bootstrap, the box
   certificate, the profiles over T* and θ_r, the data's own transfer, the baselines.

The verdict is worded no more confidently than the bootstrap allows
(:mod:`stringstab.identify.wording`).  :func:`stringstab.identify.cars.identify_cars` pools the
logs of each car instead.  The results it returns are :mod:`stringstab.identify.results`
(importable from here too).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from ..errors import StringStabError, show
from ..io.platoon_logs import PlatoonLog
from ..progress import Progress
from .estimate import Settings, estimate
from .fit import PARAMETERS
from .record import follower_record, missing_vehicles
from .results import IdentifyResult as IdentifyResult
from .results import VehicleResult as VehicleResult
from .spacing import distance_setting

__all__ = ["DEFAULT_BLOCK", "DEFAULT_BOOTSTRAP", "FitProgress", "check_settings", "identify"]

#: Default number of bootstrap refits per follower.
DEFAULT_BOOTSTRAP = 50
#: Default block length of the moving-block bootstrap, s.
DEFAULT_BLOCK = 20.0


class FitProgress:
    """Count the fits through :class:`stringstab.progress.Progress`, naming the last one on the bar.

    Parameters
    ----------
    total : int
        Fits to come.
    show_it : bool or None
        Show progress (None: yes).
    """

    def __init__(self, total: int, show_it: bool | None) -> None:
        self.p = Progress(total, "identify", unit="fit",
                          enabled=total > 0 and (show_it if show_it is not None else True))

    def step(self, what: str) -> None:
        """One fit done.

        Parameters
        ----------
        what : str
            Shown beside the bar.
        """
        self.p.update(1)
        if self.p.bar is not None:
            self.p.bar.set_postfix_str(what, refresh=False)

    def labelled(self, who: str) -> Callable[[str], None]:
        """A step function naming ``who`` on the bar.

        Parameters
        ----------
        who : str
            The follower or car being fitted.

        Returns
        -------
        callable
            ``step(what)`` that counts one fit and shows ``who what``.
        """
        return lambda what: self.step(f"{who} {what}")

    def close(self) -> None:
        """End the bar."""
        self.p.close()


def check_settings(s: Settings) -> None:
    """Refuse options out of range (one line).

    Parameters
    ----------
    s : Settings
        The options.

    Raises
    ------
    StringStabError
        An unknown model, a negative bootstrap count, a block that is not a positive number.
    """
    if s.model not in PARAMETERS:
        raise StringStabError(f"model must be 'acc' or 'cacc'; got {show(s.model)}")
    if int(s.bootstrap) < 0:
        raise StringStabError(f"bootstrap must be an integer >= 0; got {show(s.bootstrap)}")
    if not (math.isfinite(s.block) and s.block > 0):
        raise StringStabError(f"block must be a number of seconds > 0; got {show(s.block)}")


def identify(log: PlatoonLog | Sequence[PlatoonLog], model: str = "acc", *,
             sample_time: float | None = None, bootstrap: int = DEFAULT_BOOTSTRAP,
             block: float = DEFAULT_BLOCK, n_starts: int = 4, seed: int = 0,
             min_duration: float = 30.0, progress: bool | None = None, fit_delay: bool = False,
             baselines: bool = False, screen: bool = True) -> IdentifyResult:
    """Identify, certify and bootstrap every follower of a recorded platoon.

    Parameters
    ----------
    log : PlatoonLog or sequence of PlatoonLog
        From :func:`stringstab.io.platoon_logs.read_platoon_logs`.
    model : {"acc", "cacc"}
        ``acc``: u = k_x Δp + k_v Δv (k_a = 0); ``cacc``: also k_a a_{i−1}(t − δ) (needs the
        predecessor's acceleration in the log).
    sample_time : float, optional
        Certify the sampled-data loop with this period H (s); default continuous time.
    bootstrap : int
        Moving-block bootstrap refits per follower (0: none).
    block : float
        Block length, s.
    n_starts : int
        Starting points of the point fit.
    seed : int
        Seed of the starting points and the bootstrap draws.
    min_duration : float
        Shortest clean segment used, s.
    progress : bool, optional
        Show progress on stderr (default: yes).
    fit_delay : bool
        Also fit the reaction delay θ_r on the whole law (issue 25).
    baselines : bool
        Also fit IDM and OVRV on the same segments (:mod:`stringstab.identify.baselines`).
    screen : bool
        Exclude the stretches where a car does not follow its predecessor (default).

    Returns
    -------
    IdentifyResult
        Every follower identified, the ones skipped and why.

    Raises
    ------
    StringStabError
        If no follower has a usable segment, or an option is out of range.
    """
    logs = [log] if isinstance(log, PlatoonLog) else list(log)
    s = Settings(model, sample_time, int(bootstrap), float(block), n_starts, seed, min_duration, fit_delay,
                 baselines, screen)
    check_settings(s)
    jobs = []
    skipped = []
    for li, lg in enumerate(logs):
        skipped += [f"{lg.source}: {m}" if len(logs) > 1 else m for m in missing_vehicles(lg)]
        for p in lg.followers():
            rec = follower_record(lg, p, min_duration=min_duration, screen=screen)
            if not rec.data.segments:
                skipped.append(f"{lg.name(p)} (position {p}): no clean segment of at least "
                               f"{min_duration:g} s" + (f" ({'; '.join(rec.notes)})" if rec.notes else ""))
                continue
            ap = rec.data.a_pred
            if model == "cacc" and (ap is None or not all(np.isfinite(ap[g.start:g.stop]).all()
                                                         for g in rec.data.segments)):
                raise StringStabError(
                    f"--model cacc needs the predecessor's acceleration (an a column); "
                    f"{show(lg.source)} has none for {lg.name(p - 1)}")
            jobs.append((li, lg, p, rec))
    if not jobs:
        raise StringStabError(
            "no follower has a usable segment (predecessor speed, own speed and gap all measured "
            f"for at least {min_duration:g} s); " + ("; ".join(skipped) or "found none"))
    bar = FitProgress(len(jobs) * (1 + s.bootstrap), progress)
    rng = np.random.default_rng(seed)
    out = []
    try:
        for li, lg, p, rec in jobs:
            est = estimate(rec.data, s, rng, bar.labelled(lg.name(p)))
            setting, raw = distance_setting(lg.meta)
            vr = VehicleResult(**{k: getattr(est, k) for k in est.__dataclass_fields__},
                               platoon=li, position=p, name=lg.name(p), predecessor=lg.name(p - 1),
                               setting=setting, distance_setting=raw)
            vr.notes = rec.notes + vr.notes
            out.append(vr)
    finally:
        bar.close()
    return IdentifyResult(out, model, sample_time, s.document(), [lg.source for lg in logs], skipped)
