"""Reads the rim's zone depths as a NumPy array every step of the ball-through-torus scene and
plots how many masses move at each depth over time (depth 0: the zones' seeds).

    PYTHONPATH=build/release/python /usr/bin/python3 examples/python/zone_depths.py
"""

import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import flexfit  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main(out=ROOT / "out" / "zone_depths", seconds=2.0):
    scene = flexfit.load_scene(str(ROOT / "examples" / "ball_torus.toml"))
    run = flexfit.SceneRun(scene)
    mouth = run.world.part(run.body("mouth"))
    levels = 3  # contact_level 3: the zones move depths 0..2 (their ring at depth 3 is held at rest)
    counts = []
    for _ in range(round(seconds / scene.time_step)):
        run.step()
        depths = mouth.zone_depths  # one int per mass, -1 where the rim is at rest
        counts.append(np.bincount(depths[depths >= 0], minlength=levels)[:levels])
    counts = np.array(counts)
    times = np.arange(1, len(counts) + 1) * scene.time_step

    out.mkdir(parents=True, exist_ok=True)
    figure, axis = plt.subplots(figsize=(8, 4))
    axis.stackplot(times, counts.T, labels=[f"depth {d}" for d in range(levels)])
    axis.set_xlabel("time (s)")
    axis.set_ylabel("moving rim masses")
    axis.legend(loc="upper right")
    figure.tight_layout()
    figure.savefig(out / "zone_depths.png", dpi=100)
    print(f"most moving masses {counts.sum(axis=1).max()} (of {mouth.model.mass_count}); plot {out / 'zone_depths.png'}")
    return counts


if __name__ == "__main__":
    main()
