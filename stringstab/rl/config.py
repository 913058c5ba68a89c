"""Configuration of the policy trainer: the IDL paper's Table 1 as defaults, one field per choice.

Three agents share one trainer (:func:`stringstab.rl.train`):

``idl``
    TD3 whose action is the gain triple K = (k_x, k_v, k_a) ∈ [−2, 2]³ of the eq-4 linear law
    (IDL eq 17); every action is repaired to a certified triple before the law acts (§3.3).
``td3``
    pure TD3 whose action is the acceleration u ∈ [acc_min, acc_max] (the paper's baseline 4).
``ddpg``
    pure DDPG, same action (the paper's baseline 3, Zhu et al. 2020 with the IDL reward).

:func:`config_for` builds each from its name.  Every config is a frozen dataclass; integer
fields are integers and every field is checked on construction
(:class:`~stringstab.errors.StringStabError` saying what was expected and what was found).
The JSON form (:meth:`TD3Config.as_dict`, :func:`config_from_dict`) is what checkpoints store.

Where the paper is silent the choice is marked "(not in the paper)" and listed in
``docs/training.md``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Literal

from .. import constants
from ..errors import StringStabError, show
from ..traffic.radio import Radio
from ..traffic.sensors import SensorNoise
from ..tuning.repair import REPAIR_METHODS

__all__ = [
    "ALGOS",
    "IDL_OPTIONS",
    "LOOP_FIELDS",
    "REPAIRS",
    "DDPGConfig",
    "TD3Config",
    "config_for",
    "config_from_dict",
    "loop_from_info",
    "loop_info",
    "sensor_fields",
]

#: Agent names of the command line.
ALGOS: tuple[str, str, str] = ("idl", "td3", "ddpg")
#: Repair methods of the IDL action (``"off"``: the ablation without repair):
#: :data:`stringstab.tuning.repair.REPAIR_METHODS`.
REPAIRS: tuple[str, ...] = REPAIR_METHODS

Action = Literal["gains", "accel"]
#: The fields of the loop as it runs (issues 25 and 26), left out of :meth:`TD3Config.as_dict`
#: at their defaults.
LOOP_FIELDS: tuple[str, str, str] = ("reaction_delay", "radio", "sensors")


def sensor_fields(sensors: SensorNoise) -> dict[str, Any]:
    """A :class:`~stringstab.traffic.SensorNoise` as its constructor's keywords (JSON-ready).

    Parameters
    ----------
    sensors : SensorNoise
        The sensors.

    Returns
    -------
    dict
        ``gap``, ``gap_rate``, ``speed``, ``correlation_time``, ``filter_time``, ``seed``:
        ``SensorNoise(**sensor_fields(s)) == s``.
    """
    return {f.name: getattr(sensors, f.name) for f in dataclasses.fields(sensors)}


@dataclass(frozen=True)
class TD3Config:
    """TD3 (Fujimoto et al. 2018) with the IDL paper's Table 1 settings.

    The default is the IDL agent (``action="gains"``, repair by projection); ``action="accel"``
    is the pure TD3 baseline.
    """

    #: Agent name written to checkpoints ("idl" or "td3" for this class).
    algo: str = "idl"
    #: "gains": the action is K (IDL eq 17); "accel": the action is the acceleration u.
    action: Action = "gains"
    #: Environment steps to train for (summed over the parallel environments).
    total_steps: int = 300_000
    #: Seed of everything: networks, exploration noise, replay sampling, episode order.
    seed: int = 0
    #: Learning rate of the actor, Table 1 ("Learning rate A").
    learning_rate_actor: float = 1e-3
    #: Learning rate of the critic(s), Table 1 ("Learning rate C").
    learning_rate_critic: float = 1e-3
    #: Discount factor γ, Table 1.
    gamma: float = 0.90
    #: Std of the Gaussian exploration noise as a fraction of the half-range of each action
    #: (Table 1: 0.15 for IDL; §5.1(2): 0.25 is best for pure TD3).
    exploration_noise: float = 0.15
    #: Replay memory capacity in transitions, Table 1.
    buffer_size: int = 10_000
    #: Minibatch size, Table 1.
    batch_size: int = 128
    #: Soft (Polyak) update rate of the target networks, Table 1 ("Soft update rate"; CleanRL's
    #: ``tau``, renamed: τ is the actuator lag in this toolkit).
    soft_update: float = 0.01
    #: Critic updates per actor and target update, Table 1 ("Policy target update interval").
    policy_delay: int = 3
    #: Std of the target-policy smoothing noise, fraction of the action half-range (not in the
    #: paper; Fujimoto et al.'s 0.2).
    target_policy_noise: float = 0.2
    #: Clip of the smoothing noise, fraction of the half-range (not in the paper; Fujimoto's 0.5).
    noise_clip: float = 0.5
    #: Value of the state after a collision (a termination) in the critic's target; None: the
    #: penalty p_e (Table 2) at every remaining step, p_e (ω1 + ω2 + ω3)/(1 − γ).  The paper ends
    #: training events at a collision without saying what that end is worth; with rewards in
    #: [−1, 0] a value of 0 would make crashing the cheapest way out of a bad episode.
    collision_value: float | None = None
    #: Hidden layer widths of the actor and critics (2 × 128 ReLU, §4.1.3).
    hidden: tuple[int, ...] = (128, 128)
    #: Environment steps of uniform random actions before learning (not in the paper).
    learning_starts: int = 2_000
    #: Gradient updates per vector step of the environments (not in the paper).
    updates_per_step: int = 1
    #: Parallel environments stepped together (not in the paper; its events run one at a time).
    num_envs: int = 8
    #: Stop after this many collision-free episode ends (§4.1.2: 700); 0 disables the rule.
    stop_episodes: int = 700
    #: Repair of the proposed gains before the eq-4 law acts (§3.3): "projection" (nearest
    #: certified gains, by certified lookup; the default), "projection-exact"
    #: (:class:`stringstab.tuning.Projector`), "region-growing" (the paper's search, with a
    #: projection where its output is not certified) or "off" (the ablation).
    repair: str = "projection"
    #: Spacing of the certified lattice of the "projection" repair, in gain units.
    repair_resolution: float = 0.05
    #: Bisection steps from the lattice point towards the proposed gains (each one exact check).
    repair_refine: int = 4
    #: Certify executed gains also for the sampled-data loop at the control step ``dt`` (zero-order
    #: hold; :mod:`stringstab.certify.sampled`), which is the loop the simulator runs.
    repair_sampled: bool = True
    #: Which action the replay buffer stores: "proposed" (the actor's, before the repair; the
    #: repair is then part of the environment) or "executed" (after the repair).
    store_action: str = "proposed"
    #: Weight λ of a penalty λ·mean ‖(μ(s) − R(μ(s)))/half-range‖² added to the actor loss, R the
    #: repair (not in the paper).  With the proposed action stored, the repair is part of the
    #: environment and Q is flat along the directions the projection collapses, so without it
    #: the actor drifts to the corners of the gain box; 0 disables it (it acts only with a repair).
    proposal_penalty: float = 1.0
    #: Largest change of each executed gain per control step, gain units (not in the paper; 0:
    #: off).  The proposal is clipped to within ``gain_rate`` of the previous executed gains,
    #: then repaired (:class:`stringstab.rl.envs.RepairedGains`).  Much of an IDL policy's jerk
    #: (M_CI) can come from its gains changing every step (u = K·Y jumps when K does;
    #: docs/training.md).  Use with ``observe`` containing "gains" (the limit makes the
    #: previous gains part of the state).
    gain_rate: float = 0.0
    #: Extras appended to the eq-16 state (not in the paper): "accel" (the follower's own
    #: acceleration, which the comfort reward of eq 21 penalises changes of and eq 16 omits)
    #: and "gains" (the gains executed at the previous step).
    observe: tuple[str, ...] = ()
    #: Random start of training episodes off equilibrium (not in the paper): initial gap scaled by
    #: 1 + s_g·U(−1, 1) and speed offset by s_v·U(−1, 1), (s_g, s_v) in (fraction, m/s); NGSIM
    #: pairs start as recorded.  (0, 0): every episode starts in equilibrium, where training
    #: may meet no collision and so teach nothing about avoiding one (docs/training.md).
    start_spread: tuple[float, float] = (0.0, 0.0)
    #: TTC* of the safety reward (eq 20), s.  Table 2's 3 s is also the threshold of the TIT
    #: metric (eq 31); a larger value in the reward (not in the paper) is a safety margin: the
    #: agent is penalised before the metric counts, so it learns to keep TTC above 3 s.
    reward_ttc_star: float = constants.TTC_STAR
    #: Actuator lag τ, s (not printed by the paper; 0.1 s as in its reference Zhou et al. 2020).
    tau: float = constants.TAU
    #: Communication delay δ, s (Table 2).
    delta: float = constants.DELTA
    #: Desired time headway T*, s (Table 2).
    headway: float = constants.HEADWAY
    #: Control and simulation step Δt, s (NGSIM's 10 Hz, §4.1.1).
    dt: float = constants.DT
    #: Reward weights ω1, ω2, ω3 of eq 18 (Table 2).
    weights: tuple[float, float, float] = constants.REWARD_WEIGHTS
    #: Length of a training episode cut from a driving cycle, s (not in the paper: its events
    #: are NGSIM pairs of at least 15 s).
    episode_seconds: float = 30.0
    #: Environment steps between checkpoints of a run folder.
    checkpoint_every: int = 20_000
    #: torch CPU threads (small: the machine is shared and the networks are tiny).
    torch_threads: int = 1
    #: Reaction (actuation) delay θ_r of the follower, s (issue 25; not in the paper): the
    #: vehicle applies its command θ_r late, τ ȧ = u(t − θ_r) − a, integrated exactly
    #: (:mod:`stringstab.traffic.dynamics`); the repair certifies with it (the continuous
    #: certificate with ``reaction_delay`` and, with ``repair_sampled``, the sampled-data one
    #: with θ_r at ``dt``).  0 (default) changes nothing, bit for bit.
    reaction_delay: float = 0.0
    #: The follower's V2V radio (issue 26; :class:`stringstab.traffic.Radio`: message period,
    #: loss, staleness and fallback); None (default): the predecessor's acceleration every step.
    radio: Radio | None = None
    #: The follower's sensors (:class:`stringstab.traffic.SensorNoise`: noise and a filter on
    #: the gap, gap rate and own speed); None (default): exact measurements.
    sensors: SensorNoise | None = None

    # -- construction -------------------------------------------------------------------
    def __post_init__(self) -> None:
        _check(self)

    def as_dict(self) -> dict[str, Any]:
        """The config as JSON-ready plain values (with ``"class"``).

        ``reaction_delay``, ``radio`` and ``sensors`` are left out at their defaults (0, None,
        None), so a config without them writes what it always wrote.
        """
        d = dataclasses.asdict(self)
        for name in LOOP_FIELDS:
            d.pop(name)
        if self.reaction_delay:
            d["reaction_delay"] = self.reaction_delay
        if self.radio is not None:
            d["radio"] = self.radio.describe()
        if self.sensors is not None:
            d["sensors"] = sensor_fields(self.sensors)
        d["hidden"] = list(self.hidden)
        d["weights"] = list(self.weights)
        d["observe"] = list(self.observe)
        d["start_spread"] = list(self.start_spread)
        return {"class": type(self).__name__, **d}

    def replace(self, **changes: Any) -> TD3Config:
        """A copy with some fields changed (checked again)."""
        return dataclasses.replace(self, **changes)

    @property
    def terminal_value(self) -> float:
        """The value used for a terminated (collided) next state (see ``collision_value``)."""
        if self.collision_value is not None:
            return float(self.collision_value)
        return constants.PENALTY * float(sum(self.weights)) / (1.0 - self.gamma)

    @property
    def twin_critics(self) -> bool:
        """TD3 uses two critics and the smaller target (clipped double Q-learning)."""
        return True

    @property
    def smoothing(self) -> bool:
        """TD3 smooths the target policy with clipped noise."""
        return True

    @property
    def gain_bounds(self) -> tuple[float, float]:
        """Range of each gain, Table 2."""
        return constants.GAIN_BOUNDS

    @property
    def accel_bounds(self) -> tuple[float, float]:
        """Range of the acceleration action, Table 1 ("Action bound") and Table 2."""
        return (constants.ACCEL_MIN, constants.ACCEL_MAX)


@dataclass(frozen=True)
class DDPGConfig(TD3Config):
    """DDPG (Lillicrap et al. 2015): one critic, no target smoothing, actor updated every step.

    Table 1's shared settings are kept (the paper trains its DDPG baseline with the same reward
    and does not list separate values); the default action is the acceleration.
    """

    algo: str = "ddpg"
    action: Action = "accel"
    policy_delay: int = 1
    target_policy_noise: float = 0.0
    noise_clip: float = 0.0
    repair: str = "off"

    @property
    def twin_critics(self) -> bool:
        """DDPG uses a single critic (no clipped double Q-learning)."""
        return False

    @property
    def smoothing(self) -> bool:
        """DDPG does not smooth the target policy."""
        return False


_INT_FIELDS = ("total_steps", "seed", "buffer_size", "batch_size", "policy_delay",
               "learning_starts", "updates_per_step", "num_envs", "stop_episodes",
               "repair_refine", "checkpoint_every", "torch_threads")
_MIN_INT = {"total_steps": 1, "seed": 0, "buffer_size": 1, "batch_size": 1, "policy_delay": 1,
            "learning_starts": 0, "updates_per_step": 1, "num_envs": 1, "stop_episodes": 0,
            "repair_refine": 0, "checkpoint_every": 1, "torch_threads": 1}
_POSITIVE = ("learning_rate_actor", "learning_rate_critic", "soft_update", "repair_resolution",
             "tau", "dt", "episode_seconds", "reward_ttc_star")
_NONNEG = ("gain_rate", "proposal_penalty", "exploration_noise", "target_policy_noise", "noise_clip", "delta", "headway")


def _check(c: TD3Config) -> None:
    for name in _INT_FIELDS:
        v = getattr(c, name)
        if isinstance(v, bool) or not isinstance(v, int):
            raise StringStabError(f"config field {name} must be an integer; got {show(v)}")
        if v < _MIN_INT[name]:
            raise StringStabError(f"config field {name} must be >= {_MIN_INT[name]}; got {v}")
    for name in (*_POSITIVE, *_NONNEG, "gamma"):
        v = getattr(c, name)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise StringStabError(f"config field {name} must be a finite number; got {show(v)}")
        if name in _POSITIVE and not v > 0:
            raise StringStabError(f"config field {name} must be > 0; got {v!r}")
        if name in _NONNEG and v < 0:
            raise StringStabError(f"config field {name} must be >= 0; got {v!r}")
    if c.collision_value is not None and (
            isinstance(c.collision_value, bool) or not isinstance(c.collision_value, (int, float))
            or not math.isfinite(c.collision_value)):
        raise StringStabError(
            f"config field collision_value must be a finite number or None; got {show(c.collision_value)}")
    if not 0 <= c.gamma < 1:
        raise StringStabError(f"config field gamma must be in [0, 1); got {c.gamma!r}")
    if c.soft_update > 1:
        raise StringStabError(f"config field soft_update must be in (0, 1]; got {c.soft_update!r}")
    if c.algo not in ALGOS:
        raise StringStabError(f"config field algo must be one of {list(ALGOS)}; got {c.algo!r}")
    if c.action not in ("gains", "accel"):
        raise StringStabError(f"config field action must be 'gains' or 'accel'; got {c.action!r}")
    if c.repair not in REPAIRS:
        raise StringStabError(f"config field repair must be one of {list(REPAIRS)}; got {c.repair!r}")
    if not isinstance(c.repair_sampled, bool):
        raise StringStabError(f"config field repair_sampled must be true or false; got {show(c.repair_sampled)}")
    if c.store_action not in ("proposed", "executed"):
        raise StringStabError(
            f"config field store_action must be 'proposed' or 'executed'; got {c.store_action!r}")
    hidden = tuple(c.hidden)
    if not hidden or any(isinstance(h, bool) or not isinstance(h, int) or h < 1 for h in hidden):
        raise StringStabError(f"config field hidden must be positive integers; got {show(c.hidden)}")
    object.__setattr__(c, "hidden", hidden)
    w = tuple(float(x) for x in c.weights)
    if len(w) != 3 or not all(math.isfinite(x) and x >= 0 for x in w):
        raise StringStabError(f"config field weights must be 3 numbers >= 0; got {show(c.weights)}")
    object.__setattr__(c, "weights", w)
    from ..traffic.state import OBSERVE

    obs = tuple(c.observe) if isinstance(c.observe, (list, tuple)) else None
    if obs is None or not set(obs) <= set(OBSERVE) or len(set(obs)) != len(obs):
        raise StringStabError(
            f"config field observe must list distinct names from {list(OBSERVE)}; got {show(c.observe)}")
    object.__setattr__(c, "observe", tuple(x for x in OBSERVE if x in obs))
    try:
        sp = tuple(float(x) for x in c.start_spread)
    except (TypeError, ValueError) as e:
        raise StringStabError(
            f"config field start_spread must be 2 numbers >= 0; got {show(c.start_spread)}") from e
    if len(sp) != 2 or not all(math.isfinite(x) and x >= 0 for x in sp):
        raise StringStabError(f"config field start_spread must be 2 numbers >= 0; got {show(c.start_spread)}")
    object.__setattr__(c, "start_spread", sp)
    if c.gain_rate > 0 and c.action != "gains":
        raise StringStabError(f"config field gain_rate needs action 'gains'; got action {c.action!r}")
    _check_loop(c)
    if c.batch_size > c.buffer_size:
        raise StringStabError(
            f"config field batch_size ({c.batch_size}) must not exceed buffer_size ({c.buffer_size})")


def _check_loop(c: TD3Config) -> None:
    """θ_r, the radio and the sensors (issues 25, 26): their types, θ_r's range, the refusal."""
    from ..params import check_reaction_delay

    if isinstance(c.reaction_delay, bool):
        raise StringStabError(f"config field reaction_delay must be a number of seconds >= 0; "
                              f"got {show(c.reaction_delay)}")
    theta = check_reaction_delay(c.reaction_delay, "config field reaction_delay (reaction delay θ_r)")
    object.__setattr__(c, "reaction_delay", theta)
    if c.radio is not None and not isinstance(c.radio, Radio):
        raise StringStabError(f"config field radio must be a stringstab.traffic.Radio or None; "
                              f"got {type(c.radio).__name__}")
    if c.sensors is not None and not isinstance(c.sensors, SensorNoise):
        raise StringStabError(f"config field sensors must be a stringstab.traffic.SensorNoise or "
                              f"None; got {type(c.sensors).__name__}")
    if c.radio is not None and c.radio.message_period is not None:
        from ..traffic.radio import message_steps

        message_steps(c.radio.message_period, c.dt)  # a whole multiple of the step, or one line
    if theta > 0 and c.action == "gains" and c.repair != "off" and c.repair_sampled:
        from ..certify.lifting_reaction import check_reaction_sampled

        check_reaction_sampled(theta, c.dt)  # at most 2,000 steps of dt, or one line


