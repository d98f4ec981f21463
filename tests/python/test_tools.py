"""The measuring scripts' own computations (tools/): geometry checked against what the mesh
must keep, tables against ratios worked out by hand."""

import csv
import json
import math
import subprocess
import sys

import pytest
from conftest import ROOT

sys.path.insert(0, str(ROOT / "tools"))
import tool_press  # noqa: E402


def subdivided_octahedron(levels):
    """A closed surface: the octahedron, midpoint-subdivided `levels` times (tool_press.subdivide)."""
    vertices = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    faces = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
    for _ in range(levels):
        vertices, faces = tool_press.subdivide(vertices, faces)
    return vertices, faces


def area(vertices, faces):
    total = 0.0
    for a, b, c in faces:
        u = [q - p for p, q in zip(vertices[a], vertices[b])]
        w = [q - p for p, q in zip(vertices[a], vertices[c])]
        total += 0.5 * math.dist((0, 0, 0), (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]))
    return total


def directed_edges(faces):
    return [(f[i], f[(i + 1) % 3]) for f in faces for i in range(3)]


# Kept as they are: a half (its seam's faces split in 2) and a wedge (at its corners, in 3).
@pytest.mark.parametrize("near,inner", [(lambda p: p[0] > 0.3, lambda p: p[0] > 0.6),
                                        (lambda p: p[0] > 0.2 and p[1] > 0.2, lambda p: p[0] > 0.3 and p[1] > 0.3)])
def test_refine_away_stays_closed_and_oriented_and_keeps_the_near_faces(near, inner):
    vertices, faces = subdivided_octahedron(3)
    refined_vertices, refined = vertices, faces
    for _ in range(2):
        refined_vertices, refined = tool_press.refine_away(refined_vertices, refined, near)
    # Closed and consistently wound: each directed edge once, its reverse once (no crack at the seam).
    edges = directed_edges(refined)
    unique = set(edges)
    assert len(edges) == len(unique)
    assert all((b, a) in unique for a, b in unique)
    # The same surface: splitting at midpoints of flat triangles keeps the area.
    assert math.isclose(area(refined_vertices, refined), area(vertices, faces), rel_tol=1e-12)
    # Faces with every vertex well inside the near side are the input's, untouched.
    inside = [f for f in faces if all(inner(vertices[v]) for v in f)]
    assert inside and all(f in refined for f in inside)
    # The far side was refined: each of its faces into 16 by two levels.
    far_before = sum(1 for f in faces if all(vertices[v][0] < 0.0 for v in f))
    far_after = sum(1 for f in refined if all(refined_vertices[v][0] < 0.0 for v in f))
    assert far_before and far_after >= 16 * far_before


def test_step_tails_reads_the_runs_metrics(tmp_path, flexfit_exe, examples):
    # Two names for one build: each the scene's pinned golden hash (tests/world/scene_run_test.cpp),
    # and each tail read from metrics.csv's steps.
    import step_tails
    table = tmp_path / "tails.csv"
    subprocess.run([sys.executable, str(ROOT / "tools" / "step_tails.py"), "--flexfit", f"a={flexfit_exe}", "--flexfit", f"b={flexfit_exe}",
                    "--scene", str(examples / "contact.toml"), "--rounds", "1", "--csv", str(table)], check=True)
    with open(table) as f:
        rows = list(csv.DictReader(f))
    assert [r["build"] for r in rows] == ["a", "b"]
    assert [r["state_hash"] for r in rows] == ["6f71c49d7327c00a"] * 2
    for r in rows:
        first, slowest, p50, p99, worst = (float(r[c]) for c in step_tails.COLUMNS)
        assert 0 < first <= slowest and 0 < p50 <= p99 <= worst <= slowest
    metrics = tmp_path / "metrics.csv"
    metrics.write_text("time,contacts,us_world_step\n0.001,0,7.5\n0.002,3,2.0\n0.003,4,9.0\n0.004,0,1.0\n")
    assert step_tails.tails(metrics) == [7.5, 9.0, 2.0, 9.0, 9.0]


