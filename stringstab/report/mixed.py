"""The report of ``stringstab platoon simulate``: the string, its verdicts, the CAV, the replays.

Built from the objects the command already has (the recorded string's certificate, the design
and its certificate, the data's own amplification, the replays) with :class:`~stringstab.report.Report`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from .render import Report

__all__ = ["platoon_report"]


def _g(x: Any, digits: int = 4) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a" if x is None else str(x)
    return f"{x:.{digits}g}"


def platoon_report(rec: Any, recorded: Any, design: Any, replay: Any, files: Sequence[str], *,
                   empirical: Any = None, probe: Any = None, command: str,
                   started: float | None = None) -> Report:
    """The report of ``stringstab platoon simulate``.

    Parameters
    ----------
    rec : RecordedString
        The recorded string.
    recorded : StringCertificate
        Its head-to-tail certificate.
    design : Design
        The CAV design (:func:`stringstab.mixed.design.design_cavs`).
    replay : Replay
        The replays (:func:`stringstab.mixed.replay.replay`).
    files : sequence of str
        The figures written (names relative to the output folder) with their captions, as
        ``"name|caption"`` or plain names.
    empirical : StringEmpirical, optional
        The data's own head-to-tail amplification.
    probe : Probe, optional
        The strings driven by a sinusoid at the recorded string's peak frequency.
    command : str
        The command line.
    started : float, optional
        ``time.perf_counter()`` at the start of the command.

    Returns
    -------
    Report
    """
    pos = ",".join(str(p) for p in design.positions)
    rep = Report(
        "A recorded string, head to tail, and the CAV that stops the wave", command=command,
        params={"identify.json": rec.source, "log": rec.log, "leader": rec.leader,
                "recorded positions": f"{rec.positions[0]}..{rec.positions[-1]}",
                "CAV position(s)": pos, "simulator": replay.simulator,
                "seconds replayed": round(replay.seconds, 1)},
        intro="The followers identified from a log, in their recorded order, are certified head "
              "to tail: internally stable and sup_ω ∏|Γ_i(jω)| ≤ 1 with the exact delays, by a "
              "sound branch and bound on the product. A CAV put in place of the follower(s) at "
              "the given position(s) gets the gains of the largest attenuation margin, and the "
              "same certificate judges the result. The recorded leader is then replayed through "
              "both strings.", started=started)
    sec = rep.section("Verdicts")
    sec.verdict("the recorded string is certified head to tail", recorded.certified,
                f"{recorded.verdict}; sup ∏|Γ_i| = {_g(recorded.sup_gain)} at "
                f"ω = {_g(recorded.peak_omega)} rad/s; {recorded.reason}")
    sec.verdict(f"with the CAV at {pos} the string is certified head to tail", design.certified,
                design.note)
    if empirical is not None:
        e = empirical.as_dict()
        sec.text(f"The data's own amplification from the first car to the last: max |Ĝ| = "
                 f"{_g(e['gain'])} ± {_g(e['gain_error'], 2)} at ω = {_g(e['omega'], 3)} rad/s "
                 f"(the data: amplifies = {e['amplifies']}); peak-to-peak speed ratio "
                 f"{_g(e['peak_to_peak'], 3)}, acceleration-energy ratio {_g(e['energy'], 3)} "
                 f"(0 < ω ≤ 1 rad/s), over {e['seconds']:.0f} s.")
    rows = []
    for row_r, row_d in zip(recorded.vehicle_rows(), design.certificate.vehicle_rows()):
        rows.append({"pos": row_r["position"], "recorded": row_r["name"],
                     "sup|Γ| recorded": row_r["sup_gain"], "verdict recorded": row_r["verdict"],
                     "with CAV": row_d["name"], "sup|Γ| with CAV": row_d["sup_gain"],
                     "verdict with CAV": row_d["verdict"]})
    rep.section("Vehicles").table(
        rows, caption="Each vehicle's own certificate, in the recorded string and with the CAV(s).")
    runs = [{"string": r.label, "energy ratio (0 < ω ≤ 1)": r.band_ratio,
             "energy ratio (all ω)": r.energy_ratio, "peak-to-peak": r.peak_to_peak,
             "min gap [m]": r.min_gap, "collisions": r.collisions} for r in replay.runs]
    s2 = rep.section("Replays of the recorded leader")
    s2.table(runs, caption="The last follower against the recorded leader in each replay: "
             "acceleration-energy ratios (the band 0 < ω ≤ 1 rad/s excludes the GPS noise of the "
             "leader's acceleration), peak-to-peak speed ratio, smallest gap, collisions.")
    for n in replay.notes:
        s2.text(f"Note: {n}")
    if probe is not None:
        s3 = rep.section(f"A sinusoid at the peak frequency ω = {probe.omega:.3g} rad/s")
        s3.table([{"string": lab, "simulated": m, "∏|Γ_i(jω)|": p}
                  for lab, m, p in zip(probe.labels, probe.measured, probe.predicted)],
                 caption="The last car's steady acceleration amplitude over the leader's when "
                 "the leader's speed oscillates at the recorded string's peak frequency: "
                 "simulated, and from the transfer functions.")
    figs = rep.section("Figures")
    for f in files:
        name, _, caption = str(f).partition("|")
        figs.figure(name, caption or None)
    return rep
