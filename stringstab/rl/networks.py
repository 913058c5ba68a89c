"""The actor and critic networks (IDL paper §4.1.3, Table 1): 2 × 128 ReLU MLPs, Glorot init.

The actor's last layer is a tanh scaled to the environment's action bounds (Table 1, "Output
activation: tanh"); the critic maps (state, action) to one Q-value.  Weights are initialised
Glorot-uniform (Table 1, "Initializer"; :func:`torch.nn.init.xavier_uniform_`) with zero biases,
as in Keras, the paper's framework.  Shapes follow CleanRL's ``td3_continuous_action.py``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
import torch
from torch import nn

__all__ = ["Actor", "QNetwork", "mlp"]


def mlp(n_in: int, hidden: Sequence[int], n_out: int) -> nn.Sequential:
    """Linear–ReLU layers of widths ``hidden``, then a linear output; Glorot-uniform weights.

    Parameters
    ----------
    n_in : int
        Input width (the state's length, or state + action for a critic).
    hidden : sequence of int
        Hidden layer widths (Table 1: 128, 128).
    n_out : int
        Output width.

    Returns
    -------
    torch.nn.Sequential
        The network, weights Glorot-uniform and biases zero (Table 1, as in Keras).
    """
    layers: list[nn.Module] = []
    width = n_in
    for h in hidden:
        layers += [nn.Linear(width, int(h)), nn.ReLU()]
        width = int(h)
    layers.append(nn.Linear(width, n_out))
    for m in layers:
        if isinstance(m, nn.Linear):
            nn.init.xavier_uniform_(m.weight)
            nn.init.zeros_(m.bias)
    return nn.Sequential(*layers)


class Actor(nn.Module):
    """Deterministic policy μ(s): tanh output scaled to [low, high] per action dimension.

    Examples
    --------
    >>> import torch
    >>> _ = torch.manual_seed(0)
    >>> a = Actor(3, 3, low=[-2, -2, -2], high=[2, 2, 2])
    >>> out = a(torch.zeros(5, 3))
    >>> tuple(out.shape), bool((out.abs() <= 2).all())
    ((5, 3), True)
    """

    action_scale: torch.Tensor
    action_bias: torch.Tensor

    def __init__(self, obs_dim: int, act_dim: int, *, low: npt.ArrayLike, high: npt.ArrayLike,
                 hidden: Sequence[int] = (128, 128)) -> None:
        super().__init__()
        lo = np.asarray(low, dtype=np.float32).reshape(act_dim)
        hi = np.asarray(high, dtype=np.float32).reshape(act_dim)
        self.net = mlp(obs_dim, hidden, act_dim)
        self.register_buffer("action_scale", torch.as_tensor((hi - lo) / 2.0))
        self.register_buffer("action_bias", torch.as_tensor((hi + lo) / 2.0))

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        """μ(s) = tanh(net(s)) · scale + bias: the action within [low, high].

        Parameters
        ----------
        obs : torch.Tensor (n, obs_dim)
            States.

        Returns
        -------
        torch.Tensor (n, act_dim)
            Actions in environment units.
        """
        return torch.tanh(self.net(obs)) * self.action_scale + self.action_bias


class QNetwork(nn.Module):
    """Critic Q(s, a) on the concatenated state and action (actions in environment units)."""

    def __init__(self, obs_dim: int, act_dim: int, *, hidden: Sequence[int] = (128, 128)) -> None:
        super().__init__()
        self.net = mlp(obs_dim + act_dim, hidden, 1)

    def forward(self, obs: torch.Tensor, act: torch.Tensor) -> torch.Tensor:
        """Q(s, a) of each state-action pair.

        Parameters
        ----------
        obs : torch.Tensor (n, obs_dim)
            States.
        act : torch.Tensor (n, act_dim)
            Actions, environment units.

        Returns
        -------
        torch.Tensor (n, 1)
            The Q-values.
        """
        return self.net(torch.cat([obs, act], dim=1))
