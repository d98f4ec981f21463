#!/usr/bin/python3
"""Plot of the contact experiment (thesis Fig. 4.31): contacts, moving masses, computed and
active springs over time. Usage: plot_contact.py CSV OUTDIR"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main(csv_path, out_dir):
    cols = {}
    with open(csv_path, newline="") as f:
        for row in csv.DictReader(f):
            for key, value in row.items():
                cols.setdefault(key, []).append(float(value))
    t = cols["time"]
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), dpi=100, sharex=True)
    for key, label in (("moving_masses", "moving masses"), ("computed_springs", "computed springs"),
                       ("active_springs", "active springs (> 0.01)"), ("contacts", "contacts")):
        top.plot(t, cols[key], label=label, linewidth=1.2)
    top.set_ylabel("count")
    top.legend(fontsize=8)
    top.grid(True, alpha=0.3)
    top.set_title("rigid torus pressed into a rigid-deformable torus, then withdrawn")
    bottom.plot(t, cols["max_displacement"], label="largest displacement of a blue mass", linewidth=1.2)
    bottom.plot(t, cols["max_penetration"], label="deepest blue mass inside the yellow torus", linewidth=1.2)
    bottom.plot(t, [x - 25.5 for x in cols["rigid_x"]], label="yellow torus x - 25.5", linewidth=1.0, linestyle="--")
    bottom.set_xlabel("time (s)")
    bottom.set_ylabel("length")
    bottom.legend(fontsize=8)
    bottom.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(f"{out_dir}/contact.png")
    plt.close(fig)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
