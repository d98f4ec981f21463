#!/usr/bin/python3
"""Plots of the ball-through-torus experiment (thesis 4.4.2): the ball's height and the rim's
largest deformation over time, one panel per torus (columns) and friction (rows), solid lines
under gravity and dashed lines pushed with 2,500. The runs with the rigid rim's "held" assembly
area (the snap jump, Fig. 4.36) are left out. Usage: plot_ball_torus.py RUNS_CSV OUTDIR"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_columns(path):
    cols = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            for key, value in row.items():
                cols.setdefault(key, []).append(float(value))
    return cols


def main(runs_csv, out_dir):
    base = os.path.dirname(runs_csv)
    with open(runs_csv, newline="") as f:
        runs = [r for r in csv.DictReader(f) if r.get("area", "thesis") == "thesis"]
    tori = list(dict.fromkeys(r["torus"] for r in runs))
    frictions = list(dict.fromkeys(r.get("friction", "0") for r in runs))
    diameters = list(dict.fromkeys(r["diameter"] for r in runs))
    colours = dict(zip(diameters, plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    for key, ylabel, name in (("ball_y", "ball centre height", "ball_height.png"),
                              ("mouth_deformation", "largest rim deformation", "rim_deformation.png")):
        fig, axes = plt.subplots(len(frictions), len(tori), figsize=(5 * len(tori), 4.2 * len(frictions)), dpi=100,
                                 sharey=True, squeeze=False)
        for row, friction in zip(axes, frictions):
            for ax, torus in zip(row, tori):
                for r in (r for r in runs if r["torus"] == torus and r.get("friction", "0") == friction):
                    cols = read_columns(os.path.join(base, r["csv"]))
                    if key not in cols:
                        continue
                    ax.plot(cols["time"], cols[key], color=colours[r["diameter"]],
                            linestyle="-" if r["load"] == "gravity" else "--", linewidth=1.2,
                            label=f'{r["diameter"]} {r["load"]}: {r["result"]}')
                ax.set_title(f"{torus} torus, friction {friction}")
                ax.set_xlabel("time (s)")
                ax.grid(True, alpha=0.3)
                if ax.lines:
                    ax.legend(fontsize=6)
                else:
                    ax.text(0.5, 0.5, "rigid: no deformation", transform=ax.transAxes, ha="center")
            row[0].set_ylabel(ylabel)
        fig.tight_layout()
        fig.savefig(os.path.join(out_dir, name))
        plt.close(fig)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
