#!/usr/bin/python3
"""Runs `flexfit run SCENE`, echoes its output, and checks the contact force columns of PART
(a dynamic part) in its metrics.csv: PART_contact_fx, _fy, _fz are there, zero in every step
without contacts, non-zero in every step with contacts (in the scene given, PART is the only
body that can press the deformable part: every contact is its own), and at their largest
pointing up (the deformable part holds PART up against its load). Prints "contact force
checked" only when all of that holds.

Usage: check_contact_force.py FLEXFIT SCENE OUT_DIR PART [--duration SECONDS]
"""
import csv
import pathlib
import subprocess
import sys


def main():
    flexfit, scene, out, part = sys.argv[1:5]
    extra = sys.argv[5:]
    run = subprocess.run([flexfit, "run", scene, "--out", out, "--no-progress", *extra], check=True,
                         stdout=subprocess.PIPE, text=True)
    print(run.stdout, end="")
    with open(pathlib.Path(out) / "metrics.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    columns = [f"{part}_contact_f{axis}" for axis in "xyz"]
    missing = [c for c in columns if c not in rows[0]]
    if missing:
        sys.exit(f"{scene}: metrics.csv has no column {', '.join(missing)}")
    touching, apart = [], []
    for row in rows:
        force = [float(row[c]) for c in columns]
        (touching if int(row["contacts"]) > 0 else apart).append((float(row["time"]), force))
    if not touching:
        sys.exit(f"{scene}: no step with contacts")
    for time, force in apart:
        if any(force):
            sys.exit(f"{scene}: t = {time}: contact force {force} on {part} without any contact")
    for time, force in touching:
        if not any(force):
            sys.exit(f"{scene}: t = {time}: {part} in contact but its contact force is zero")
    time, (fx, fy, fz) = max(touching, key=lambda tf: sum(x * x for x in tf[1]))
    if not fy > 10.0 * (abs(fx) + abs(fz)):
        sys.exit(f"{scene}: t = {time}: the largest contact force on {part}, ({fx}, {fy}, {fz}), does not point up")
    print(f"{part}: contact force checked: non-zero in the {len(touching)} steps with contacts, zero in the other "
          f"{len(apart)}; largest ({fx:.6g}, {fy:.6g}, {fz:.6g}) at t = {time}")


if __name__ == "__main__":
    main()
