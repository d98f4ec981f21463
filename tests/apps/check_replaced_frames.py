#!/usr/bin/python3
"""`flexfit run` twice into one --out directory: a long run with OBJ and VTK frames, then a short
one with VTK frames only. The second run's directory must hold its own frames and frames.pvd
(listing exactly them) and none of the first run's, while a file of the user's stays. Prints
"frames replaced" only when all holds.

Usage: check_replaced_frames.py FLEXFIT SCENE OUT_DIR
"""
import pathlib
import re
import shutil
import subprocess
import sys


def run(flexfit, scene, out, *options):
    subprocess.run([flexfit, "run", scene, "--out", str(out), "--no-progress", *options], check=True, stdout=subprocess.DEVNULL)


def frames(out):
    return sorted(p.name for p in out.iterdir() if re.fullmatch(r"frame_[0-9]{6}\.(obj|vtp|glb)", p.name))


def main():
    flexfit, scene, out = sys.argv[1], sys.argv[2], pathlib.Path(sys.argv[3])
    shutil.rmtree(out, ignore_errors=True)
    run(flexfit, scene, out, "--duration", "0.06", "--obj-every", "0.01", "--vtk-every", "0.01")
    first = frames(out)
    assert len(first) == 12, first
    (out / "notes.txt").write_text("the user's\n")
    run(flexfit, scene, out, "--duration", "0.02", "--vtk-every", "0.01")
    second = frames(out)
    assert second == ["frame_000010.vtp", "frame_000020.vtp"], second
    listed = re.findall(r'file="([^"]+)"', (out / "frames.pvd").read_text())
    assert listed == second, listed
    assert (out / "notes.txt").read_text() == "the user's\n"
    run(flexfit, scene, out, "--duration", "0.02")  # no frames at all: no frames.pvd either
    assert frames(out) == [] and not (out / "frames.pvd").exists(), sorted(p.name for p in out.iterdir())
    print("frames replaced")


if __name__ == "__main__":
    main()
