#!/usr/bin/python3
"""Whether a scene's slow steps are the work's or the machine's: the same build run several times.

A build simulates the same steps on every run (the state hash says so), so a step whose work is
slow is slow in every run, while a stall of the machine (an interrupt, the hypervisor taking the
core) falls on a different step each time. For each scene and build (`--flexfit NAME=PATH`,
alternating from round to round), runs `flexfit run` `--runs` times and reads every in-contact
step's World::step time (metrics.csv's `us_world_step`; older builds without it: the sum of the
stage columns, as tools/ab_stages.py). Reports:
- measured_p50 / measured_p99 / measured_max: the median over the runs of each run's own
  (nearest rank), what tools/ab_stages.py and tools/step_tails.py report;
- floor_p50 / floor_p99 / floor_max: the same ranks of each step's fastest time over the runs,
  the tail the work itself sets (a step is slow there only if it was slow in every run);
- top_repeat_pct: of each run's slowest 1 % of steps, the share (%) that are among the slowest
  1 % of the next run (mean over consecutive pairs), beside top_chance_pct, the share expected
  if the slow steps fell at random (1 % of the steps): near chance, the tail is the machine's.

  tools/tail_repeats.py --flexfit new=build/release/apps/flexfit/flexfit \
      --flexfit 6d7824d=/tmp/base/build/apps/flexfit/flexfit \
      --scene examples/ball_torus_haptic.toml --runs 8 --csv bench/results/tail_repeats.csv
"""
import argparse
import csv
import math
import re
import statistics
import subprocess
from pathlib import Path

from ab_stages import percentile, step_us  # nearest rank, as every other table here
from results_table import alternating_runs, report

COLUMNS = ["measured_p50", "measured_p99", "measured_max", "floor_p50", "floor_p99", "floor_max", "top_repeat_pct", "top_chance_pct"]


def contact_step_times(metrics):
    """World::step's time of every in-contact step of one run, in step order."""
    with open(metrics) as f:
        rows = [r for r in csv.DictReader(f) if float(r["contacts"]) > 0]
    if not rows:
        return []
    return [step_us(r) for r in rows]


def run(flexfit, scene, out):
    done = subprocess.run([flexfit, "run", scene, "--out", out, "--no-progress"], capture_output=True, text=True, check=True)
    return contact_step_times(Path(out) / "metrics.csv"), re.search(r"state hash (\w+)", done.stdout).group(1)


def ranks(values):
    ordered = sorted(values)
    return [percentile(ordered, p) for p in (50, 99, 100)]


def slowest(times, share=0.01):
    """The indices of the slowest `share` of the steps (at least one)."""
    count = max(1, math.ceil(share * len(times)))
    return set(sorted(range(len(times)), key=lambda s: -times[s])[:count])


def summary(scene, name, runs):
    hashes = sorted({h for _, h in runs})
    lengths = {len(t) for t, _ in runs}
    if len(hashes) != 1 or len(lengths) != 1:
        raise SystemExit(f"{scene}, {name}: the runs differ (state hashes {hashes}, contact steps {sorted(lengths)}): not one trajectory")
    times = [t for t, _ in runs]
    steps = len(times[0])
    row = {"scene": Path(scene).stem, "build": name, "runs": len(runs), "contact_steps": steps}
    if steps == 0:  # no contact: no contact tail
        return row | {k: "" for k in COLUMNS} | {"state_hash": hashes[0]}
    measured = [statistics.median(ranks(t)[i] for t in times) for i in range(3)]
    floor = ranks([min(t[s] for t in times) for s in range(steps)])
    tops = [slowest(t) for t in times]
    repeat = statistics.mean(len(a & b) / len(a) for a, b in zip(tops, tops[1:])) if len(tops) > 1 else float("nan")
    values = [*measured, *floor, 100.0 * repeat, 100.0 * len(tops[0]) / steps]
    return row | dict(zip(COLUMNS, values)) | {"state_hash": hashes[0]}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--flexfit", action="append", required=True, help="NAME=PATH of a flexfit build")
    ap.add_argument("--scene", action="append", required=True)
    ap.add_argument("--runs", type=int, default=6)
    ap.add_argument("--csv")
    args = ap.parse_args()
    if args.runs < 2:
        raise SystemExit("give --runs 2 or more: the floor and the repeats compare runs")
    builds = [tuple(b.split("=", 1)) for b in args.flexfit]
    results = alternating_runs(builds, args.scene, args.runs, run)  # (scene, build) -> [(times, hash)]
    report([summary(scene, name, results[(scene, name)]) for scene in args.scene for name, _ in builds], args.csv)


if __name__ == "__main__":
    main()
