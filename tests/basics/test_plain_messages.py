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


def test_library_refusals_are_the_toolkits_error():
    """Bad arguments deep in the library are StringStabError (one line at the CLI), not bare errors."""
    import math

    from stringstab.certify.criteria import psi

    tr = from_speed([0, 1], [10.0, 12.0], dt=0.5)
    for bad in (math.nan, math.inf, -1.0):
        with pytest.raises(StringStabError, match="hold needs a finite seconds"):
            tr.hold(bad)
    with pytest.raises(StringStabError, match="source must be 'derived' or 'printed'"):
        psi(1.0, 0.5, 0.2, tau=0.1, delta=0.2, headway=1.1, source="neither")
