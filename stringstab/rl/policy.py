"""A trained deterministic policy: NumPy in, NumPy out, saved as safetensors + JSON.

``policy(obs)`` is the actor's action μ(s) in environment units (no exploration noise): the
proposed gains K for an IDL policy, the acceleration for a pure-RL one.  For an IDL policy,
:meth:`Policy.gains` is what the vehicle *executes*: μ(s) after the repair step
(:class:`~stringstab.tuning.repair.GainRepair`), each triple certified by the exact certificate.

:meth:`Policy.save` writes ``policy.safetensors`` (the actor's weights) and ``policy.json``
(sizes, bounds, settings and the weights file's SHA-256); :func:`load_policy` refuses a missing,
altered, truncated or foreign file with one :class:`~stringstab.errors.StringStabError` and never
runs code from it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from ..io import atomic_write_text, check_output_dir, dumps_json
from ..tuning.repair import GainRepair
from .checkpoint import read_json, read_tensors, write_tensors
from .repair import repair_for

__all__ = ["POLICY_FORMAT", "POLICY_KEYS", "Policy", "load_policy"]

#: Format tag of ``policy.json``.
POLICY_FORMAT = "stringstab-rl-policy/1"
#: The keys of a policy's info (``policy.json`` without ``format`` and ``sha256``).
POLICY_KEYS = ("algo", "action", "obs_dim", "act_dim", "low", "high", "hidden", "tau", "delta",
               "headway", "dt", "observe", "gain_rate", "repair")

Array = npt.NDArray[np.float64]


class Policy:
    """A deterministic actor with its settings (build with :func:`load_policy` or from training).

    Attributes
    ----------
    info : dict
        ``algo``, ``action`` ("gains" or "accel"), ``obs_dim``, ``act_dim``, ``low``, ``high``,
        ``hidden``, the model parameters (``tau``, ``delta``, ``headway``, ``dt``), the state
        extras ``observe``, the ``gain_rate`` and the ``repair`` settings (every key of
        :data:`POLICY_KEYS`).
    repair : GainRepair or None
        The repair of a gain policy, rebuilt from ``info["repair"]`` by
        :func:`~stringstab.rl.repair.repair_for` (None for an acceleration policy).

    Raises
    ------
    StringStabError
        If ``info`` lacks a key of :data:`POLICY_KEYS` or holds invalid repair settings.
    """

    def __init__(self, actor: Any, info: dict[str, Any], *, where: str = "policy info") -> None:
        self.actor = actor
        self.actor.eval()
        self.info = dict(info)
        for key in POLICY_KEYS:
            if key not in self.info:
                raise StringStabError(f"expected key {key!r} in {where}, found keys "
                                      f"{sorted(self.info)}")
        self.repair: GainRepair | None = repair_for(self.info, where=where)

    @property
    def algo(self) -> str:
        """The agent that trained it ("idl", "td3" or "ddpg")."""
        return str(self.info["algo"])

    @property
    def action(self) -> str:
        """"gains" (IDL) or "accel" (pure RL)."""
        return str(self.info["action"])

    def __call__(self, obs: npt.ArrayLike) -> Array:
        """μ(s) for states ``obs`` of shape (n, obs_dim) (or (obs_dim,)): (n, act_dim) float64."""
        import torch

        x = np.asarray(obs, dtype=np.float32)
        one = x.ndim == 1
        x2 = x.reshape(1, -1) if one else x
        if x2.ndim != 2 or x2.shape[1] != self.info["obs_dim"]:
            raise StringStabError(
                f"policy input: expected states of shape (n, {self.info['obs_dim']}); got {x.shape}")
        with torch.no_grad():
            a = self.actor(torch.as_tensor(x2)).numpy().astype(np.float64)
        return a[0] if one else a

    @property
    def observe(self) -> tuple[str, ...]:
        """Extras of the state beyond eq 16 (``TD3Config.observe``)."""
        return tuple(self.info["observe"])

    @property
    def gain_rate(self) -> float:
        """Per-step limit on each gain's change (``TD3Config.gain_rate``; 0: none)."""
        return float(self.info["gain_rate"])

    def step_gains(self, state: npt.ArrayLike, *, accel: npt.ArrayLike | None = None,
                   prev_gains: npt.ArrayLike | None = None) -> Array:
        """One control step of an IDL policy, as in training: the executed gains ``(n, 3)``.

        ``state`` is the eq-16 state ``(n, 3)``; the policy's ``observe`` extras are appended
        (own acceleration ``accel`` (n,), the previous executed gains ``prev_gains`` (n, 3);
        None at an episode's first step: zeros, and no rate limit), the proposal is rate
        limited (``gain_rate``) and repaired, so each returned triple is certified (unless the
        repair is off).

        Parameters
        ----------
        state : array_like (n, 3)
            The IDL state of eq 16 (:func:`stringstab.traffic.state_vector`).
        accel : array_like (n,), optional
            The follower's own acceleration, m/s² (zeros if None; used with ``observe`` "accel").
        prev_gains : array_like (n, 3), optional
            The gains executed at the previous step; None at an episode's first step.

        Returns
        -------
        ndarray (n, 3)
            The executed gains (k_x, k_v, k_a) of eq 4
            (:func:`~stringstab.rl.envs.executed_gains`, as in training).

        Raises
        ------
        StringStabError
            If the policy outputs accelerations.
        """
        from ..traffic.state import extend_state
        from .envs import executed_gains

        s = np.asarray(state, dtype=np.float64).reshape(-1, 3)
        fresh = prev_gains is None
        prev = np.zeros((s.shape[0], 3)) if fresh else np.asarray(prev_gains, np.float64).reshape(-1, 3)
        a = np.zeros(s.shape[0]) if accel is None else np.asarray(accel, np.float64).reshape(-1)
        x = extend_state(s, observe=self.observe, accel=a, prev_gains=prev)
        if self.repair is None:
            raise StringStabError(f"policy of {self.algo!r} outputs accelerations, not gains")
        return executed_gains(self(x), self.repair, prev_gains=None if fresh else prev,
                              gain_rate=self.gain_rate)

    def gains(self, obs: npt.ArrayLike) -> Array:
        """The executed gains of an IDL policy: μ(s) repaired (each certified unless repair off).

        Stateless: for a policy trained with a ``gain_rate`` or ``observe`` extras, use
        :meth:`step_gains`, which is how it runs in training and evaluation.

        Parameters
        ----------
        obs : array_like (..., obs_dim)
            Full policy inputs (eq-16 state plus any ``observe`` extras).

        Returns
        -------
        ndarray (..., 3)
            The repaired gains (k_x, k_v, k_a).

        Raises
        ------
        StringStabError
            If the policy outputs accelerations.
        """
        if self.action != "gains":
            raise StringStabError(f"policy of {self.algo!r} outputs accelerations, not gains")
        K = self(obs)
        shape = K.shape
        K2 = K.reshape(-1, 3)
        assert self.repair is not None
        return self.repair(K2).reshape(shape)

    def save(self, directory: str | os.PathLike[str]) -> Path:
        """Write ``policy.safetensors`` and ``policy.json`` into ``directory`` (created).

        Parameters
        ----------
        directory : str or path-like
            The folder (checked as an output folder, created if absent).

        Returns
        -------
        Path
            The folder.
        """
        d = check_output_dir(directory, what="policy folder")
        d.mkdir(parents=True, exist_ok=True)
        arrays = {k: v.detach().cpu().numpy() for k, v in self.actor.state_dict().items()}
        digest = write_tensors(d / "policy.safetensors", arrays)
        doc = {"format": POLICY_FORMAT, **self.info, "sha256": digest}
        atomic_write_text(d / "policy.json", dumps_json(doc))
        return d


