"""Thesis Table 4.5 as a sweep on a Dask cluster, and its plot.

    PYTHONPATH=build/release/python /usr/bin/python3 examples/python/table_4_5_sweep.py [--workers N] [--scheduler ADDRESS]

Runs examples/sweeps/table_4_5.toml (5 balls x 3 rims x 2 frictions, pushed through the container
mouth) on a local cluster of N worker processes, or on the Dask scheduler at ADDRESS, into
out/table_4_5/; prints the outcome of each run (assembled, passed, stopped) as the thesis's table
and plots each rim's largest deformation and outcome per ball (out/table_4_5/table_4_5.png).
A second call runs nothing: every run is done (delete out/table_4_5 to run again).
"""

import argparse
import pathlib
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import flexfit  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def outcome(row):
    if row["assembly_events"] > 0:
        return "assembled"
    return "passed" if row["ball_y"] + 0.5 * float(row["diameter"]) < 0 else "stopped"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--scheduler", default=None, help="a Dask scheduler's address (default: a local cluster)")
    parser.add_argument("--out", default=str(ROOT / "out" / "table_4_5"))
    args = parser.parse_args()

    start = time.perf_counter()
    table = flexfit.sweep(ROOT / "examples" / "sweeps" / "table_4_5.toml", args.out, scheduler=args.scheduler, workers=args.workers)
    seconds = time.perf_counter() - start
    print(f"{len(table)} runs ({len(table.attrs['ran'])} run now) in {seconds:.1f} s on "
          f"{args.scheduler or f'{args.workers} local worker(s)'}; table {args.out}/results.csv")

    table["outcome"] = table.apply(outcome, axis=1)
    print(table.pivot_table(index="diameter", columns=["rim", "friction"], values="outcome", aggfunc="first").to_string())

    figure, axes = plt.subplots(1, 2, figsize=(11, 4))
    markers = {"assembled": "o", "passed": "s", "stopped": "x"}
    for (rim, friction), group in table.groupby(["rim", "friction"]):
        label = f"{rim}, friction {friction}"
        axes[0].plot(group["diameter"], group["max_deformation"], marker="o", label=label)
        for _, row in group.iterrows():
            axes[1].scatter(row["diameter"], f"{rim} / {friction}", marker=markers[row["outcome"]], color="k")
    axes[0].set_xlabel("ball diameter")
    axes[0].set_ylabel("largest rim deformation")
    axes[0].legend(fontsize=7)
    axes[1].set_xlabel("ball diameter")
    axes[1].set_title("o assembled   s passed   x stopped")
    figure.suptitle("Thesis Table 4.5: balls pushed through the container mouth")
    figure.tight_layout()
    path = pathlib.Path(args.out) / "table_4_5.png"
    figure.savefig(path, dpi=100)
    print(f"plot {path}")


if __name__ == "__main__":
    main()
