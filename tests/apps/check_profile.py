#!/usr/bin/python3
"""Runs `flexfit run SCENE`, echoes its output, and checks the profile in its summary.json:
world_step_seconds is there, every stage is named, and the stages add up to the step
(0.97 <= sum / total <= 1.0; the profile partitions the step, so this fails only when a stage
is missing from stage_seconds or the file is inconsistent). And the in-contact step-time tail:
contact_step_us_p50, _p99 and _max equal the nearest-rank percentiles computed here from
metrics.csv's per-step us_world_step over the steps with contacts (null when there are none),
and step_us_max the largest over every step.

Usage: check_profile.py FLEXFIT SCENE OUT_DIR [--duration SECONDS]
"""
import csv
import json
import math
import pathlib
import subprocess
import sys

STAGES = ["operator_input", "rigid_motion", "contact_solver", "broad_phase", "narrow_phase", "contact_response",
          "zone_dynamics", "zone_retirement", "assembly"]


def main():
    flexfit, scene, out = sys.argv[1:4]
    extra = sys.argv[4:]
    run = subprocess.run([flexfit, "run", scene, "--out", out, "--no-progress", *extra], check=True,
                         stdout=subprocess.PIPE, text=True)
    print(run.stdout, end="")
    summary = json.loads((pathlib.Path(out) / "summary.json").read_text())
    total = summary["world_step_seconds"]
    stages = summary["stage_seconds"]
    if sorted(stages) != sorted(STAGES):
        sys.exit(f"{scene}: stages {sorted(stages)}, expected {sorted(STAGES)}")
    ratio = sum(stages.values()) / total
    print(f"{pathlib.Path(scene).name}: world_step_seconds {total:.6f}, stages sum to {ratio:.6f} of it")
    if not 0.97 <= ratio <= 1.0 + 1e-9:
        sys.exit(f"{scene}: stages sum to {ratio:.6f} of world_step_seconds (expected 0.97 to 1.0)")
    check_tail(scene, summary, pathlib.Path(out) / "metrics.csv")


def nearest_rank(values, p):
    """The smallest value that at least p % of the values do not exceed."""
    ordered = sorted(values)
    rank = max(1, math.ceil(p / 100.0 * len(ordered)))
    return ordered[rank - 1]


def check_tail(scene, summary, metrics):
    with metrics.open() as f:
        rows = list(csv.DictReader(f))
    every = [float(r["us_world_step"]) for r in rows]
    if every and abs(summary["step_us_max"] - max(every)) > 1e-3:
        sys.exit(f"{scene}: step_us_max {summary['step_us_max']}, expected {max(every)} from metrics.csv")
    slowest_at = float(rows[every.index(max(every))]["time"]) if every else None
    if every and abs(summary["step_us_max_time"] - slowest_at) > 1e-9:
        sys.exit(f"{scene}: step_us_max_time {summary['step_us_max_time']}, expected {slowest_at} from metrics.csv")
    steps = [float(r["us_world_step"]) for r in rows if int(r["contacts"]) > 0]
    for key, p in (("p50", 50), ("p99", 99), ("max", 100)):
        got = summary[f"contact_step_us_{key}"]
        expected = nearest_rank(steps, p) if steps else None
        if (got is None) != (expected is None) or (got is not None and abs(got - expected) > 1e-9):
            sys.exit(f"{scene}: contact_step_us_{key} {got}, expected {expected} from metrics.csv")
    if steps:
        print(f"{pathlib.Path(scene).name}: in-contact step p50 {summary['contact_step_us_p50']} us, "
              f"p99 {summary['contact_step_us_p99']} us, max {summary['contact_step_us_max']} us ({len(steps)} steps)")


if __name__ == "__main__":
    main()