def _need(doc: dict[str, Any], key: str, kind: type | tuple[type, ...], where: str) -> Any:
    v = doc.get(key)
    if isinstance(v, bool) or not isinstance(v, kind):
        raise StringStabError(f"{where}: field {key!r} must be {getattr(kind, '__name__', kind)}; "
                              f"found {v!r}")
    return v


def load_policy(directory: str | os.PathLike[str]) -> Policy:
    """Load a policy saved by :meth:`Policy.save` (or a training run folder holding one).

    Parameters
    ----------
    directory : str or path-like
        A folder holding ``policy.json`` and ``policy.safetensors`` (a training run folder
        does).

    Returns
    -------
    Policy
        The actor with its description (``algo``, ``action``, τ, δ, T*, ``dt``, ``observe``,
        ``gain_rate``, the repair).

    Raises
    ------
    StringStabError
        If the folder or a file is missing, a file was altered or truncated, the JSON is not a
        stringstab policy or lacks a key of :data:`POLICY_KEYS`, or the weights do not fit the
        described network.
    """
    import torch

    from .networks import Actor

    d = Path(directory)
    if not d.is_dir():
        raise StringStabError(f"policy folder {str(d)!r} does not exist; expected a folder with "
                              "policy.json and policy.safetensors")
    where = str(d / "policy.json")
    info = read_json(d / "policy.json", fmt=POLICY_FORMAT, what="policy")
    for key in (*POLICY_KEYS, "sha256"):
        if key not in info:
            raise StringStabError(f"expected key {key!r} in {where}, found keys {sorted(info)}")
    obs_dim = _need(info, "obs_dim", int, where)
    act_dim = _need(info, "act_dim", int, where)
    hidden = _need(info, "hidden", list, where)
    low, high = _need(info, "low", list, where), _need(info, "high", list, where)
    if _need(info, "action", str, where) not in ("gains", "accel"):
        raise StringStabError(f"{where}: action must be 'gains' or 'accel'; found {info['action']!r}")
    if info["action"] == "gains" and act_dim != 3:
        raise StringStabError(f"{where}: a gain policy has act_dim 3; found {act_dim}")
    for key in ("tau", "delta", "headway", "dt"):
        _need(info, key, (int, float), where)
    if len(low) != act_dim or len(high) != act_dim:
        raise StringStabError(f"{where}: low/high must have act_dim={act_dim} entries")
    from ..traffic.state import OBSERVE, state_dim

    observe = info["observe"]
    if (not isinstance(observe, list) or not set(observe) <= set(OBSERVE)
            or len(set(observe)) != len(observe)):
        raise StringStabError(f"{where}: observe must list names from {list(OBSERVE)}; "
                              f"found {observe!r}")
    want_dim = state_dim(observe)
    if observe and obs_dim != want_dim:  # (without extras a custom environment's states may be any size)
        raise StringStabError(f"{where}: obs_dim must be {want_dim} for observe {observe}; "
                              f"found {obs_dim}")
    rate = info["gain_rate"]
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not 0 <= rate < float("inf"):
        raise StringStabError(f"{where}: gain_rate must be a number >= 0; found {rate!r}")
    arrays = read_tensors(d / "policy.safetensors", expected_sha256=_need(info, "sha256", str, where),
                          what="policy")
    try:
        actor = Actor(obs_dim, act_dim, low=low, high=high, hidden=[int(h) for h in hidden])
        want = actor.state_dict()
        if set(arrays) != set(want):
            raise StringStabError(
                f"policy: {str(d / 'policy.safetensors')!r} holds tensors {sorted(arrays)}; "
                f"expected {sorted(want)}")
        actor.load_state_dict({k: torch.as_tensor(np.array(v)) for k, v in arrays.items()})
    except (RuntimeError, ValueError, TypeError) as e:
        if isinstance(e, StringStabError):
            raise
        raise StringStabError(f"policy: weights do not fit the network in {where} ({e})") from e
    info.pop("format", None)
    info.pop("sha256", None)
    return Policy(actor, info, where=where)
