#!/usr/bin/python3
"""Runs `flexfit run SCENE`, echoes its output, and checks the profile in its summary.json:
world_step_seconds is there, every stage is named, and the stages add up to the step
(0.97 <= sum / total <= 1.0; the profile partitions the step, so this fails only when a stage
is missing from stage_seconds or the file is inconsistent).

Usage: check_profile.py FLEXFIT SCENE OUT_DIR [--duration SECONDS]
"""
import json
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


if __name__ == "__main__":
    main()
