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
  if the slow steps fell at random (1 % of the steps): near chance, the tail is the machine's
  (build/release/bench/bench_step_noise reads the same percentiles of a step of constant work,
  the machine's share of a measured tail at a given step time);
- where the floor's tail goes: over the floor's slowest 1 % of steps (tail_*) and the steps
  ranked 45-55 % in it (mid_*), the mean of each step's fastest narrow phase, contact response
  and zone dynamics over the runs (`*_us`), its contacts and the zones it opened (the rise of
  metrics.csv's zone count from the step before; both the same in every run). A tail above the
  middle by more contacts is the work's size; by zones opened, the zones' bookkeeping.

  tools/tail_repeats.py --flexfit new=build/release/apps/flexfit/flexfit \
      --flexfit 6d7824d=/tmp/base/build/apps/flexfit/flexfit \
      --scene examples/ball_torus_haptic.toml --runs 8 --csv bench/results/tail_repeats.csv

`--without-key NAME=KEY` runs build NAME on a copy of each scene without the lines that set KEY
(an older build that does not know a newer key, such as `reserved_zones`, which changes no
state); the copy sits beside the scene, so its relative paths hold, and is removed after.
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
# A step's figures for the tail's composition: the stages' metrics.csv columns, then the counts.
STAGES = {"narrow_us": "us_narrow_phase", "response_us": "us_contact_response", "zone_dynamics_us": "us_zone_dynamics"}
COUNTS = ["contacts", "zones_opened"]
COMPOSITION = [f"{band}_{k}" for band in ("tail", "mid") for k in [*COUNTS, *STAGES]]


def contact_steps(metrics):
    """Every in-contact step of one run, in step order: World::step's time ("step_us"), the
    stages of STAGES, its contacts and the zones it opened."""
    with open(metrics) as f:
        rows = list(csv.DictReader(f))
    steps, zones = [], 0
    for r in rows:
        count = int(r.get("zones", 0))
        opened, zones = max(0, count - zones), count
        if float(r["contacts"]) > 0:
            steps.append({"step_us": step_us(r), "contacts": float(r["contacts"]), "zones_opened": float(opened)}
                         | {k: float(r[c]) for k, c in STAGES.items() if c in r})
    return steps


def contact_step_times(metrics):
    """World::step's time of every in-contact step of one run, in step order."""
    return [s["step_us"] for s in contact_steps(metrics)]


def run(flexfit, scene, out):
    done = subprocess.run([flexfit, "run", scene, "--out", out, "--no-progress"], capture_output=True, text=True, check=True)
    steps = contact_steps(Path(out) / "metrics.csv")
    return [s["step_us"] for s in steps], re.search(r"state hash (\w+)", done.stdout).group(1), steps


def composition(floor, stages):
    """The tail_* and mid_* columns: `floor` each step's fastest time, `stages` each run's
    contact_steps (the stages at their fastest over the runs, the counts from the first run)."""
    order = sorted(range(len(floor)), key=lambda s: floor[s])
    low, high = int(0.45 * len(order)), int(0.55 * len(order))
    bands = {"tail": sorted(slowest(floor)), "mid": order[low:max(low + 1, high)]}  # at least one middle step
    out = {}
    for band, chosen in bands.items():
        for k in COUNTS:
            out[f"{band}_{k}"] = statistics.mean(stages[0][s][k] for s in chosen)
        for k in STAGES:
            out[f"{band}_{k}"] = statistics.mean(min(run[s][k] for run in stages) for s in chosen) if k in stages[0][0] else ""
    return out


def ranks(values):
    ordered = sorted(values)
    return [percentile(ordered, p) for p in (50, 99, 100)]


def slowest(times, share=0.01):
    """The indices of the slowest `share` of the steps (at least one)."""
    count = max(1, math.ceil(share * len(times)))
    return set(sorted(range(len(times)), key=lambda s: -times[s])[:count])


def summary(scene, name, runs):
    hashes = sorted({r[1] for r in runs})
    lengths = {len(r[0]) for r in runs}
    if len(hashes) != 1 or len(lengths) != 1:
        raise SystemExit(f"{scene}, {name}: the runs differ (state hashes {hashes}, contact steps {sorted(lengths)}): not one trajectory")
    times = [r[0] for r in runs]
    steps = len(times[0])
    row = {"scene": Path(scene).stem, "build": name, "runs": len(runs), "contact_steps": steps}
    with_stages = all(len(r) > 2 for r in runs)  # run()'s; a caller may give the times alone
    if steps == 0:  # no contact: no contact tail
        return row | {k: "" for k in COLUMNS} | ({k: "" for k in COMPOSITION} if with_stages else {}) | {"state_hash": hashes[0]}
    measured = [statistics.median(ranks(t)[i] for t in times) for i in range(3)]
    floor = [min(t[s] for t in times) for s in range(steps)]
    tops = [slowest(t) for t in times]
    repeat = statistics.mean(len(a & b) / len(a) for a, b in zip(tops, tops[1:])) if len(tops) > 1 else float("nan")
    values = [*measured, *ranks(floor), 100.0 * repeat, 100.0 * len(tops[0]) / steps]
    parts = composition(floor, [r[2] for r in runs]) if with_stages else {}
    return row | dict(zip(COLUMNS, values)) | parts | {"state_hash": hashes[0]}


def without_keys(run, strip):
    """run(path, scene, out), on a copy of the scene without the keys strip[path] sets."""
    def stripped(path, scene, out):
        keys = strip.get(path)
        if not keys:
            return run(path, scene, out)
        setting = re.compile(r"\s*(%s)\s*=" % "|".join(map(re.escape, keys)))
        original = Path(scene)
        copy = original.with_name(f".{original.stem}.without-keys.toml")
        copy.write_text("".join(line for line in original.read_text().splitlines(keepends=True) if not setting.match(line)))
        try:
            return run(path, str(copy), out)
        finally:
            copy.unlink()
    return stripped


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--flexfit", action="append", required=True, help="NAME=PATH of a flexfit build")
    ap.add_argument("--scene", action="append", required=True)
    ap.add_argument("--runs", type=int, default=6)
    ap.add_argument("--csv")
    ap.add_argument("--without-key", action="append", default=[], help="NAME=KEY: build NAME runs the scenes without KEY")
    args = ap.parse_args()
    if args.runs < 2:
        raise SystemExit("give --runs 2 or more: the floor and the repeats compare runs")
    builds = [tuple(b.split("=", 1)) for b in args.flexfit]
    strip = {}
    for item in args.without_key:
        name, key = item.split("=", 1)
        strip.setdefault(dict(builds)[name], []).append(key)
    results = alternating_runs(builds, args.scene, args.runs, without_keys(run, strip))  # (scene, build) -> [(times, hash, steps)]
    report([summary(scene, name, results[(scene, name)]) for scene in args.scene for name, _ in builds], args.csv)


if __name__ == "__main__":
    main()
