"""The update rules: TD3 (Fujimoto et al. 2018) and DDPG (Lillicrap et al. 2015), CleanRL-shaped.

One :class:`Agent` holds the actor, the critic(s), their targets and Adam optimisers (Table 1).
:meth:`Agent.update` is one gradient step on a minibatch:

* critic: minimise the mean squared error to y = r + γ [(1 − d) Q'(s', a') + d V_c] (Table 1,
  "Loss critic"; d = 1 after a collision, whose value V_c is ``config.terminal_value``); TD3 takes the smaller of two target critics (clipped double Q-learning) and smooths
  the target action, a' = clip(μ'(s') + clip(ε, −c, c)), ε ~ N(0, σ̃²) (§3.4 (2), (5));
  DDPG uses one critic and a' = μ'(s');
* actor: every ``policy_delay`` critic updates (Table 1: 3 for TD3; 1 for DDPG), minimise
  −mean Q1(s, μ(s)) (Table 1, "Loss actor") plus, optionally, ``proposal_penalty`` times the
  squared distance of μ(s) to its repair (``action_filter``; not in the paper), then move every target network towards its network
  by the soft update rate (Table 1: 0.01).

Noise scales are fractions of the action half-range (the actor's ``action_scale``), so one
setting serves gains in [−2, 2] and accelerations in [−7.6, 3] m/s².
"""

from __future__ import annotations

import copy
import json
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt
import torch
import torch.nn.functional as F

from ..errors import StringStabError
from .config import TD3Config
from .networks import Actor, QNetwork

__all__ = ["Agent"]


