#!/usr/bin/python3
"""A tool pressed into a user's part, in a world, by one or more flexfit binaries side by side.

The part is Wuson (Debian's assimp-testmodels, a third-party mesh of 3,732 faces, open, 51
pieces), its vertices shuffled (seeded), at 1x, 4x and 16x its faces (midpoint subdivision). A
kinematic level-3 icosphere of radius 10 % of the part's box diagonal comes down onto its
highest vertex, presses 20 % of its radius in, and slides along it while the part deforms
(rigid-deformable part, face query: `rigid_deformable_query = "faces"`). For each binary and
size: the in-contact steps' mean narrow phase and World::step, and the step's p50 / p99
(nearest rank), from metrics.csv. Runs alternate between binaries, their order reversed every
other round, `--rounds` times; the medians are reported, and the floor: each step's fastest
time over the rounds (floor_*, the work's own cost; the medians carry this VM's stalls, which
moved a binary's x1 narrow phase from 12.8 to 20.8 us between two runs minutes apart).

  tools/tool_press.py --flexfit new=build/release/apps/flexfit/flexfit \
      --flexfit old=/tmp/base/build/apps/flexfit/flexfit --csv bench/results/tool_press.csv
A path ending in "+plain" runs that binary with coherent_collision = false; "+auto" with
rigid_deformable_query = "auto" (the point shell where the part is finer than the tool; the
contacts are then masses, not face pairs). Suffixes combine.
"""
import argparse
import csv
import math
import os
import random
import statistics
import subprocess
import tempfile

from ab_stages import percentile, step_us  # nearest rank, as every other table here
from results_table import alternating_runs, report

WUSON = "/usr/share/assimp/models/OFF/Wuson.off"


def read_off(path):
    words = []
    with open(path) as f:
        for line in f:
            line = line.split("#", 1)[0].split()
            words.extend(line)
    assert words[0] == "OFF", path
    nv, nf = int(words[1]), int(words[2])
    at = 4
    vertices = [tuple(float(w) for w in words[at + 3 * i: at + 3 * i + 3]) for i in range(nv)]
    at += 3 * nv
    faces = []
    for _ in range(nf):
        n = int(words[at])
        poly = [int(w) for w in words[at + 1: at + 1 + n]]
        at += 1 + n
        faces.extend((poly[0], poly[k], poly[k + 1]) for k in range(1, n - 1))
    return vertices, faces


def subdivide(vertices, faces):
    """Every face split in 4 at its edges' midpoints."""
    return refine_away(vertices, faces, lambda p: False)


def refine_away(vertices, faces, near):
    """One level of conforming red-green refinement of the faces whose centroid is not `near`:
    those split into 4 at their edges' midpoints; a near face with split edges (the seam) into
    2 or 3, so the mesh stays conforming. Faces with no split edge stay as they are."""
    vertices = list(vertices)
    split = set()
    for f in faces:
        if not near(tuple(sum(vertices[v][d] for v in f) / 3 for d in range(3))):
            split.update((min(f[i], f[(i + 1) % 3]), max(f[i], f[(i + 1) % 3])) for i in range(3))
    mids = {}

    def mid(a, b):
        key = (min(a, b), max(a, b))
        if key not in mids:
            mids[key] = len(vertices)
            vertices.append(tuple(0.5 * (x + y) for x, y in zip(vertices[a], vertices[b])))
        return mids[key]

    out = []
    for f in faces:
        cut = [(min(f[i], f[(i + 1) % 3]), max(f[i], f[(i + 1) % 3])) in split for i in range(3)]
        if all(cut):
            a, b, c = f
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            out += [(a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca)]
        elif any(cut):
            # Rotate so that edge (a, b) is cut and, with two cuts, (b, c) is the other.
            k = next(i for i in range(3) if cut[i] and (sum(cut) == 1 or cut[(i + 1) % 3]))
            a, b, c = f[k], f[(k + 1) % 3], f[(k + 2) % 3]
            ab = mid(a, b)
            if sum(cut) == 1:
                out += [(a, ab, c), (ab, b, c)]
            else:
                bc = mid(b, c)
                out += [(ab, b, bc), (a, ab, bc), (a, bc, c)]
        else:
            out.append(f)
    return vertices, out


def shuffled(vertices, faces, seed):
    order = list(range(len(vertices)))
    random.Random(seed).shuffle(order)  # vertex v becomes order[v]
    moved = [None] * len(vertices)
    for v, p in enumerate(vertices):
        moved[order[v]] = p
    return moved, [tuple(order[v] for v in f) for f in faces]


def write_obj(path, vertices, faces):
    with open(path, "w") as f:
        for p in vertices:
            f.write("v %.17g %.17g %.17g\n" % p)
        for a, b, c in faces:
            f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


SCENE = """[world]
rigid_deformable_query = "{query}"
time_step = 0.001
gravity = [0, 0, 0]
duration = 2.0

[[part]]
name = "part"
mesh = "{mesh}"
mode = "rigid-deformable"
motion = "static"
restoration = "constraint"
constraint_fraction = 2e-3
global_damping = 0.5
contact_level = 3

[[part]]
name = "tool"
generator = {{ type = "sphere", radius = {radius}, level = 3 }}
mode = "rigid"
motion = "kinematic"
position = [{x}, {y_start}, {z}]

[[action]]
time = 0.0
type = "grab"
part = "tool"

[[action]]
time = 0.0
type = "move"
part = "tool"
position = [{x}, {y_press}, {z}]
duration = 0.5

[[action]]
time = 0.5
type = "move"
part = "tool"
position = [{x}, {y_press}, {z_end}]
duration = 1.5
"""