def test_ab_bench_table_takes_medians_over_rounds_and_the_reference_of_the_same_argument():
    """tools/ab_bench.py's table from known per-round medians: ratios computed by hand."""
    import ab_bench
    report = json.dumps({"benchmarks": [
        {"aggregate_name": "median", "run_name": "BM_Ours/0", "label": "torus1", "real_time": 5.0, "time_unit": "us"},
        {"aggregate_name": "mean", "run_name": "BM_Ours/0", "label": "torus1", "real_time": 99.0, "time_unit": "us"},
        {"aggregate_name": "median", "run_name": "BM_Naive/0", "label": "torus1", "real_time": 12000.0, "time_unit": "ns"}]})
    assert list(ab_bench.medians(report)) == [("BM_Ours/0", "torus1", 5000.0), ("BM_Naive/0", "torus1", 12000.0)]
    times = {("before", "BM_Ours/0"): [6000.0, 5000.0, 7000.0], ("after", "BM_Ours/0"): [4000.0, 5000.0, 4500.0],
             ("before", "BM_Naive/0"): [12000.0, 13000.0, 11000.0], ("after", "BM_Naive/0"): [12000.0, 12500.0, 11500.0]}
    header, rows = ab_bench.table(times, {"BM_Ours/0": "torus1"}, ["before", "after"], "BM_Naive", 3)
    assert header[:5] == ["benchmark", "mesh", "before_us", "after_us", "speedup"]
    assert rows == [["BM_Ours/0", "torus1", "6.000", "4.500", f"{6000 / 4500:.3f}", "12.000", "12.000",
                     f"{12000 / 6000:.3f}", f"{12000 / 4500:.3f}", 3]]


def test_tool_press_summary_keeps_the_contact_steps_whole_and_refuses_rounds_that_differ():
    """Two rounds of one binary: medians of the figures, the floors from each step's fastest
    time, the contact steps as the integer every round gave; rounds that disagree on them fail."""
    def round_of(narrow, steps):
        return {"contact_steps": 2, "contacts": 3.0, "us_narrow_phase": sum(narrow) / 2, "us_world_step": sum(steps) / 2,
                "per_step": {"0.001": (narrow[0], steps[0]), "0.002": (narrow[1], steps[1])}}
    row = tool_press.summary([round_of([4.0, 6.0], [10.0, 12.0]), round_of([5.0, 3.0], [9.0, 14.0])])
    assert row["contact_steps"] == 2 and isinstance(row["contact_steps"], int)
    assert row["us_narrow_phase"] == pytest.approx((5.0 + 4.0) / 2) and row["us_world_step"] == pytest.approx((11.0 + 11.5) / 2)
    assert row["floor_us_narrow_phase"] == pytest.approx((4.0 + 3.0) / 2)
    assert row["floor_us_world_step"] == pytest.approx((9.0 + 12.0) / 2) and row["floor_us_step_p99"] == 12.0
    other = round_of([4.0, 6.0], [10.0, 12.0])
    other["contact_steps"] = 3
    with pytest.raises(SystemExit, match="did not repeat"):
        tool_press.summary([round_of([4.0, 6.0], [10.0, 12.0]), other])


def test_bench_ratios_reads_the_median_or_the_fastest_repetition(tmp_path, capsys):
    """tools/bench_ratios.py on a CSV with repetitions, their median and min rows, and a
    benchmark run once: the ratios of the chosen statistic, worked out by hand."""
    import bench_ratios
    path = tmp_path / "msd.csv"
    path.write_text("\n".join([
        "a preamble line",
        "name,iterations,real_time,cpu_time,time_unit,label",
        "BM_Ours/0,10,5.0,5.0,ns,torus1",
        "BM_Ours/0,10,4.0,4.0,ns,torus1",
        "BM_Ours/0,10,9.0,9.0,ns,torus1",
        "BM_Ours/0_mean,3,6.0,6.0,ns,torus1",
        "BM_Ours/0_median,3,5.0,5.0,ns,torus1",
        "BM_Ours/0_stddev,3,2.6,2.6,ns,torus1",
        "BM_Ours/0_min,3,4.0,4.0,ns,torus1",
        "BM_Naive/0,10,15.0,15.0,ns,torus1",
        "BM_Naive/0_median,3,15.0,15.0,ns,torus1",
        "BM_Naive/0_min,3,14.0,14.0,ns,torus1",
        "BM_Ours/1,10,2.0,2.0,ns,heart",
        "BM_Naive/1,10,7.0,7.0,ns,heart"]) + "\n")
    medians, fastest = bench_ratios.load(path), bench_ratios.load(path, "min")
    assert {name: float(row["real_time"]) for name, row in medians.items()} == {
        "BM_Ours/0": 5.0, "BM_Naive/0": 15.0, "BM_Ours/1": 2.0, "BM_Naive/1": 7.0}
    assert {name: float(row["real_time"]) for name, row in fastest.items()} == {
        "BM_Ours/0": 4.0, "BM_Naive/0": 14.0, "BM_Ours/1": 2.0, "BM_Naive/1": 7.0}
    bench_ratios.prefixes(fastest, "BM_Ours", "BM_Naive")
    table = capsys.readouterr().out
    assert "| torus1 | 14 | 4 | 3.50x |" in table and "| heart | 7 | 2 | 3.50x |" in table