def loop_info(config: TD3Config) -> dict[str, Any]:
    """The loop a policy was trained in, for its ``policy.json`` (only what is not default).

    Parameters
    ----------
    config : TD3Config
        The training config.

    Returns
    -------
    dict
        ``reaction_delay`` (s) when θ_r > 0, ``radio`` (:meth:`Radio.describe
        <stringstab.traffic.Radio.describe>`) and ``sensors`` (:func:`sensor_fields`) when set;
        empty at the defaults, so a policy without them is saved as before.
    """
    d = config.as_dict()
    return {k: d[k] for k in LOOP_FIELDS if k in d}


def loop_from_info(info: Any) -> tuple[float, Radio | None, SensorNoise | None]:
    """θ_r, the radio and the sensors of a saved policy's info (:func:`loop_info` read back).

    Parameters
    ----------
    info : mapping
        The policy's info (``policy.json``).

    Returns
    -------
    (float, Radio or None, SensorNoise or None)
        θ_r (0 when absent), the radio and the sensors (None when absent).

    Raises
    ------
    StringStabError
        If an entry is malformed (one line naming it).
    """
    from ..params import check_reaction_delay

    theta = check_reaction_delay(info.get("reaction_delay", 0.0), "policy reaction_delay (θ_r)")
    parts: list[Any] = []
    for key, kind in (("radio", Radio), ("sensors", SensorNoise)):
        doc = info.get(key)
        if doc is None:
            parts.append(None)
            continue
        if not isinstance(doc, dict):
            raise StringStabError(f"policy {key}: expected a JSON object; found {doc!r}")
        sub = dict(doc)
        if key == "radio" and isinstance(sub.get("fallback_gains"), list):
            sub["fallback_gains"] = tuple(sub["fallback_gains"])
        try:
            parts.append(kind(**sub))
        except TypeError as e:
            raise StringStabError(f"policy {key}: {e}") from e
    return theta, parts[0], parts[1]


