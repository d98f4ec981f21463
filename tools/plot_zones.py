#!/usr/bin/python3
"""Plots of the zones experiment (thesis Fig. 4.17-4.18, 6.1-6.4): per model, steps/s and
speed-up over full MSD against the depth level, one curve per zone count.
Usage: plot_zones.py CSV OUTDIR"""
import csv
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(csv_path, out_dir):
    curves = defaultdict(lambda: defaultdict(list))  # model -> zones -> [(level, sps, speedup)]
    full = {}
    with open(csv_path, newline="") as f:
        for row in csv.DictReader(f):
            model, zones = row["model"], int(row["zones"])
            if zones == 0:
                full[model] = float(row["steps_per_second"])
                continue
            if zones < 0:  # one zone covering every mass
                continue
            curves[model][zones].append((int(row["level"]), float(row["steps_per_second"]), float(row["speedup"])))
    for model, by_zones in curves.items():
        for column, name, label in ((1, "steps", "steps/s"), (2, "speedup", "speed-up over full MSD")):
            fig, ax = plt.subplots(figsize=(8, 4.5), dpi=100)
            for zones, points in sorted(by_zones.items()):
                points.sort()
                ax.plot([p[0] for p in points], [p[column] for p in points], marker="o", markersize=3,
                        label=f"{zones} zone{'s' if zones > 1 else ''}")
            reference = full[model] if column == 1 else 1.0
            ax.axhline(reference, color="black", linestyle="--", linewidth=1, label="full MSD")
            ax.set_yscale("log")
            ax.set_xlabel("depth level")
            ax.set_ylabel(label)
            ax.set_title(f"{model}: rigid-deformable {label}")
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8, ncol=2)
            fig.tight_layout()
            fig.savefig(f"{out_dir}/{name}_{model}.png")
            plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
