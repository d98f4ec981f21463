#!/usr/bin/python3
"""Plots of the restoration experiment: active springs over time, one curve per material,
one figure per threshold (thesis Fig. 4.5 and 4.6). Usage: plot_restoration.py CSV OUTDIR"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(csv_path, out_dir):
    series = defaultdict(lambda: ([], [], []))
    with open(csv_path, newline="") as f:
        for row in csv.DictReader(f):
            t, a, b = series[row["material"]]
            t.append(float(row["time"]))
            a.append(int(row["active_0.01"]))
            b.append(int(row["active_0.1"]))
    for column, threshold in ((1, "0.01"), (2, "0.1")):
        fig, ax = plt.subplots(figsize=(8, 4.5), dpi=100)
        for material, data in series.items():
            ax.plot(data[0], data[column], label=material, linewidth=1.2)
        ax.set_xscale("symlog", linthresh=1.0)
        ax.set_xlabel("time (s)")
        ax.set_ylabel(f"active springs (| |xi-xj| - L | > {threshold})")
        ax.set_title(f"torus1: active springs, threshold {threshold}")
        ax.grid(True, alpha=0.3)
        ax.legend()
        fig.tight_layout()
        fig.savefig(f"{out_dir}/active_springs_{threshold}.png")
        plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
