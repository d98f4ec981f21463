"""examples/python/ run and produce their plots; what they print is checked against the runs."""

import os
import pathlib
import re
import subprocess
import sys

import numpy as np
import pytest

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


def test_the_cpp_haptic_loop_is_grab_and_move_through_the_cpp_api(tmp_path, capsys, haptic_loop_exe):
    # examples/cpp/haptic_loop.cpp builds grab_and_move.py's world through the C++ API and steps
    # it as a device loop: at 1 kHz the same run, so the same largest coupling force and state.
    forces = grab_and_move.main(tmp_path)
    python_hash = re.search(r"state hash ([0-9a-f]{16})", capsys.readouterr().out).group(1)
    printed = subprocess.run([haptic_loop_exe, "--free-running"], check=True, capture_output=True, text=True).stdout
    summary = re.search(r"largest device force ([0-9.]+) N; ball lowest at y = (-?[0-9.]+), now (-?[0-9.]+); .* state hash ([0-9a-f]{16})",
                        printed)
    assert summary, printed
    assert float(summary.group(1)) == pytest.approx(np.linalg.norm(forces, axis=1).max(), abs=1e-3)
    assert float(summary.group(3)) == pytest.approx(-12.0, abs=1e-3) and summary.group(4) == python_hash
    assert "3000 steps at 1000 Hz" in printed and "(free running)" in printed
    # The rim's anchor springs are the same at any rate, so the run converges as the rate rises
    # (5 kHz closer to 2 kHz than 2 kHz to 1 kHz, within 1 % of each other), and the rim restores.
    largest = [float(summary.group(1))]
    for rate in (2000, 5000):
        out = subprocess.run([haptic_loop_exe, "--free-running", "--rate", str(rate)], check=True, capture_output=True, text=True).stdout
        largest.append(float(re.search(r"largest device force ([0-9.]+) N", out).group(1)))
        assert "rim moving masses 0;" in out, out
    assert abs(largest[2] - largest[1]) < abs(largest[1] - largest[0]) and max(largest) < 1.01 * min(largest), largest
    # Paced by the clock: every tick ends at or after its deadline, so the last one too.
    paced = subprocess.run([haptic_loop_exe, "--seconds", "0.5"], check=True, capture_output=True, text=True).stdout
    wall = float(re.search(r"500 steps at 1000 Hz in ([0-9.]+) s wall;", paced).group(1))
    assert wall >= 0.5, paced
    bad = subprocess.run([haptic_loop_exe, "--rate", "0"], capture_output=True, text=True)
    assert bad.returncode == 2 and "--rate must be in [100, 100000] Hz" in bad.stderr


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