#: The options ``config_for("idl")`` adds to :class:`TD3Config` (none in the paper; chosen on
#: a validation split of the training episodes by
#: ``analysis/train_validate.py``, see docs/training.md).  ``config_for("idl", paper=True)``
#: leaves them out.
IDL_OPTIONS: dict[str, Any] = {"gain_rate": 0.02, "observe": ("accel", "gains"),
                               "start_spread": (0.3, 3.0)}


def config_for(algo: str, *, paper: bool = False, **overrides: Any) -> TD3Config:
    """The config of agent ``algo`` ("idl", "td3" or "ddpg") with ``overrides``.

    ``idl`` is :class:`TD3Config` with gain actions, the projection repair and
    :data:`IDL_OPTIONS` (without them when ``paper`` is true: the eq-16 state, no gain rate
    limit, episodes started in equilibrium); ``td3`` is
    :class:`TD3Config` with acceleration actions and exploration noise 0.25 (the best for pure
    TD3 in the paper's §5.1(2)); ``ddpg`` is :class:`DDPGConfig`.

    Parameters
    ----------
    algo : {"idl", "td3", "ddpg"}
        The agent: IDL (TD3 choosing the gains of eq 4, eq 17), pure TD3 or DDPG choosing the
        acceleration.
    paper : bool, default False
        For ``"idl"``, leave out :data:`IDL_OPTIONS` (the paper's set-up); ignored otherwise.
    **overrides
        Config fields to set, applied last (they win over the defaults above).

    Returns
    -------
    TD3Config
        A :class:`TD3Config` (or :class:`DDPGConfig`, a subclass), every field checked.

    Raises
    ------
    StringStabError
        On an unknown ``algo`` or an invalid field.

    Examples
    --------
    >>> config_for("td3").action, config_for("td3").exploration_noise
    ('accel', 0.25)
    >>> config_for("idl").gain_rate > 0, config_for("idl", paper=True).gain_rate
    (True, 0.0)
    >>> config_for("ppo")
    Traceback (most recent call last):
    ...
    stringstab.errors.StringStabError: --algo must be one of idl, td3, ddpg; got 'ppo'
    """
    if algo == "idl":
        return TD3Config(**{"algo": "idl", "action": "gains", **({} if paper else IDL_OPTIONS),
                            **overrides})
    if algo == "td3":
        return TD3Config(**{"algo": "td3", "action": "accel", "exploration_noise": 0.25,
                            "repair": "off", **overrides})
    if algo == "ddpg":
        return DDPGConfig(**{"algo": "ddpg", **overrides})
    raise StringStabError(f"--algo must be one of {', '.join(ALGOS)}; got {algo!r}")


