"""The toolkit simulator's trapezoidal position option (SUMO's ballistic update); no SUMO needed."""

from __future__ import annotations

import numpy as np
import pytest

from stringstab.errors import StringStabError
from stringstab.traffic import LinearController, Platoon, leader_by_name, simulate, sinusoid


def test_trapezoid_positions_speeds_and_accels():
    lead = sinusoid(omega=1.0, duration=30.0)
    c = LinearController(1.2, 0.5, 0.6)
    ex = simulate(lead, c, 4)
    tr = simulate(lead, c, 4, position_update="trapezoid")
    assert tr.params["position_update"] == "trapezoid" and "position_update" not in ex.params
    # positions obey the trapezoid rule on the recorded speeds, to round-off
    x, v = tr.position[1:], tr.speed[1:]
    step = x[:, 1:] - x[:, :-1] - 0.5 * tr.dt * (v[:, 1:] + v[:, :-1])
    assert np.abs(step).max() < 1e-9
    # the exact integral does not (the option changes something)
    xe, ve = ex.position[1:], ex.speed[1:]
    assert np.abs(xe[:, 1:] - xe[:, :-1] - 0.5 * ex.dt * (ve[:, 1:] + ve[:, :-1])).max() > 1e-7


def test_trapezoid_step_differs_from_exact_by_the_closed_form():
    # one step from a = 0 with command u: exact x = v dt + u dt^2/2 + (0 - u) tau (dt - tau(1 - e)),
    # trapezoid x = dt (v + v_next)/2; their difference is abar tau ((dt - tau(1-e)) - (1-e) dt / 2)
    dt, tau, u, v0 = 0.1, 0.1, 1.5, 10.0
    out = {}
    for mode in ("exact", "trapezoid"):
        p = Platoon(1, 1, dt=dt, tau=tau, delta=0.0, position_update=mode)
        p.reset([0.0], [v0], [0.0], gap=20.0, speed=v0)
        x0 = float(p.position[0, 1])
        p.observe([0.0], [v0], [0.0])
        p.advance(np.array([[u]]))
        out[mode] = (float(p.position[0, 1]) - x0, float(p.speed[0, 1]), float(p.accel[0, 1]))
    e = np.exp(-dt / tau)
    abar = -u
    want = abar * tau * ((dt - tau * (1 - e)) - (1 - e) * dt / 2)
    assert out["exact"][1:] == out["trapezoid"][1:]
    assert out["exact"][0] - out["trapezoid"][0] == pytest.approx(want, rel=1e-9, abs=1e-15)


def test_trapezoid_is_not_the_default_and_bad_values_are_refused():
    lead = leader_by_name("udds", dt=0.1, duration=30.0)
    c = LinearController(1.2, 0.5, 0.6)
    a = simulate(lead, c, 2)
    b = simulate(lead, c, 2, position_update="exact")
    assert np.array_equal(a.position, b.position)
    with pytest.raises(StringStabError, match="position_update must be 'exact' or 'trapezoid'"):
        simulate(lead, c, 2, position_update="euler")  # type: ignore[arg-type]
