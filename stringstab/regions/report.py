"""The text report of a region map: a few lines for people (``stringstab region`` prints it)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol

import numpy as np

__all__ = ["ReportedMap", "percent", "render_report"]


class ReportedMap(Protocol):
    """What the report reads from a map: :class:`~stringstab.regions.result.RegionMap` has it.

    Written as a protocol so that this module sits below ``result.py`` (``RegionMap.report``
    calls :func:`render_report`) and imports nothing from it.
    """

    @property
    def axes(self) -> Mapping[str, Any]:
        """The grid's axes: gain name (``"k_x"``, ``"k_v"``, ``"k_a"``) to its coordinates."""
        ...

    @property
    def methods(self) -> tuple[str, ...]:
        """The methods evaluated (``"exact"``, ``"continuous"``, ``"taylor"``, ``"printed"``)."""
        ...

    @property
    def shape(self) -> tuple[int, ...]:
        """The grid shape."""
        ...

    @property
    def size(self) -> int:
        """Number of grid points."""
        ...

    def title(self) -> str:
        """A one-line description: the fixed gain, the parameters (or the box), the sample time.

        Returns
        -------
        str
            The description.
        """
        ...

    def class_shares(self) -> dict[str, dict[str, float]]:
        """Share of grid points in each class of each method's class map.

        Returns
        -------
        dict of str to dict of str to float
            Method -> class label -> share in [0, 1].
        """
        ...

    def verdict_shares(self) -> dict[str, dict[str, float]]:
        """Share of grid points of each verdict of each method.

        Returns
        -------
        dict of str to dict of str to float
            Method -> verdict label -> share in [0, 1].
        """
        ...

    def disagreements(self) -> dict[str, int]:
        """Number of points where methods disagree on string stability.

        Returns
        -------
        dict of str to int
            ``"a vs b"`` per pair of methods, ``"any"`` and ``"inconclusive"`` (as
            :meth:`stringstab.regions.RegionMap.disagreements`).
        """
        ...

    @property
    def message_period(self) -> float | None:
        """The V2V message period (s) of a multi-rate map, else None (issue 26)."""
        ...

    def stable(self, method: str) -> np.ndarray:
        """Where ``method`` says string stable.

        Parameters
        ----------
        method : str
            One of :attr:`methods`.

        Returns
        -------
        bool ndarray, shape :attr:`shape`
            True where the method's verdict is string stable.
        """
        ...


def percent(x: float) -> str:
    """A share as a percentage with one decimal (``<0.1 %`` for a tiny non-zero share).

    Parameters
    ----------
    x : float
        A share in [0, 1].

    Returns
    -------
    str
        For instance ``"20.0 %"``; ``"<0.1 %"`` for 0 < x < 0.001.
    """
    return "<0.1 %" if 0 < x < 1e-3 else f"{100 * x:.1f} %"


def render_report(rmap: ReportedMap) -> str:
    """The grid, the class shares per method and the disagreements, one line each.

    Parameters
    ----------
    rmap : RegionMap
        The map to describe (anything with the attributes of :class:`ReportedMap`).

    Returns
    -------
    str
        The report, lines joined by newlines (no final newline): the grid and τ, δ, T*; the
        class shares of each method (Taylor types I-IV of IDL §3.3, exact verdicts); the
        points where methods disagree; for a sampled map, the points certified in one of
        continuous and sampled time only.

    Examples
    --------
    >>> import numpy as np
    >>> from stringstab.regions import region_map
    >>> m = region_map({"k_x": np.linspace(-1, 1, 5), "k_v": np.linspace(-1, 1, 5)},
    ...                {"k_a": 0.5}, tau=0.1, delta=0.2, headway=1.1, methods="taylor")
    >>> print(render_report(m))
    5 x 5 = 25 points: k_x in [-1, 1], k_v in [-1, 1]; k_a = 0.5; τ = 0.1 s, δ = 0.2 s, T* = 1.1 s
    taylor: not internally stable 72.0 %, type III 8.0 %, type IV 0.0 %, type I 20.0 %, type II 0.0 % (stable 20.0 %)
    """
    axes = ", ".join(f"{n} in [{a[0]:g}, {a[-1]:g}]" for n, a in rmap.axes.items())
    lines = [f"{' x '.join(str(s) for s in rmap.shape)} = {rmap.size:,} points: {axes}; {rmap.title()}"]
    width = max(len(m) for m in rmap.methods)
    vs = rmap.verdict_shares()
    for m, shares in rmap.class_shares().items():
        text = ", ".join(f"{k} {percent(v)}" for k, v in shares.items())
        if m in ("taylor", "printed"):
            text += f" (stable {percent(vs[m]['stable'])})"
        lines.append(f"{m + ':':<{width + 1}} {text}")
    if len(rmap.methods) > 1:
        d = rmap.disagreements()
        pairs = ", ".join(f"{k} {v:,}" for k, v in d.items() if " vs " in k)
        lines.append(f"disagreements: {pairs}; any {d['any']:,} of {rmap.size:,} points"
                     + (f"; exact inconclusive at {d['inconclusive']:,}" if "exact" in rmap.methods else ""))
    if "continuous" in rmap.methods:
        band = int((rmap.stable("continuous") & ~rmap.stable("exact")).sum())
        back = int((rmap.stable("exact") & ~rmap.stable("continuous")).sum())
        how = ("when sampled" if rmap.message_period is None  # a multi-rate map (issue 26)
               else f"with messages every {rmap.message_period:g} s")
        lines.append(f"certified in continuous time but not {how}: {band:,} points "
                     f"({percent(band / rmap.size)}); certified {how} but not in "
                     f"continuous time: {back:,}")
    return "\n".join(lines)