def test_tail_repeats_tells_a_slow_step_of_every_run_from_stalls_that_move():
    import tail_repeats
    # Each run stalls on another step: every step's fastest time is the work's 10 us, each run's
    # own p99 (nearest rank of 4 steps: the slowest) is its stall, and no slow step repeats.
    moving = tail_repeats.summary("s.toml", "a", [([10.0, 50.0, 10.0, 10.0], "h"), ([10.0, 10.0, 10.0, 60.0], "h"), ([10.0, 10.0, 40.0, 10.0], "h")])
    assert (moving["measured_p99"], moving["floor_p50"], moving["floor_p99"], moving["floor_max"]) == (50.0, 10.0, 10.0, 10.0)
    assert (moving["top_repeat_pct"], moving["top_chance_pct"]) == (0.0, 25.0)
    # A step slow in every run is the work's: the floor keeps its fastest time, and it repeats.
    work = tail_repeats.summary("s.toml", "a", [([10.0, 50.0, 12.0], "h"), ([11.0, 45.0, 10.0], "h")])
    assert (work["floor_p50"], work["floor_p99"], work["top_repeat_pct"]) == (10.0, 45.0, 100.0)
    # Runs that did not simulate the same steps are not compared.
    with pytest.raises(SystemExit, match="not one trajectory"):
        tail_repeats.summary("s.toml", "a", [([10.0], "h"), ([10.0], "g")])
    assert tail_repeats.summary("s.toml", "a", [([], "h"), ([], "h")])["floor_p99"] == ""


def test_tail_repeats_composes_the_floor_tail_from_each_steps_fastest_stages(tmp_path):
    import tail_repeats
    # 100 steps: step 7 is the slowest in both runs (its narrow phase), so it alone is the floor's
    # slowest 1 %; the middle band (ranks 45-55 %) holds ordinary steps.
    def steps(narrow_at_7, extra):
        out = []
        for s in range(100):
            narrow = narrow_at_7 if s == 7 else 10.0 + 0.01 * s + extra
            out.append({"step_us": narrow + 20.0, "narrow_us": narrow, "response_us": 5.0 + extra, "zone_dynamics_us": 3.0,
                        "contacts": 900.0 if s == 7 else 100.0, "zones_opened": 2.0 if s == 7 else 0.0})
        return out
    runs = [steps(80.0, 0.0), steps(60.0, 1.0)]  # run 2 slower everywhere: the floor takes run 1 but at step 7
    row = tail_repeats.summary("s.toml", "a", [([x["step_us"] for x in r], "h", r) for r in runs])
    assert (row["tail_contacts"], row["tail_zones_opened"], row["tail_narrow_us"], row["tail_response_us"]) == (900.0, 2.0, 60.0, 5.0)
    assert (row["mid_contacts"], row["mid_zones_opened"], row["mid_zone_dynamics_us"]) == (100.0, 0.0, 3.0)
    assert 10.0 < row["mid_narrow_us"] < 11.0
    # From metrics.csv: the zones a step opened are the rise of the zone count, in-contact steps only.
    metrics = tmp_path / "metrics.csv"
    metrics.write_text("time,contacts,zones,us_narrow_phase,us_contact_response,us_zone_dynamics,us_world_step\n"
                       "0.001,0,0,1,1,1,4\n0.002,3,2,2,2,2,7\n0.003,4,5,3,3,3,10\n0.004,2,1,1,1,1,4\n")
    read = tail_repeats.contact_steps(metrics)
    assert [(x["step_us"], x["contacts"], x["zones_opened"], x["narrow_us"]) for x in read] == [(7.0, 3.0, 2.0, 2.0), (10.0, 4.0, 3.0, 3.0), (4.0, 2.0, 0.0, 1.0)]


def test_tail_repeats_reads_the_step_timer_or_older_builds_stage_sums(tmp_path):
    import tail_repeats
    timed = tmp_path / "timed.csv"
    timed.write_text("time,contacts,us_a,us_world_step\n0.001,0,1.0,7.5\n0.002,3,1.0,2.0\n0.003,4,2.0,9.0\n")
    assert tail_repeats.contact_step_times(timed) == [2.0, 9.0]
    older = tmp_path / "older.csv"
    older.write_text("time,contacts,us_a,us_b\n0.001,2,1.0,2.5\n0.002,0,1.0,7.0\n")
    assert tail_repeats.contact_step_times(older) == [3.5]