def config_from_dict(doc: Any, *, source: str = "config") -> TD3Config:
    """Rebuild a config from :meth:`TD3Config.as_dict` output, checking every field.

    JSON lists are turned back into the tuples the fields hold (``hidden``, ``weights``,
    ``observe``, ``start_spread``).

    Parameters
    ----------
    doc : object
        The decoded JSON: a mapping with ``class`` (``"TD3Config"`` or ``"DDPGConfig"``) and
        config fields.
    source : str
        What ``doc`` was read from, for the error messages.

    Returns
    -------
    TD3Config
        The config (a :class:`DDPGConfig` for ``class: "DDPGConfig"``).

    Raises
    ------
    StringStabError
        If ``doc`` is not such a mapping (unknown class or field, wrong type or value).
    """
    if not isinstance(doc, dict):
        raise StringStabError(f"{source}: expected a JSON object; found {type(doc).__name__}")
    d = dict(doc)
    cls_name = d.pop("class", None)
    classes: dict[str, type[TD3Config]] = {"TD3Config": TD3Config, "DDPGConfig": DDPGConfig}
    if cls_name not in classes:
        raise StringStabError(f"{source}: expected class TD3Config or DDPGConfig; found {cls_name!r}")
    cls = classes[cls_name]
    names = {f.name for f in dataclasses.fields(cls)}
    unknown = sorted(set(d) - names)
    if unknown:
        raise StringStabError(f"{source}: unknown config fields {unknown}")
    if "hidden" in d and isinstance(d["hidden"], list):
        d["hidden"] = tuple(d["hidden"])
    for key in ("weights", "observe", "start_spread"):
        if key in d and isinstance(d[key], list):
            d[key] = tuple(d[key])
    if isinstance(d.get("radio"), dict) or isinstance(d.get("sensors"), dict):
        _, radio, sensors = loop_from_info({k: d.get(k) for k in ("radio", "sensors")})
        d["radio"], d["sensors"] = radio, sensors
    try:
        return cls(**d)
    except TypeError as e:
        raise StringStabError(f"{source}: {e}") from e

