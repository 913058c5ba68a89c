"""Error messages show plain numbers (errors.show), never NumPy reprs such as np.float64(0.5)."""

import numpy as np
import pytest

from stringstab.errors import StringStabError
from stringstab.params import Params, positive
from stringstab.traffic import Limits, from_speed, simulate, sinusoid
from stringstab.traffic.controllers import LinearController


@pytest.mark.parametrize("call, text", [
    (lambda: Params(tau=np.float64(-0.1)), "got -0.1"),
    (lambda: positive("dt", np.float64(0.0), unit=" s"), "got 0.0"),
    (lambda: sinusoid(omega=np.float64(-1.0)), "got -1.0"),
    (lambda: from_speed(np.array([0.0, 1.0]), np.array([1.0, -2.0])), "got -2.0 at t=1.0"),
    (lambda: from_speed(np.array([1.0, 0.5]), np.array([1.0, 1.0])), "got t[0]=1.0 then t[1]=0.5"),
    (lambda: simulate(sinusoid(omega=1.0, duration=5.0), LinearController(1.2, 0.5, 0.6),
                      np.float64(1.5)), "got 1.5"),
    (lambda: Limits(accel_min=np.float64(1.0)), "got [1.0, 3.0]"),
])
def test_numpy_values_print_plainly(call, text):
    with pytest.raises(StringStabError) as e:
        call()
    msg = str(e.value)
    assert "np." not in msg and "array(" not in msg, msg
    assert text in msg, msg
