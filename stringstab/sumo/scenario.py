"""A straight single-lane road for a leader and N followers, generated with netconvert.

The network is one edge of one lane from x = 0 to the road's length (built by SUMO's
``netconvert`` from a node and an edge file); the routes put the leader ``L`` and the followers
``F1 .. FN`` on it at t = 0 with their initial speeds, each follower's front bumper
``gap_i + length`` behind its predecessor's (SUMO's and the toolkit's positions are both front
bumpers; the gap is bumper to bumper).  Vehicles are inserted without SUMO's insertion checks
(``insertionChecks="none"``) so the gaps are exactly the controller's equilibrium gaps even
at standstill; their vType has ``minGap = 0``, no driver imperfection (``sigma = 0``), speed
factor 1 and bounds wider than the toolkit's limits, which the toolkit applies itself.
"""

from __future__ import annotations

import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from ..errors import StringStabError
from .runtime import binary

__all__ = ["EDGE", "LEADER_ID", "StraightRoad", "follower_ids", "straight_road"]

#: The edge of the straight road.
EDGE = "road"
#: SUMO id of the leader.
LEADER_ID = "L"
#: Margin before the last follower and after the leader's last position, m.
MARGIN = 50.0


def follower_ids(n: int) -> list[str]:
    """SUMO ids of the followers: ``F1`` (behind the leader) .. ``FN``.

    Parameters
    ----------
    n : int
        Number of followers.

    Returns
    -------
    list of str
        The ids, front to back.

    Examples
    --------
    >>> follower_ids(3)
    ['F1', 'F2', 'F3']
    """
    return [f"F{i}" for i in range(1, n + 1)]


@dataclass(frozen=True)
class StraightRoad:
    """A generated scenario: its files and where the leader starts.

    Attributes
    ----------
    net, routes : Path
        The network and route files.
    leader_start : float
        The leader's initial position along the lane (SUMO's lane position), m.
    road_length : float
        Length of the lane, m.
    """

    net: Path
    routes: Path
    leader_start: float
    road_length: float

    def sumo_args(self) -> list[str]:
        """The SUMO options that load this scenario."""
        return ["-n", str(self.net), "-r", str(self.routes)]


def straight_road(directory: str | Path, *, distance: float, gaps: npt.ArrayLike,
                  speeds: npt.ArrayLike, leader_speed: float, length: float,
                  vtype: str | None = None, type_id: str = "platoon") -> StraightRoad:
    """Write a straight one-lane road with a leader and its followers into ``directory``.

    Parameters
    ----------
    directory : path
        An existing (temporary) folder.
    distance : float
        How far the leader will drive, m (the road is made long enough).
    gaps, speeds : array (N,)
        Initial bumper-to-bumper gaps (m) and speeds (m/s) of the followers.
    leader_speed : float
        The leader's initial speed, m/s.
    length : float
        Vehicle length, m.
    vtype, type_id : str, optional
        The XML of another vType for every vehicle (e.g. SUMO's CACC) and its id; default a
        Krauss vType driven through speed commands (the module docstring).

    Returns
    -------
    StraightRoad

    Raises
    ------
    StringStabError
        If netconvert fails or the inputs are not finite.
    """
    d = Path(directory)
    g = np.asarray(gaps, dtype=np.float64).ravel()
    v = np.asarray(speeds, dtype=np.float64).ravel()
    if not (np.isfinite(g).all() and np.isfinite(v).all() and np.isfinite(distance)):
        raise StringStabError("the initial gaps, speeds and the leader's distance must be finite")
    platoon = float(np.sum(g + length))
    start = MARGIN + platoon + length
    road = start + max(float(distance), 0.0) + 2 * MARGIN
    (d / "road.nod.xml").write_text(
        '<nodes>\n  <node id="a" x="0" y="0"/>\n'
        f'  <node id="b" x="{road!r}" y="0"/>\n</nodes>\n', encoding="utf-8")
    (d / "road.edg.xml").write_text(
        f'<edges>\n  <edge id="{EDGE}" from="a" to="b" numLanes="1" speed="60"/>\n</edges>\n',
        encoding="utf-8")
    net = d / "road.net.xml"
    proc = subprocess.run(
        [binary("netconvert"), "-n", str(d / "road.nod.xml"), "-e", str(d / "road.edg.xml"),
         "-o", str(net), "--no-warnings", "true", "--no-turnarounds", "true"],
        stdin=subprocess.DEVNULL, capture_output=True, text=True, check=False)
    if proc.returncode != 0 or not net.is_file():
        msg = " ".join((proc.stderr or proc.stdout).split())[:300]
        raise StringStabError(f"netconvert could not build the straight road: {msg}")
    x = start - np.cumsum(g + length)
    if vtype is None:
        vtype = (f'<vType id="{type_id}" length="{length!r}" minGap="0" accel="10" decel="10" '
                 'emergencyDecel="20" sigma="0" maxSpeed="60" speedFactor="1" speedDev="0" '
                 'carFollowModel="Krauss" tau="1"/>')
    lines = [
        "<routes>",
        f"  {vtype}",
        f'  <route id="r" edges="{EDGE}"/>',
        f'  <vehicle id="{LEADER_ID}" type="{type_id}" route="r" depart="0" departLane="0" '
        f'departPos="{start!r}" departSpeed="{float(leader_speed)!r}" insertionChecks="none"/>',
    ]
    for vid, xi, vi in zip(follower_ids(g.size), x, v):
        lines.append(
            f'  <vehicle id="{vid}" type="{type_id}" route="r" depart="0" departLane="0" '
            f'departPos="{float(xi)!r}" departSpeed="{float(vi)!r}" insertionChecks="none"/>')
    lines.append("</routes>")
    routes = d / "platoon.rou.xml"
    routes.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return StraightRoad(net, routes, start, road)
