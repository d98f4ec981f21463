#!/usr/bin/python3
"""Runs `flexfit experiment ball-torus` (2 s per run, default frictions 0 and 0.5), echoes its
summary, and checks its runs.csv:

- the frictionless runs (the thesis's Table 4.5 set: rigid, elastic and stiff rims, balls 14 to
  17, gravity and push) have the outcomes they had before friction was added (at 2 s per run:
  the 6 s table's outcomes except elastic 16 under gravity, which passes only after 3 s);
- the friction column is there, and every run of that set comes once per friction;
- under the named rim "yielding" every ball up to 17 passes when pushed, at every friction;
- the snap jump: the rigid rim, with the assembly area it needs (reaching up to where it held the
  ball), snaps each ball it stopped farther than any rigid-deformable rim that let that ball
  through (thesis Fig. 4.36-4.37).

Prints "ball-torus: all checks passed" only when every check holds (the ctest looks for it).

Usage: check_ball_torus.py FLEXFIT OUT_DIR
"""
import csv
import pathlib
import subprocess
import sys

DIAMETERS = ["14", "15", "15.1", "16", "17"]
FRICTIONS = ["0", "0.5"]

# Outcomes of the frictionless runs at 2 s per run, as the command gave them before it had a
# friction column (same scenes, same state hashes).
FRICTIONLESS = {
    ("rigid", "14"): ("assembled", "assembled"), ("rigid", "15"): ("stopped", "stopped"),
    ("rigid", "15.1"): ("stopped", "stopped"), ("rigid", "16"): ("stopped", "stopped"),
    ("rigid", "17"): ("stopped", "stopped"),
    ("elastic", "14"): ("assembled", "assembled"), ("elastic", "15"): ("assembled", "assembled"),
    ("elastic", "15.1"): ("assembled", "assembled"), ("elastic", "16"): ("stopped", "assembled"),
    ("elastic", "17"): ("stopped", "assembled"),
    ("stiff", "14"): ("assembled", "assembled"), ("stiff", "15"): ("assembled", "assembled"),
    ("stiff", "15.1"): ("assembled", "assembled"), ("stiff", "16"): ("stopped", "assembled"),
    ("stiff", "17"): ("stopped", "stopped"),
}
PASSED = ("assembled", "passed")


def main():
    flexfit, out = sys.argv[1:3]
    run = subprocess.run([flexfit, "experiment", "ball-torus", "--out", out, "--duration", "2", "--no-plots"], check=True,
                         stdout=subprocess.PIPE, text=True)
    print(run.stdout, end="")
    errors = []
    with open(pathlib.Path(out) / "runs.csv", newline="") as f:
        reader = csv.DictReader(f)
        columns = reader.fieldnames or []
        runs = list(reader)
    for column in ("friction", "area", "result", "snap_jump_distance", "snap_jump_degrees"):
        if column not in columns:
            errors.append(f"runs.csv has no column '{column}' (columns: {columns})")
    if errors:
        sys.exit("\n".join(errors))

    table = {}  # (torus, diameter, load, friction, area) -> run
    for r in runs:
        key = (r["torus"], r["diameter"], r["load"], r["friction"], r["area"])
        if key in table:
            errors.append(f"run {key} twice")
        table[key] = r
        if r["result"] == "assembled" and not (r["snap_jump_distance"] and r["snap_jump_degrees"]):
            errors.append(f"{r['run']}: assembled but no snap jump")
        if r["snap_jump_degrees"] and not 0.0 <= float(r["snap_jump_degrees"]) <= 180.0:
            errors.append(f"{r['run']}: snap jump of {r['snap_jump_degrees']} degrees")

    def result(torus, d, load, mu, area="thesis"):
        r = table.get((torus, d, load, mu, area))
        return r["result"] if r else None

    def jump(torus, d, load, mu, area="thesis"):
        r = table.get((torus, d, load, mu, area))
        return float(r["snap_jump_distance"]) if r and r["snap_jump_distance"] else None

    # The friction column: every run of the thesis's set once per friction, frictionless ones
    # with their old outcomes.
    if sorted({r["friction"] for r in runs}) != FRICTIONS:
        errors.append(f"frictions {sorted({r['friction'] for r in runs})}, expected {FRICTIONS}")
    for (torus, d), outcomes in FRICTIONLESS.items():
        for load, expected in zip(("gravity", "push"), outcomes):
            for mu in FRICTIONS:
                if result(torus, d, load, mu) is None:
                    errors.append(f"no run {torus} {d} {load} friction {mu}")
            got = result(torus, d, load, "0")
            if got is not None and got != expected:
                errors.append(f"frictionless {torus} {d} {load}: {got}, was {expected}")

    # The named rim: every ball up to 17 passes when pushed.
    for d in DIAMETERS:
        for mu in FRICTIONS:
            got = result("yielding", d, "push", mu)
            if got not in PASSED:
                errors.append(f"yielding rim, ball {d} pushed, friction {mu}: {got or 'not run'}, expected it to pass")

    # The snap jump: rigid rim (held area) against the rigid-deformable rims (thesis area).
    compared = 0
    for d in ["15", "15.1", "16", "17"]:
        for mu in FRICTIONS:
            for load in ("gravity", "push"):
                rigid = jump("rigid", d, load, mu, "held")
                if rigid is None:
                    if load == "push":
                        errors.append(f"rigid rim, ball {d} pushed, friction {mu}: no snap with the held area")
                    continue
                for torus in ("elastic", "stiff", "yielding"):
                    soft = jump(torus, d, load, mu)
                    if soft is None:
                        continue
                    compared += 1
                    if not rigid > soft:
                        errors.append(f"ball {d} {load} friction {mu}: rigid rim's snap jump {rigid:.3f} not larger than "
                                      f"{torus}'s {soft:.3f}")
            if jump("yielding", d, "push", mu) is None:
                errors.append(f"yielding rim, ball {d} pushed, friction {mu}: no snap jump to compare")
    summary = (pathlib.Path(out) / "summary.md").read_text()
    for text in ("| friction |", "Every ball passed, at every friction.", "## Snap jump"):
        if text not in summary:
            errors.append(f"summary.md lacks '{text}'")
    if errors:
        sys.exit("ball-torus check failed:\n  " + "\n  ".join(errors))
    print(f"ball-torus: {len(runs)} runs, {compared} snap jumps of the rigid rim larger than the rigid-deformable rims'")
    print("ball-torus: all checks passed")


if __name__ == "__main__":
    main()
