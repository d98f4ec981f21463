#!/usr/bin/python3
"""Two or more flexfit binaries on the same scenes, side by side: in-contact step and stages.

For each scene and round, runs `flexfit run SCENE` with every binary, rotating their order
from round to round so the VM's drift falls on each alike. From each run's metrics.csv, over
the steps with contacts: the world step's p50 / p99 / max (nearest rank) and each stage's mean.
Older binaries have no us_world_step column: their step is then the sum of the stage columns
(column `step_source` says which), a little less than the whole step's own timer. Prints the medians over the
rounds and each binary's ratio to the first (first / this: above 1 means this one is faster),
and the state hash each printed: a different hash means the binaries did not simulate the same
thing, and their times are not a like-for-like comparison.

  tools/ab_stages.py --flexfit base=/tmp/base/flexfit --flexfit new=build/release/apps/flexfit/flexfit \
      --scene examples/ball_torus_haptic.toml --rounds 6 --csv /tmp/ab.csv
"""
import argparse
import csv
import math
import os
import re
import statistics
import subprocess
import tempfile

from results_table import report


def percentile(sorted_values, p):
    return sorted_values[min(len(sorted_values), max(1, math.ceil(p / 100 * len(sorted_values)))) - 1]


def stage_columns(row):
    """A metrics.csv row's per-stage time columns (us_*, but the whole step's)."""
    return [k for k in row if k.startswith("us_") and k != "us_world_step"]


def step_us(row):
    """World::step's time in a metrics.csv row: its us_world_step, or (older builds) the sum of its stages."""
    return float(row["us_world_step"]) if "us_world_step" in row else sum(float(row[k]) for k in stage_columns(row))


def measure(flexfit, scene, directory):
    """One run: the in-contact figures and the state hash."""
    out = os.path.join(directory, "run")
    done = subprocess.run([flexfit, "run", scene, "--out", out, "--no-progress"], check=True, capture_output=True, text=True)
    found = re.search(r"state hash (\w+)", done.stdout)
    with open(os.path.join(out, "metrics.csv")) as f:
        rows = [r for r in csv.DictReader(f) if float(r["contacts"]) > 0]
    if not rows:
        raise SystemExit(f"{scene}: no step with contacts under {flexfit}")
    stages = stage_columns(rows[0])
    steps = sorted(step_us(r) for r in rows)
    figures = {"step_source": "us_world_step" if "us_world_step" in rows[0] else "sum of stages", "contact_steps": len(rows), "contacts": statistics.mean(float(r["contacts"]) for r in rows),
               "us_step_p50": percentile(steps, 50), "us_step_p99": percentile(steps, 99), "us_step_max": steps[-1]}
    figures.update({k: statistics.mean(float(r[k]) for r in rows) for k in stages})
    return figures, found.group(1) if found else "?"


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--flexfit", action="append", required=True, help="NAME=PATH of a flexfit binary (two or more)")
    parser.add_argument("--scene", action="append", required=True)
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--csv")
    args = parser.parse_args()
    binaries = [b.split("=", 1) for b in args.flexfit]
    if len(binaries) < 2 or any(len(b) != 2 for b in binaries):
        raise SystemExit("give two or more --flexfit NAME=PATH")
    rows = []
    with tempfile.TemporaryDirectory() as directory:
        for scene in args.scene:
            runs, hashes = {}, {}
            for r in range(args.rounds):
                for name, path in binaries[r % len(binaries):] + binaries[: r % len(binaries)]:
                    figures, state = measure(path, scene, directory)
                    runs.setdefault(name, []).append(figures)
                    hashes.setdefault(name, set()).add(state)
            first = None
            for name, _ in binaries:
                keys = [k for k in runs[name][0] if k != "step_source"]
                median = {"step_source": runs[name][0]["step_source"]}
                median.update({k: statistics.median(run[k] for run in runs[name]) for k in keys})
                first = first or median
                row = {"scene": os.path.basename(scene), "binary": name, "state_hash": " ".join(sorted(hashes[name]))}
                row["p50_ratio"] = first["us_step_p50"] / median["us_step_p50"]
                row["p99_ratio"] = first["us_step_p99"] / median["us_step_p99"]
                row.update(median)
                rows.append(row)
    keys = list(dict.fromkeys(k for row in rows for k in row))
    report([{k: row.get(k, float("nan")) for k in keys} for row in rows], args.csv)


if __name__ == "__main__":
    main()
