"""examples/python/ run and produce their plots; what they print is checked against the runs."""

import os
import pathlib
import subprocess
import sys

import numpy as np

EXAMPLES = pathlib.Path(__file__).resolve().parents[2] / "examples" / "python"
sys.path.insert(0, str(EXAMPLES))

import grab_and_move  # noqa: E402
import zone_depths  # noqa: E402


def test_grab_and_move_reports_the_rims_push_back(tmp_path):
    forces = grab_and_move.main(tmp_path)
    assert (tmp_path / "coupling_force.png").stat().st_size > 0
    # Pulled down through the rim, the coupling pulls the ball down (negative y) hardest while
    # the rim holds it, and little before contact or once it is through.
    y = forces[:, 1]
    assert y.min() < -10 * abs(y[-1]) and y.argmin() < 2000


def test_zone_depths_counts_every_moving_mass(tmp_path):
    counts = zone_depths.main(tmp_path, seconds=0.6)
    assert (tmp_path / "zone_depths.png").stat().st_size > 0
    assert counts.shape == (600, 3) and counts.sum(axis=1).max() > 0
    busiest = counts.sum(axis=1).argmax()
    assert counts[busiest, 1] > counts[busiest, 0] > 0  # seeds, and a wider ring around them


def test_table_4_5_sweep_runs_on_dask_and_plots(tmp_path):
    env = dict(os.environ)
    printed = subprocess.run([sys.executable, str(EXAMPLES / "table_4_5_sweep.py"), "--workers", "2", "--out", str(tmp_path)], check=True,
                             capture_output=True, text=True, env=env).stdout
    assert "30 runs (30 run now)" in printed, printed
    assert (tmp_path / "table_4_5.png").stat().st_size > 0
    import pandas

    table = pandas.read_csv(tmp_path / "results.csv")
    assert len(table) == 30 and (table["status"] == "ok").all()
    # A rigid rim stops the balls of 15.1 and more (no tunnelling); the yielding rim lets every
    # pushed ball through (thesis 4.4.3, `flexfit experiment ball-torus`).
    rigid = table[table["rim"] == "rigid"]
    assert (rigid[rigid["diameter"] >= 15.1]["assembly_events"] == 0).all()
    assert (table[table["rim"] == "yielding"]["assembly_events"] == 1).all()