def distance_to_segment(p, a, b):
    ab = [y - x for x, y in zip(a, b)]
    t = sum((q - x) * d for q, x, d in zip(p, a, ab)) / sum(d * d for d in ab)
    t = min(1.0, max(0.0, t))
    return math.dist(p, [x + t * d for x, d in zip(a, ab)])


# Faces within this many tool radii of the tool's path stay as the file has them with --refine
# away: the contacts and the zones under the tool (within about 1.6 radii) meet the same faces.
NEAR_RADII = 2.5


def scenes(directory, refine="uniform"):
    vertices, faces = read_off(WUSON)
    lo = [min(p[d] for p in vertices) for d in range(3)]
    hi = [max(p[d] for p in vertices) for d in range(3)]
    radius = 0.1 * math.dist(lo, hi)
    top = max(vertices, key=lambda p: p[1])
    y_press, z_end = top[1] + 0.8 * radius, top[2] + 2.0 * radius
    path = ((top[0], y_press, top[2]), (top[0], y_press, z_end))
    near = lambda p: distance_to_segment(p, *path) < NEAR_RADII * radius  # noqa: E731
    out = []
    for level in range(3):
        v, f = shuffled(vertices, faces, 7)
        name = f"wuson_{'away_' if refine == 'away' else ''}x{4 ** level}"
        mesh = os.path.join(directory, name + ".obj")
        write_obj(mesh, v, f)
        scene = os.path.join(directory, f"tool_press_{name}.toml")
        with open(scene, "w") as s:
            s.write(SCENE.format(query="faces", mesh=mesh, radius=radius, x=top[0], z=top[2], y_start=top[1] + 1.3 * radius,
                                 y_press=y_press, z_end=z_end))
        out.append((f"wuson {'refined away ' + str(level) if refine == 'away' else 'x' + str(4 ** level)}", len(f), scene))
        vertices, faces = refine_away(vertices, faces, near) if refine == "away" else subdivide(vertices, faces)
    return out


# A binary path's suffixes, each rewriting the scene for that run.
VARIANTS = {
    "+plain": ("[world]\n", "[world]\ncoherent_collision = false\n"),
    "+auto": ('rigid_deformable_query = "faces"', 'rigid_deformable_query = "auto"'),
}


def measure(flexfit, scene, directory):
    os.makedirs(directory, exist_ok=True)
    out = os.path.join(directory, "run")
    with open(scene) as f:
        text = f.read()
    while any(flexfit.endswith(suffix) for suffix in VARIANTS):
        suffix = next(s for s in VARIANTS if flexfit.endswith(s))
        flexfit = flexfit[: -len(suffix)]
        text = text.replace(*VARIANTS[suffix], 1)
    scene = os.path.join(directory, "variant.toml")
    with open(scene, "w") as f:
        f.write(text)
    subprocess.run([flexfit, "run", scene, "--out", out, "--no-progress"], check=True, stdout=subprocess.DEVNULL)
    with open(os.path.join(out, "metrics.csv")) as f:
        rows = [r for r in csv.DictReader(f) if float(r["contacts"]) > 0]
    steps = [step_us(r) for r in rows]
    narrow = [float(r["us_narrow_phase"]) for r in rows]
    return {"contact_steps": len(rows), "contacts": statistics.mean(float(r["contacts"]) for r in rows),
            "moving_masses": statistics.mean(float(r["moving_masses"]) for r in rows),
            "us_narrow_phase": statistics.mean(narrow), "us_world_step": statistics.mean(steps),
            "us_step_p50": percentile(sorted(steps), 50), "us_step_p99": percentile(sorted(steps), 99),
            "per_step": {r["time"]: (n, s) for r, n, s in zip(rows, narrow, steps)}}


def floors(results):
    """The work's own times, without this VM's stalls: a binary simulates the same steps in every
    round, so each step's fastest narrow phase and World::step over the rounds is what its work
    costs (a stall falls on a different step each round; tools/tail_repeats.py's floor)."""
    common = set.intersection(*(set(r["per_step"]) for r in results))
    narrow = [min(r["per_step"][t][0] for r in results) for t in common]
    steps = [min(r["per_step"][t][1] for r in results) for t in common]
    return {"floor_us_narrow_phase": statistics.mean(narrow), "floor_us_world_step": statistics.mean(steps),
            "floor_us_step_p99": percentile(sorted(steps), 99)}


def summary(results):
    """One binary's row over its rounds: the median of each figure, the floors, and the contact
    steps, which a run repeats exactly (the simulation is deterministic): rounds that differ
    there are an error, not a median."""
    counts = sorted({r["contact_steps"] for r in results})
    if len(counts) != 1:
        raise SystemExit(f"the rounds' contact steps differ ({counts}): a run did not repeat itself")
    row = {key: counts[0] if key == "contact_steps" else statistics.median(r[key] for r in results)
           for key in results[0] if key != "per_step"}
    row.update(floors(results))
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--flexfit", action="append", required=True, help="NAME=PATH of a flexfit binary")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--csv")
    parser.add_argument("--refine", choices=("uniform", "away"), default="uniform",
                        help="x4 and x16: every face split in 4 (uniform), or only the faces away from the tool's path (away)")
    args = parser.parse_args()
    binaries = [b.split("=", 1) for b in args.flexfit]
    if not os.path.exists(WUSON):
        raise SystemExit(f"{WUSON} is missing: install Debian's assimp-testmodels")
    with tempfile.TemporaryDirectory() as directory:
        parts = scenes(directory, args.refine)
        runs = alternating_runs(binaries, [scene for _, _, scene in parts], args.rounds, measure)
    report([{"part": label, "faces": faces, "binary": name, **summary(runs[(scene, name)])}
            for label, faces, scene in parts for name, _ in binaries], args.csv)


if __name__ == "__main__":
    main()