class Agent:
    """Networks, targets and optimisers of one TD3 or DDPG learner.

    Parameters
    ----------
    config : TD3Config or DDPGConfig
        Hyper-parameters (``twin_critics`` and ``smoothing`` tell TD3 from DDPG).
    obs_dim, act_dim : int
        State and action sizes.
    low, high : sequence of float
        Action bounds (environment units).
    """

    def __init__(self, config: TD3Config, obs_dim: int, act_dim: int, *,
                 low: npt.ArrayLike, high: npt.ArrayLike,
                 action_filter: Callable[[npt.NDArray[np.float64]], npt.ArrayLike] | None = None
                 ) -> None:
        self.config = config
        self.action_filter = action_filter
        self.low = torch.as_tensor(np.asarray(low, dtype=np.float32).reshape(act_dim))
        self.high = torch.as_tensor(np.asarray(high, dtype=np.float32).reshape(act_dim))
        self.actor = Actor(obs_dim, act_dim, low=self.low.numpy(), high=self.high.numpy(),
                           hidden=config.hidden)
        self.actor_target = copy.deepcopy(self.actor)
        n_q = 2 if config.twin_critics else 1
        self.critics = [QNetwork(obs_dim, act_dim, hidden=config.hidden) for _ in range(n_q)]
        self.critic_targets = [copy.deepcopy(q) for q in self.critics]
        self.actor_optimizer = torch.optim.Adam(self.actor.parameters(),
                                                lr=config.learning_rate_actor)
        self.critic_optimizer = torch.optim.Adam(
            [p for q in self.critics for p in q.parameters()], lr=config.learning_rate_critic)
        self.n_updates = 0

    # -- acting -----------------------------------------------------------------------------
    @torch.no_grad()
    def act(self, obs: npt.ArrayLike) -> npt.NDArray[np.float32]:
        """μ(s) for a batch of states, in environment units (no exploration noise).

        Parameters
        ----------
        obs : array_like (n, obs_dim)
            States (the eq-16 state of the IDL paper, with any ``observe`` extras).

        Returns
        -------
        ndarray (n, act_dim), float32
            The actor's actions: gains (eq 17) or accelerations (m/s²), within the action bounds.
        """
        x = torch.as_tensor(np.asarray(obs, dtype=np.float32))
        return np.asarray(self.actor(x).numpy(), dtype=np.float32)

    # -- learning ---------------------------------------------------------------------------
    def update(self, batch: dict[str, npt.NDArray[np.float32]]) -> dict[str, float]:
        """One critic step (and, every ``policy_delay`` steps, one actor and target step).

        The critic target is y = r + γ ((1 − d) min_j Q'_j(s', μ'(s') + ε) + d V_term), with
        target policy smoothing ε (TD3) when enabled, the minimum over twin critics (TD3; one
        critic for DDPG), and V_term = ``terminal_value`` for a terminated next state.  The actor
        maximises Q_1(s, μ(s)) (minus the proposal penalty, if set); targets are updated softly
        with rate ``soft_update``.

        Parameters
        ----------
        batch : dict of str to ndarray (float32)
            ``obs``, ``actions``, ``rewards`` (n, 1), ``next_obs``, ``dones`` (n, 1)
            (:meth:`ReplayBuffer.sample`).

        Returns
        -------
        dict of str to float
            ``critic_loss``, and ``actor_loss`` on the steps where the actor was updated.
        """
        c = self.config
        obs, act = torch.as_tensor(batch["obs"]), torch.as_tensor(batch["actions"])
        rew, nxt = torch.as_tensor(batch["rewards"]), torch.as_tensor(batch["next_obs"])
        done = torch.as_tensor(batch["dones"])
        scale: torch.Tensor = self.actor.action_scale
        with torch.no_grad():
            a2 = self.actor_target(nxt)
            if c.smoothing:
                eps = (torch.randn_like(a2) * c.target_policy_noise).clamp(-c.noise_clip, c.noise_clip)
                a2 = torch.clamp(a2 + eps * scale, self.low, self.high)
            q_next = self.critic_targets[0](nxt, a2)
            for qt in self.critic_targets[1:]:
                q_next = torch.minimum(q_next, qt(nxt, a2))
            # a terminated (collided) next state is worth ``terminal_value``, not 0
            y = rew + c.gamma * ((1.0 - done) * q_next + done * c.terminal_value)
        q_loss = sum((F.mse_loss(q(obs, act), y) for q in self.critics), torch.zeros(()))
        self.critic_optimizer.zero_grad()
        q_loss.backward()
        self.critic_optimizer.step()
        self.n_updates += 1
        out = {"critic_loss": float(q_loss.item())}
        if self.n_updates % c.policy_delay == 0:
            mu = self.actor(obs)
            actor_loss = -self.critics[0](obs, mu).mean()
            if c.proposal_penalty > 0 and self.action_filter is not None:
                with torch.no_grad():
                    executed = torch.as_tensor(np.asarray(
                        self.action_filter(mu.numpy().astype(np.float64)), dtype=np.float32))
                gap = (mu - executed) / scale
                actor_loss = actor_loss + c.proposal_penalty * (gap * gap).sum(dim=1).mean()
            self.actor_optimizer.zero_grad()
            actor_loss.backward()
            self.actor_optimizer.step()
            with torch.no_grad():
                for net, tgt in [(self.actor, self.actor_target),
                                 *zip(self.critics, self.critic_targets)]:
                    for p, pt in zip(net.parameters(), tgt.parameters()):
                        pt.mul_(1.0 - c.soft_update).add_(p, alpha=c.soft_update)
            out["actor_loss"] = float(actor_loss.item())
        return out

    # -- checkpoints --------------------------------------------------------------------------
    def _modules(self) -> dict[str, torch.nn.Module]:
        mods: dict[str, torch.nn.Module] = {"actor": self.actor, "actor_target": self.actor_target}
        for i, (q, qt) in enumerate(zip(self.critics, self.critic_targets)):
            mods[f"critic{i}"] = q
            mods[f"critic{i}_target"] = qt
        return mods

    def _optimizers(self) -> dict[str, torch.optim.Optimizer]:
        return {"actor": self.actor_optimizer, "critic": self.critic_optimizer}

    def state(self) -> tuple[dict[str, Any], dict[str, torch.Tensor]]:
        """(JSON-ready meta, flat tensors) of every network and optimiser."""
        tensors: dict[str, torch.Tensor] = {}
        for name, m in self._modules().items():
            for k, v in m.state_dict().items():
                tensors[f"{name}.{k}"] = v.detach().clone().contiguous()
        groups: dict[str, Any] = {}
        for name, opt in self._optimizers().items():
            sd = opt.state_dict()
            groups[name] = sd["param_groups"]
            for idx, st in sd["state"].items():
                for k, v in st.items():
                    t = v if isinstance(v, torch.Tensor) else torch.tensor(v)
                    tensors[f"optim.{name}.{idx}.{k}"] = t.detach().clone().reshape(-1).contiguous()
        meta = {"n_updates": self.n_updates, "param_groups": json.loads(json.dumps(groups))}
        return meta, tensors

    def load_state(self, meta: dict[str, Any], tensors: dict[str, torch.Tensor]) -> None:
        """Restore :meth:`state` output; refuses missing or mis-shaped tensors.

        Parameters
        ----------
        meta : dict
            The JSON-ready part of :meth:`state` (``n_updates``, the optimisers' parameter groups).
        tensors : dict of str to torch.Tensor
            Networks, targets and Adam moments, by name.

        Raises
        ------
        StringStabError
            If a tensor is missing or does not fit this agent's networks.
        """
        try:
            for name, m in self._modules().items():
                want = m.state_dict()
                sd = {k: tensors[f"{name}.{k}"] for k in want}
                for k, v in sd.items():
                    if tuple(v.shape) != tuple(want[k].shape):
                        raise StringStabError(
                            f"checkpoint tensor {name}.{k}: expected shape {tuple(want[k].shape)}; "
                            f"found {tuple(v.shape)}")
                m.load_state_dict(sd)
            for name, opt in self._optimizers().items():
                state: dict[int, dict[str, torch.Tensor]] = {}
                prefix = f"optim.{name}."
                for key, v in tensors.items():
                    if key.startswith(prefix):
                        i_str, k = key[len(prefix):].split(".", 1)
                        state.setdefault(int(i_str), {})[k] = v.reshape(()) if k == "step" else v
                # the moment tensors have the shapes of their parameters
                params = [p for g in opt.param_groups for p in g["params"]]
                for idx, st in state.items():
                    for k in ("exp_avg", "exp_avg_sq"):
                        if k in st:
                            st[k] = st[k].reshape(params[idx].shape)
                opt.load_state_dict({"state": state, "param_groups": meta["param_groups"][name]})
        except KeyError as e:
            raise StringStabError(f"checkpoint: missing tensor {e}") from e
        except (RuntimeError, ValueError, IndexError) as e:
            if isinstance(e, StringStabError):
                raise
            raise StringStabError(f"checkpoint: tensors do not fit this agent ({e})") from e
        self.n_updates = int(meta["n_updates"])
