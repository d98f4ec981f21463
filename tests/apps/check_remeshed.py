#!/usr/bin/python3
"""Runs an example scene and its remeshed twin (the same scene with the deformable part read
from a file and simulated on its isotropic remeshing, drawn as the file's mesh) and checks
that they give the same outcome, within stated shares, and that the twin's OBJ frame draws the
file's own mesh. Prints "remeshed: same outcome" only when all of that holds.

Usage: check_remeshed.py FLEXFIT EXAMPLES_DIR OUT_DIR
"""
import json
import pathlib
import subprocess
import sys

# (generated scene, remeshed twin, deformable part, its file, summary keys and allowed relative
# difference, whether the scene must assemble)
PAIRS = [
    ("ball_torus", "ball_torus_remeshed", "mouth", "container_mouth.tri",
     {"max_deformation": 0.05, "last_contact": 0.05, "restored_at": 0.10}, True),
    ("contact", "contact_remeshed", "blue", "torus1.tri",
     {"max_deformation": 0.10, "last_contact": 0.05, "restored_at": 0.10}, False),
]


def run(flexfit, scene, out):
    done = subprocess.run([flexfit, "run", str(scene), "--out", str(out), "--no-progress"], check=True,
                          stdout=subprocess.PIPE, text=True)
    print(done.stdout, end="")
    return json.loads((out / "summary.json").read_text()), done.stdout


def obj_vertex_counts(path):
    counts, name = {}, None
    for line in path.read_text().splitlines():
        if line.startswith("o "):
            name = line[2:].strip()
            counts[name] = 0
        elif line.startswith("v "):
            counts[name] += 1
    return counts


def file_vertex_count(tri):
    return int(tri.read_text().splitlines()[1].split()[0])


def main():
    flexfit, examples, out = sys.argv[1], pathlib.Path(sys.argv[2]).resolve(), pathlib.Path(sys.argv[3])
    failures = []
    for generated, remeshed, part, mesh_file, keys, assembles in PAIRS:
        a, a_text = run(flexfit, examples / f"{generated}.toml", out / generated)
        # The twin with one OBJ frame at the end (mesh paths made absolute).
        text = (examples / f"{remeshed}.toml").read_text().replace(f'"{mesh_file}"', f'"{examples / mesh_file}"')
        duration = a["simulated_seconds"]
        twin = out / f"{remeshed}.toml"
        out.mkdir(parents=True, exist_ok=True)
        twin.write_text(text + f"\n[output]\nobj_every = {duration}\n")
        b, b_text = run(flexfit, twin, out / remeshed)
        for key, share in keys.items():
            x, y = a[key], b[key]
            if abs(y - x) > share * abs(x):
                failures.append(f"{remeshed}: {key} {y} against {x} generated (more than {share:.0%} apart)")
            print(f"{remeshed}: {key} {y:.4g} against {x:.4g} generated ({abs(y - x) / abs(x):.1%}, allowed {share:.0%})")
        if assembles and ("assembled:" not in a_text or "assembled:" not in b_text):
            failures.append(f"{remeshed}: both must assemble")
        frames = sorted((out / remeshed).glob("frame_*.obj"))
        if not frames:
            failures.append(f"{remeshed}: no OBJ frame written")
            continue
        drawn = obj_vertex_counts(frames[-1]).get(part)
        expected = file_vertex_count(examples / mesh_file)
        if drawn != expected:
            failures.append(f"{remeshed}: the OBJ frame draws {part} with {drawn} vertices, the file has {expected}")
    for f in failures:
        print("FAILED:", f)
    if failures:
        sys.exit(1)
    print("remeshed: same outcome")


if __name__ == "__main__":
    main()
