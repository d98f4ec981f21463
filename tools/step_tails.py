#!/usr/bin/python3
"""Step-time tails of example scenes, side by side for several flexfit builds.

For each round, each scene and each build (`--flexfit NAME=PATH`, in alternating order from
round to round, so the machine's drift falls on every column alike), runs `flexfit run` and
reads metrics.csv's per-step `us_world_step` (World::step's wall time): the first step, the
slowest step of the run, and the in-contact p50 / p99 / max (nearest rank). The medians over
rounds are written, with the state hash each build printed (builds that change no result print
the same one).

  tools/step_tails.py --flexfit before=/tmp/old/flexfit --flexfit after=build/release/apps/flexfit/flexfit \
      --scene examples/ball_torus_haptic.toml --rounds 4 --csv bench/results/step_tails.csv
"""
import argparse
import csv
import math
import re
import statistics
import subprocess
from pathlib import Path

from ab_stages import percentile  # nearest rank, as every other table here
from results_table import alternating_runs

COLUMNS = ["first_step_us", "slowest_step_us", "contact_step_us_p50", "contact_step_us_p99", "contact_step_us_max"]


def tails(metrics):
    """The COLUMNS of one run, from its metrics.csv (the in-contact ones NaN without contact)."""
    with open(metrics) as f:
        rows = list(csv.DictReader(f))
    every = [float(r["us_world_step"]) for r in rows]
    contact = sorted(float(r["us_world_step"]) for r in rows if int(r["contacts"]) > 0)
    ranks = [percentile(contact, p) if contact else float("nan") for p in (50, 99, 100)]
    return [every[0], max(every), *ranks]


def run(flexfit, scene, out):
    done = subprocess.run([flexfit, "run", scene, "--out", out, "--no-progress"], capture_output=True, text=True, check=True)
    return tails(Path(out) / "metrics.csv"), re.search(r"state hash (\w+)", done.stdout).group(1)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--flexfit", action="append", required=True, help="NAME=PATH of a flexfit build")
    ap.add_argument("--scene", action="append", required=True)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--csv", required=True)
    args = ap.parse_args()
    builds = [tuple(b.split("=", 1)) for b in args.flexfit]
    results = alternating_runs(builds, args.scene, args.rounds, run)  # (scene, build) -> [(tails, hash)]
    with open(args.csv, "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["scene", "build", *COLUMNS, "state_hash", "rounds"])
        for scene in args.scene:
            for name, _ in builds:
                runs = results[(scene, name)]
                hashes = sorted({h for _, h in runs})
                medians = [statistics.median(t[i] for t, _ in runs) for i in range(len(COLUMNS))]
                cells = ["" if math.isnan(m) else f"{m:.1f}" for m in medians]  # no contact: no contact tail
                out.writerow([Path(scene).stem, name, *cells, "/".join(hashes), len(runs)])


if __name__ == "__main__":
    main()
