"""A training point whose worker is SIGKILLed mid-training resumes from its checkpoint, bit for bit.

Runs one tiny IDL training point (3 000 steps, a checkpoint every 500) on a local cluster of one
worker, SIGKILLs that worker as soon as the first checkpoint exists, lets the scheduler retry the
task on the restarted worker (which resumes the run folder's checkpoint), then trains the same
point uninterrupted in this process and prints both results.  Asserts nothing; about a minute.

    python analysis/sweep_kill_train.py
"""

from __future__ import annotations

import glob
import json
import os
import signal
import tempfile
import threading
import time

from stringstab.sweep import dask_client, parse_spec, run_point, run_sweep

SPEC = """
[sweep]
name = "kill-train"
kind = "train"
seeds = [0]
[base]
algo = "idl"
total_steps = 3000
checkpoint_every = 500
num_envs = 4
stop_episodes = 0
"""


def main() -> None:
    spec = parse_spec(SPEC)
    with tempfile.TemporaryDirectory() as out, tempfile.TemporaryDirectory() as fresh:
        info: dict[str, object] = {}
        with dask_client(workers=1) as client:
            pid = next(iter(client.run(os.getpid).values()))

            def killer() -> None:
                while True:
                    ck = glob.glob(f"{out}/points/*/run/checkpoint/ckpt-*")
                    if ck:
                        info["checkpoints when killed"] = sorted(os.path.basename(x) for x in ck)
                        os.kill(pid, signal.SIGKILL)
                        return
                    time.sleep(0.05)

            t = threading.Thread(target=killer)
            t.start()
            run_sweep(spec, out, client=client, progress=False, log=print)
            t.join()
        rec = json.loads(open(glob.glob(f"{out}/points/*.json")[0]).read())
        m = rec["metrics"]
        print(f"worker pid {pid} SIGKILLed with {info['checkpoints when killed']}; the point was "
              f"finished by pid {rec['pid']}: {rec['status']}, resumed {m['resumed']}, "
              f"steps {m['steps']}, TIT {m['TIT']!r}, M_CI {m['M_CI']!r}")
        again = run_point(spec.points[0].as_dict(), fresh)["metrics"]
        print(f"uninterrupted, in this process: steps {again['steps']}, TIT {again['TIT']!r}, "
              f"M_CI {again['M_CI']!r}; identical: "
              f"{(again['TIT'], again['M_CI']) == (m['TIT'], m['M_CI'])}")


if __name__ == "__main__":
    main()
