"""The operator grabs a ball and moves it down through a deformable container mouth; the plot
shows the coupling force a haptic device would render (its opposite).

    PYTHONPATH=build/release/python /usr/bin/python3 examples/python/grab_and_move.py
"""

import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import flexfit  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main(out=ROOT / "out" / "grab_and_move"):
    world = flexfit.World(time_step=1e-3, gravity=[0, 0, 0])
    rim = flexfit.PartModel(flexfit.container_mouth(), material="elastic")
    ball = flexfit.PartModel(flexfit.sphere(8.0, 2))
    # Anchor springs restore the rim: about the default constraint's 1,000 N/m per kg at 1 kHz,
    # but the same at any time step (examples/cpp/haptic_loop.cpp runs this at 1-10 kHz).
    mouth = world.add(rim, mode="rigid-deformable", motion="static", contact_level=3, restoration="anchors", anchor_stiffness=1000.0,
                      anchor_damping=63.0)
    b = world.add(ball, mode="rigid", motion="dynamic", position=[0, 4.0, 0], density=0.01)
    world.grab(b, frequency=10.0)

    times, forces, moving = [], [], []
    for step in range(3000):  # the target eases from y = 4 to y = -12 in 2 s, then holds
        s = min(step / 2000.0, 1.0)
        y = 4.0 - 16.0 * s * s * (3.0 - 2.0 * s)
        world.set_grab_target([0, y, 0])
        world.step()
        times.append(world.time)
        forces.append(world.coupling()["force"].copy())
        moving.append(len(world.part(mouth).moving_masses))
    forces = np.array(forces)

    out.mkdir(parents=True, exist_ok=True)
    figure, axis = plt.subplots(figsize=(8, 4))
    axis.plot(times, forces[:, 1], label="coupling force y (on the ball)")
    axis.plot(times, np.linalg.norm(forces, axis=1), label="|coupling force|")
    axis.set_xlabel("time (s)")
    axis.set_ylabel("force")
    twin = axis.twinx()
    twin.plot(times, moving, color="grey", linestyle=":", label="moving rim masses")
    twin.set_ylabel("moving rim masses")
    axis.legend(loc="upper left")
    figure.tight_layout()
    figure.savefig(out / "coupling_force.png", dpi=100)
    print(f"largest coupling force {np.linalg.norm(forces, axis=1).max():.1f} at t = {times[int(np.argmax(np.linalg.norm(forces, axis=1)))]:.3f} s; "
          f"ball at y = {world.centre_of_mass(b)[1]:.2f}; state hash {world.state_hash():016x}; plot {out / 'coupling_force.png'}")
    return forces


if __name__ == "__main__":
    main()
