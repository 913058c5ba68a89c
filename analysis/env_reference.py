"""Record the IDL training environment's outputs for ``tests/rl/test_env_reference.py``.

Steps ``make_env(config_for("idl", num_envs=n, seed=0, repair="off"))`` (the car-following
env behind the clip and rate-limit wrapper, no repair) ``--steps`` times with seeded random
gains K ~ U[−3, 3]³ (so that some episodes end in collisions and restart), for n = 1 and 3, and
writes the states, rewards, ends and the step's info arrays to an ``.npz``.  Run it on the base
commit to record the reference (issue 31: the env's outputs stay bit for bit what they were)::

    git archive f6db69e stringstab | tar -x -C /tmp/base
    PYTHONPATH=/tmp/base python analysis/env_reference.py tests/data/env_f6db69e.npz
"""

from __future__ import annotations

import argparse

import numpy as np

INFO = ("gap", "speed", "accel", "command", "ttc", "headway", "r_f", "r_j", "r_e", "collision",
        "leader_index", "t", "gains", "episode_return")


def rollout(num_envs: int, steps: int) -> dict[str, np.ndarray]:
    """States, rewards, ends and info arrays of ``steps`` seeded steps, stacked along axis 0."""
    from stringstab.rl import config_for
    from stringstab.rl.envs import make_env

    envs = make_env(config_for("idl", num_envs=num_envs, seed=0, repair="off"))
    s, _ = envs.reset(seed=0)
    rng = np.random.default_rng(7)
    rows: dict[str, list[np.ndarray]] = {"state": [np.asarray(s)]}
    for _ in range(steps):
        a = rng.uniform(-3.0, 3.0, (num_envs, 3)).astype(np.float32)
        s, r, term, trunc, info = envs.step(a)
        for k, v in (("state", s), ("reward", r), ("terminated", term), ("truncated", trunc),
                     *((k, info[k]) for k in INFO)):
            rows.setdefault(k, []).append(np.asarray(v))
    return {k: np.stack(v) for k, v in rows.items()}


def main(argv: list[str] | None = None) -> None:
    """Write the reference ``.npz``."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--steps", type=int, default=400)
    args = ap.parse_args(argv)
    out = {f"n{n}_{k}": v for n in (1, 3) for k, v in rollout(n, args.steps).items()}
    np.savez_compressed(args.out, **out)


if __name__ == "__main__":
    main()
