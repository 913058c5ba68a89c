"""Record the simulator's outputs before θ_r and the radio existed, for the bit-for-bit tests.

Run once, at commit bb1b890 of ``main`` (before the reaction delay θ_r and the radio entered the
simulator, issues 25 and 26), to write ``tests/data/simulate_ref_bb1b890.json``: for a set of
runs that exercise every branch of :class:`stringstab.traffic.Platoon` (lag and kinematic
models, integer, linearly interpolated and exact fractional delays, trapezoid positions,
heterogeneous lags and gains, speed and acceleration limits, a collision, the CACC, IDM,
time-varying and mixed controllers, batches and ``record=False``) the SHA-256 of every array of
the :class:`~stringstab.traffic.PlatoonResult` (its bytes as little-endian float64 / int64 /
bool), the sum of each array (to see how far a failing run is off), ``params`` and the IDL
metrics as JSON text.  ``tests/traffic/test_simulate_reference.py`` recomputes them with no new option,
with ``reaction_delay=0`` and with the radio at one message per step, no loss and no noise.
Re-running it on a later commit would overwrite the reference with that commit's outputs, so it
refuses to unless ``--force`` is given.

    python analysis/simulate_reference.py            # at bb1b890 only
"""

from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

COMMIT = "bb1b890"
OUT = Path(__file__).resolve().parents[1] / "tests" / "data" / f"simulate_ref_{COMMIT}.json"
#: The result's arrays compared.
ARRAYS = ("t", "position", "speed", "accel", "command", "gains", "collided", "collision_events",
          "first_collision_time", "min_gap", "sum_sq_accel")


def cases() -> dict[str, Callable[..., Any]]:
    """Named runs: each a function ``run(**extra)`` passing ``extra`` on to ``simulate``."""
    from stringstab.traffic import (
        CACCController,
        IDMController,
        Limits,
        LinearController,
        MixedController,
        TimeVaryingLinearController,
        hard_braking,
        simulate,
        sinusoid,
        stop_and_go,
    )

    sin = sinusoid(omega=1.0, amplitude=1.0, speed=20.0, duration=30.0, dt=0.1)
    sin01 = sinusoid(omega=2.0, amplitude=0.5, speed=20.0, duration=8.0, dt=0.01)
    brake = hard_braking(speed=25.0, cruise_before=2.0, cruise_after=5.0, dt=0.1)
    sg = stop_and_go(dt=0.1)
    cert = LinearController(1.2, 0.5, 0.6)
    vanarem = LinearController(0.1, 0.58, 1.0)
    per_pos = LinearController([1.2, 0.9, 1.5], [0.5, 0.6, 0.4], [0.6, 0.3, 0.0])
    K = np.tile(np.array([1.2, 0.5, 0.6]), (300, 1))
    K[150:] = [0.9, 0.7, 0.2]
    tv = TimeVaryingLinearController(K)
    mixed = MixedController([cert, IDMController(), CACCController()], [0, 1, 2])

    def run(leader: Any, ctrl: Any, n: int, **kw: Any) -> Callable[..., Any]:
        return lambda **extra: simulate(leader, ctrl, n, **kw, **extra)

    return {
        "lag": run(sin, cert, 3),
        "lag_dt001": run(sin01, cert, 3),
        "uncertified": run(sin, vanarem, 4),
        "frac_linear": run(sin, cert, 3, delta=0.25),
        "frac_exact": run(sin, cert, 3, delta=0.25, fractional_delay="exact"),
        "frac_exact_het_tau": run(sin, per_pos, 3, delta=0.15, tau=[0.1, 0.3, 0.5],
                                  fractional_delay="exact"),
        "trapezoid": run(sin, cert, 3, position_update="trapezoid"),
        "kinematic": run(sin, cert, 3, model="kinematic"),
        "kinematic_frac_exact": run(sin, cert, 3, model="kinematic", delta=0.25,
                                    fractional_delay="exact"),
        "no_delay": run(sin, cert, 3, delta=0.0),
        "het_tau_gains": run(sin, per_pos, 3, tau=[0.1, 0.3, 0.5]),
        "braking_limits": run(brake, cert, 3, limits=Limits(accel_min=-5.0)),
        "collision": run(brake, LinearController(0.05, 0.05, 0.0), 3,
                         initial_gap=3.0, limits=Limits(accel_min=-3.0)),
        "stop_and_go": run(sg, cert, 3),
        "cacc": run(sin, CACCController(), 3),
        "idm": run(sin, IDMController(), 3),
        "time_varying": run(sin, tv, 2),
        "mixed": run(sin, mixed, 3),
        "batch": run([sin, sinusoid(omega=0.5, amplitude=2.0, speed=15.0, duration=30.0, dt=0.1)],
                     cert, 3),
        "batch_no_record": run([sin, sinusoid(omega=0.5, amplitude=2.0, speed=15.0,
                                              duration=30.0, dt=0.1)], vanarem, 3, record=False),
    }


def fingerprint(res: Any) -> dict[str, Any]:
    """SHA-256 and sum of every array of a run, its params and metrics, as JSON-ready values."""
    from stringstab.traffic.metrics import platoon_metrics

    out: dict[str, Any] = {}
    for name in ARRAYS:
        a = getattr(res, name)
        if a is None:
            out[name] = None
            continue
        arr = np.ascontiguousarray(a)
        dtype = {"f": "<f8", "i": "<i8", "b": "|b1"}[arr.dtype.kind]
        arr = arr.astype(dtype, copy=False)
        out[name] = {"shape": list(arr.shape), "sha256": hashlib.sha256(arr.tobytes()).hexdigest(),
                     "sum": repr(float(np.nansum(arr.astype(np.float64))))}
    out["params"] = json.dumps(res.params, sort_keys=True, default=str)
    out["metrics"] = json.dumps(platoon_metrics(res), sort_keys=True, default=str)
    return out


def record() -> dict[str, Any]:
    """Every case's fingerprint, keyed by name."""
    return {name: fingerprint(fn()) for name, fn in cases().items()}


def main(argv: list[str] | None = None) -> int:
    """Write the reference (refuses to overwrite it without ``--force``).

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (``--force``).

    Returns
    -------
    int
        0 when written, 1 when refused.
    """
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--force", action="store_true", help="overwrite an existing reference")
    args = ap.parse_args(argv)
    if OUT.exists() and not args.force:
        print(f"{OUT} exists; it is the reference of commit {COMMIT}: not overwritten", file=sys.stderr)
        return 1
    head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                          cwd=Path(__file__).resolve().parents[1]).stdout.strip()
    doc = {"commit": head, "numpy": np.__version__, "runs": record()}
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    print(f"wrote {len(doc['runs'])} runs to {OUT} (commit {head})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
