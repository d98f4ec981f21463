#!/usr/bin/python3
"""`flexfit simulate` on a mesh file in no useful vertex order (a torus with its vertices
shuffled, written here): with --vertex-order locality (the default) the masses are renumbered
inside, yet --force, --kick and --zone name the file's vertices (a level-4 zone at the loaded
vertex: wider than the one the force would open, so the motion tells where it is) and the OBJ frames are the file's mesh in
its order: the first frame is the file's vertices (exactly where nothing moved yet), and every frame matches the run with
--vertex-order as_given up to rounding. Then the same file damaged as exports are (a stray vertex no face uses in
the middle of the list, a vertex written twice): the read removes and welds them, yet the indices and frames are the
damaged file's, every frame vertex where the clean run put it. Prints "vertex order: the file's" only when all holds.

Usage: check_vertex_order.py FLEXFIT OUT_DIR
"""
import math
import pathlib
import random
import subprocess
import sys


def torus(u, v, major=3.0, minor=1.0):
    vertices = []
    for i in range(u):
        for j in range(v):
            a, b = 2 * math.pi * i / u, 2 * math.pi * j / v
            r = major + minor * math.cos(b)
            vertices.append((r * math.cos(a), minor * math.sin(b), r * math.sin(a)))
    faces = []
    for i in range(u):
        for j in range(v):
            p, q = i * v + j, ((i + 1) % u) * v + j
            pn, qn = i * v + (j + 1) % v, ((i + 1) % u) * v + (j + 1) % v
            faces += [(p, pn, q), (q, pn, qn)]
    return vertices, faces


def obj(path):
    vertices, faces = [], []
    for line in path.read_text().splitlines():
        if line.startswith("v "):
            vertices.append(tuple(float(x) for x in line.split()[1:4]))
        elif line.startswith("f "):
            faces.append(line.split()[1:4])
    return vertices, faces


def main():
    flexfit, out = sys.argv[1], pathlib.Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    vertices, faces = torus(24, 16)
    order = list(range(len(vertices)))
    random.Random(5).shuffle(order)  # vertex i is written as vertex order[i]
    shuffled = [None] * len(vertices)
    for i, p in enumerate(vertices):
        shuffled[order[i]] = p
    # The .tri format keeps the file's vertex order and every bit (assimp's formats are read in
    # first-use order, in single precision).
    mesh = out / "shuffled.tri"
    mesh.write_text(f"shuffled\n{len(shuffled)} {len(faces)}\n" + "".join("%.17g %.17g %.17g\n" % p for p in shuffled) +
                    "".join("%d %d %d\n" % tuple(order[k] for k in f) for f in faces))
    # Damaged: a stray vertex inserted as vertex 10, and face 30's first corner written again at the end.
    damaged = shuffled[:10] + [(7.0, 0.5, -2.0)] + shuffled[10:]
    shift = [k + (k >= 10) for k in order]
    damaged_faces = [[shift[k] for k in f] for f in faces]
    repeated = damaged_faces[30][0]
    damaged.append(damaged[repeated])
    damaged_faces[30][0] = len(damaged) - 1
    damaged_mesh = out / "damaged.tri"
    damaged_mesh.write_text(f"damaged\n{len(damaged)} {len(faces)}\n" + "".join("%.17g %.17g %.17g\n" % p for p in damaged) +
                            "".join("%d %d %d\n" % tuple(f) for f in damaged_faces))
    frames = {}
    for choice, file, (force, kick) in (("locality", mesh, (5, 200)), ("as_given", mesh, (5, 200)), ("damaged", damaged_mesh, (5, 201))):
        prefix = out / choice
        done = subprocess.run([flexfit, "simulate", str(file), "--vertex-order", "as_given" if choice == "as_given" else "locality",
                               "--mode", "rigid-deformable", "--force", f"{force}:0,0.5,0.2", "--kick", f"{kick}:0.3,0,0", "--zone",
                               f"{force}@4", "--duration", "0.2", "--obj-at", "0,0.1,0.2", "--obj-prefix", str(prefix)],
                              check=True, stdout=subprocess.PIPE, text=True)
        print(done.stdout, end="")
        assert ("renumbered for locality" in done.stdout) == (choice != "as_given"), "the run does not say whether it renumbered"
        frames[choice] = [obj(pathlib.Path(f"{prefix}_{t:.4f}.obj")) for t in (0.0, 0.1, 0.2)]
    for (va, fa), (vd, fd) in zip(frames["locality"], frames["damaged"]):
        assert len(vd) == len(damaged), f"a frame of the damaged file has {len(vd)} vertices, the file {len(damaged)}"
        assert all(vd[c + (c >= 10)] == va[c] for c in range(len(va))), \
            "the damaged file's frame vertices are not where the clean run put them"
        assert vd[-1] == vd[repeated], "the repeated vertex does not follow its first copy"
        assert fd == [[str(k + 1) for k in f] for f in damaged_faces[:30] + [[repeated] + damaged_faces[30][1:]] + damaged_faces[31:]], \
            "the damaged file's frame faces are not the file's"
    assert frames["damaged"][0][0][10] == (7.0, 0.5, -2.0), "the stray vertex is not at its place in the first frame"
    rest_vertices, rest_faces = frames["locality"][0]
    file_vertices = shuffled
    file_faces = [[str(order[k] + 1) for k in f] for f in faces]
    # The first frame is written after the first step: only the loaded and kicked vertices and
    # their neighbours have moved (a wrong order would put vertices whole units away).
    exact = sum(a == b for a, b in zip(rest_vertices, file_vertices))
    assert len(rest_vertices) == len(file_vertices) and exact > len(file_vertices) - 20, \
        f"the first frame is not the file's vertices in its order ({exact} of {len(file_vertices)} equal)"
    assert max(math.dist(a, b) for a, b in zip(rest_vertices, file_vertices)) < 1e-2, "the first frame is not the file's vertices"
    assert rest_faces == file_faces, "the frame's faces are not the file's"
    largest = moved5 = moved200 = 0.0
    for (va, fa), (vb, fb) in zip(frames["locality"], frames["as_given"]):
        assert fa == fb, "the two runs' frames have different faces"
        largest = max([largest] + [math.dist(a, b) for a, b in zip(va, vb)])
        moved5 = max(moved5, math.dist(vb[5], file_vertices[5]))
        moved200 = max(moved200, math.dist(vb[200], file_vertices[200]))
    print(f"largest difference between the runs {largest:.3g}; file vertex 5 moved {moved5:.3g}, vertex 200 {moved200:.3g}")
    assert largest < 1e-9, "the runs differ beyond rounding"
    assert moved5 > 1e-4 and moved200 > 1e-4, "the loaded and kicked file vertices did not move"
    print("vertex order: the file's")


if __name__ == "__main__":
    main()
