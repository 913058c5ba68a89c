"""Regenerate the figures of docs/regions.md into docs/figures/.

All maps use δ = 0.2 s and T* = 1.1 s (IDL paper Table 2) unless a figure
varies them, gains in [-2, 2]:

* ``regions_classes_tau.png``: exact class maps over (k_x, k_v) at k_a = 0.5,
  τ ∈ {0.1, 0.2, 0.5} s;
* ``regions_sup_gain_tau.png``: sup|Γ(jω)| on the same slices;
* ``regions_boundaries_tau.png``: the certified boundaries of those slices on one axes;
* ``regions_types.png``: the Taylor (derived Ψ) types at τ = 0.1 s;
* ``regions_compare_printed.png``: exact vs taylor vs printed over (k_v, k_a) at
  k_x = 0.9, τ = 0.1 s, with the triple K = (0.9, −0.5, 1.1) of docs/certify.md marked;
* ``regions_compare_tau.png``: exact vs printed on that slice for the three τ;
* ``regions_classes_delta.png`` and ``regions_compare_delta.png``: exact class maps,
  and exact vs taylor, over (k_v, k_a) at k_x = 0.9 for δ ∈ {0, 0.2, 0.4} s, τ = 0.1 s;
* ``regions_slices.png`` and ``regions_3d.png``: the exact 101³ volume at τ = 0.1 s;
* ``regions_overlay.png``: the bundled gain time series over the exact map at k_a = 0.3;
* ``regions_compare_sampled.png``: the sampled-data certificate vs the continuous one over
  (k_x, k_v) at k_a = 0.5, τ = 0.1 s, for Δt = 0.05, 0.1, 0.2 s: the band of gains certified
  in continuous time but not when sampled (docs/sampled.md).

Prints the share of certified points per map and the disagreement counts (the
numbers quoted in docs/regions.md).  Only calls the library.  Usage::

    python analysis/region_figures.py [--out docs/figures] [--n 401] [--n3 101] [--only sampled]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np

from stringstab import plots
from stringstab.io import GainTable, read_gains
from stringstab.regions import region_map

TAUS = (0.1, 0.2, 0.5)
PERIODS = (0.05, 0.1, 0.2)
GROUPS = ("tau", "printed", "delta", "3d", "overlay", "sampled")
DELTAS = (0.0, 0.2, 0.4)
DELTA, HEADWAY = 0.2, 1.1
ROLLOUT = Path(__file__).resolve().parents[1] / "stringstab" / "data" / "examples" / "gain_rollout.csv"


def save(fig, out: Path, name: str, dpi: int) -> None:
    path = out / name
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    print(f"  wrote {path} ({path.stat().st_size / 1024:.0f} KB)")


def compare_row(maps, methods, symbol: str, key: str, title: str, path: Path, dpi: int) -> None:
    """One comparison panel per map, side by side."""
    fig, axes = plt.subplots(1, len(maps), figsize=(5.0 * len(maps), 5.9), layout="constrained",
                             sharey=True)
    for m, a in zip(maps, axes):
        plots.plot_comparison(m, methods, ax=a, title=False)
        a.set_title(f"{symbol} = {m.params.as_dict()[key]:g} s", fontsize="medium")
    fig.suptitle(title, fontsize="medium")
    save(fig, path.parent, path.name, dpi)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=str(Path(__file__).resolve().parents[1] / "docs" / "figures"))
    ap.add_argument("--n", type=int, default=401, help="grid points per axis of the 2-D slices")
    ap.add_argument("--n3", type=int, default=101, help="grid points per axis of the 3-D volume")
    ap.add_argument("--dpi", type=int, default=110)
    ap.add_argument("--only", default=",".join(GROUPS),
                    help=f"figure groups to draw among {', '.join(GROUPS)} (default: all)")
    args = ap.parse_args()
    only = set(args.only.split(","))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    g = np.linspace(-2.0, 2.0, args.n)
    if "sampled" in only:
        sampled_figure(g, out, args.dpi)
    if "tau" in only:
        tau_figures(g, out, args.dpi)
    if "printed" in only:
        printed_figures(g, out, args.dpi)
    if "delta" in only:
        delta_figures(g, out, args.dpi)
    if "3d" in only:
        volume_figures(args.n3, out, args.dpi)
    if "overlay" in only:
        overlay_figure(out, args.dpi)


def sampled_figure(g, out: Path, dpi: int) -> None:
    print("sampled vs continuous: slices over (k_x, k_v) at k_a = 0.5, tau = 0.1")
    maps = [region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=0.1, delta=DELTA, headway=HEADWAY,
                       sample_time=H, methods=("exact", "continuous")) for H in PERIODS]
    fig, axes = plt.subplots(1, len(maps), figsize=(5.6 * len(maps), 7.0), layout="constrained",
                             sharey=True)
    for m, a in zip(maps, axes):
        counts = plots.plot_comparison(m, ax=a, title=False)["counts"]
        lost, kept = counts["sampled ✗ · continuous ✓"], counts["both say string stable"]
        a.set_title(f"Δt = {m.sample_time:g} s: {lost:,} of {lost + kept:,} lost", fontsize="medium")
        print(f"  dt = {m.sample_time:g}: " + m.report().splitlines()[-1])
    fig.suptitle(f"sampled (zero-order hold) vs continuous certificate; k_a = 0.5, τ = 0.1 s, "
                 f"δ = {DELTA:g} s, T* = {HEADWAY:g} s", fontsize="medium")
    save(fig, out, "regions_compare_sampled.png", dpi)


def tau_figures(g, out: Path, dpi: int) -> None:
    print("slices over (k_x, k_v) at k_a = 0.5 for several tau")
    by_tau = [region_map({"k_x": g, "k_v": g}, {"k_a": 0.5}, tau=t, delta=DELTA, headway=HEADWAY)
              for t in TAUS]
    for m in by_tau:
        print(f"  tau = {m.params.tau:g}: " + m.report().splitlines()[1].strip())
    save(plots.plot_facets(by_tau, "exact")["fig"], out, "regions_classes_tau.png", dpi)
    save(plots.plot_facets(by_tau, kind="sup_gain")["fig"], out, "regions_sup_gain_tau.png", dpi)
    save(plots.plot_boundaries(by_tau)["ax"].figure, out, "regions_boundaries_tau.png", dpi)
    save(plots.plot_class_map(by_tau[0], "taylor")["ax"].figure, out, "regions_types.png", dpi)


def printed_figures(g, out: Path, dpi: int) -> None:
    print("printed vs exact: slices over (k_v, k_a) at k_x = 0.9")
    cmp_maps = [region_map({"k_v": g, "k_a": g}, {"k_x": 0.9}, tau=t, delta=DELTA, headway=HEADWAY)
                for t in TAUS]
    for m in cmp_maps:
        print(f"  tau = {m.params.tau:g}: {m.disagreements()}; "
              f"certified {m.stable('exact').mean():.4f}, printed stable {m.stable('printed').mean():.4f}")
    ax = plots.plot_comparison(cmp_maps[0])["ax"]
    paper = GainTable.from_triples([(0.9, -0.5, 1.1)], source="docs/certify.md")
    drawn = plots.plot_trajectory(cmp_maps[0], paper, verdicts=plots.trajectory_verdicts(cmp_maps[0], paper),
                                  ax=ax, label="K of docs/certify.md")
    ax.annotate("K = (0.9, −0.5, 1.1)", (-0.5, 1.1), xytext=(-1.9, 1.55), fontsize="small",
                arrowprops=dict(arrowstyle="->", lw=0.8))
    print(f"  K = (0.9, -0.5, 1.1): exact {drawn['verdicts'][0]}")
    save(ax.figure, out, "regions_compare_printed.png", dpi)
    compare_row(cmp_maps, ["exact", "printed"], "τ", "tau",
                f"exact vs printed Proposition 1; k_x = 0.9, δ = {DELTA:g} s, T* = {HEADWAY:g} s",
                out / "regions_compare_tau.png", dpi)


def delta_figures(g, out: Path, dpi: int) -> None:
    print("several delta at tau = 0.1: slices over (k_v, k_a) at k_x = 0.9")
    by_delta = [region_map({"k_v": g, "k_a": g}, {"k_x": 0.9}, tau=0.1, delta=d, headway=HEADWAY,
                           methods=("exact", "taylor")) for d in DELTAS]
    for m in by_delta:
        print(f"  delta = {m.params.delta:g}: certified {m.stable('exact').mean():.4f}, "
              f"taylor stable {m.stable('taylor').mean():.4f}, {m.disagreements()}")
    save(plots.plot_facets(by_delta, "exact")["fig"], out, "regions_classes_delta.png", dpi)
    compare_row(by_delta, ["exact", "taylor"], "δ", "delta",
                f"exact vs Taylor Proposition 1 (derived Ψ); k_x = 0.9, τ = 0.1 s, T* = {HEADWAY:g} s",
                out / "regions_compare_delta.png", dpi)


def volume_figures(n3: int, out: Path, dpi: int) -> None:
    print(f"3-D: exact {n3}^3 volume at tau = 0.1")
    g3 = np.linspace(-2.0, 2.0, n3)
    vol = region_map({"k_x": g3, "k_v": g3, "k_a": g3}, tau=0.1, delta=DELTA, headway=HEADWAY)
    print("  " + "\n  ".join(vol.report().splitlines()))
    save(plots.plot_slices(vol, "exact", n=9)["fig"], out, "regions_slices.png", dpi)
    drawn3 = plots.plot_region_3d(vol, "exact")
    print(f"  columns whose certified k_a set is not one interval: {drawn3['n_gapped']}")
    save(drawn3["ax"].figure, out, "regions_3d.png", dpi)


def overlay_figure(out: Path, dpi: int) -> None:
    print("gain trajectory over the exact map at k_a = 0.3")
    ov = region_map({"k_x": np.linspace(0.0, 1.5, 301), "k_v": np.linspace(-1.0, 1.0, 301)}, {"k_a": 0.3},
                    tau=0.1, delta=DELTA, headway=HEADWAY, methods=("exact",))
    ax = plots.plot_class_map(ov, "exact")["ax"]
    rollout = read_gains(ROLLOUT)
    drawn = plots.plot_trajectory(ov, rollout, verdicts=plots.trajectory_verdicts(ov, rollout), ax=ax)
    print(f"  verdicts of the {len(drawn['verdicts'])} rows: "
          + ", ".join(f"{v} {drawn['verdicts'].count(v)}" for v in sorted(set(drawn["verdicts"]))))
    save(ax.figure, out, "regions_overlay.png", dpi)


if __name__ == "__main__":
    main()
