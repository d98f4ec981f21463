"""Scenes, sweeps and exports from Python, against the `flexfit` command and readers that are
not ours (VTK's, assimp's)."""

import os
import pathlib
import re
import shutil
import signal
import subprocess
import time

import pytest

import flexfit

SCENES = sorted((pathlib.Path(__file__).resolve().parents[2] / "examples").glob("*.toml"))


@pytest.mark.parametrize("scene", SCENES, ids=[s.stem for s in SCENES])
def test_python_run_of_each_example_gives_the_commands_hash(scene, flexfit_exe):
    printed = subprocess.run([flexfit_exe, "run", str(scene), "--no-progress"], check=True, capture_output=True, text=True).stdout
    expected = re.search(r"state hash ([0-9a-f]{16})", printed).group(1)
    loaded = flexfit.load_scene(str(scene))
    run = flexfit.SceneRun(loaded)
    steps = round(loaded.duration / loaded.time_step)
    for _ in range(steps):  # stepped from Python, one call a step
        run.step()
    assert f"{run.world.state_hash():016x}" == expected
    assert flexfit.run_scene(str(scene))["state_hash"] == expected


SWEEP = """scene = "{scene}"
duration = {duration}
[[parameter]]
name = "diameter"
key = ["part.ball.generator.radius", "part.ball.position", "assembly.0.primary_vector"]
values = [
  [7.0, [0, 5.6, 0], {{ origin = [0, -7.0, 0], end = [0, 7.0, 0] }}],
  [7.5, [0, 5.3, 0], {{ origin = [0, -7.5, 0], end = [0, 7.5, 0] }}],
  [8.5, [0, 4.7, 0], {{ origin = [0, -8.5, 0], end = [0, 8.5, 0] }}],
]
labels = ["14", "15", "17"]
[[parameter]]
name = "rim"
key = "part.mouth.mode"
values = ["rigid", "rigid-deformable"]
[[parameter]]
name = "friction"
key = ["part.ball.static_friction", "part.mouth.static_friction"]
values = [[0.0, 0.0], [0.5, 0.5]]
"""


def write_sweep(tmp_path, examples, duration):
    path = tmp_path / "sweep.toml"
    path.write_text(SWEEP.format(scene=examples / "ball_torus.toml", duration=duration))
    return path


def test_sweep_is_the_same_table_on_one_or_two_workers_and_from_the_command(tmp_path, examples, flexfit_exe):
    sweep = write_sweep(tmp_path, examples, 1.5)
    two = flexfit.sweep(sweep, tmp_path / "two", workers=2)
    one = flexfit.sweep(sweep, tmp_path / "one", workers=1)
    subprocess.run([flexfit_exe, "sweep", str(sweep), "--out", str(tmp_path / "cmd"), "--no-progress"], check=True, capture_output=True)
    # Any scheduler by its address: here a cluster started apart, as a user's would be.
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        remote = flexfit.sweep(sweep, tmp_path / "remote", scheduler=cluster.scheduler_address)
    assert len(remote.attrs["ran"]) == 12
    tables = [(tmp_path / d / "results.csv").read_bytes() for d in ("two", "one", "cmd", "remote")]
    assert tables[0] == tables[1] == tables[2] == tables[3]
    assert len(two) == 12 and len(two.attrs["ran"]) == 12
    assert list(two.columns[:4]) == ["run", "diameter", "rim", "friction"]
    assert (two["status"] == "ok").all() and two["state_hash"].str.len().eq(16).all()
    # A ball of diameter 17 passes a rigid-deformable rim and is assembled; a rigid rim holds it.
    d17 = two[two["diameter"] == 17]
    assert d17[d17["rim"] == "rigid-deformable"]["assembly_events"].eq(1).all()
    assert d17[d17["rim"] == "rigid"]["assembly_events"].eq(0).all()
    # Runs already done are not run again.
    again = flexfit.sweep(sweep, tmp_path / "two", workers=2)
    assert again.attrs["ran"] == [] and (tmp_path / "two" / "results.csv").read_bytes() == tables[0]


def test_an_interrupted_sweep_completes_only_what_is_missing(tmp_path, examples, flexfit_exe):
    sweep = write_sweep(tmp_path, examples, 4.0)
    out = tmp_path / "out"
    loaded = flexfit.load_sweep(str(sweep))
    command = subprocess.Popen([flexfit_exe, "sweep", str(sweep), "--out", str(out), "--jobs", "1", "--no-progress"])
    deadline = time.monotonic() + 120
    while len(list(out.glob("runs/*/row.csv"))) < 4 and time.monotonic() < deadline:
        time.sleep(0.01)
    command.send_signal(signal.SIGKILL)
    command.wait()
    done = {p.parent.name for p in out.glob("runs/*/row.csv")}
    assert 4 <= len(done) < 12, "the command was not stopped half-way"
    rows_before = {d: (out / "runs" / d / "row.csv").read_bytes() for d in done}
    table = flexfit.sweep(sweep, out, workers=2)
    assert set(table.attrs["ran"]) == set(loaded.run_ids) - done
    assert {d: (out / "runs" / d / "row.csv").read_bytes() for d in done} == rows_before
    reference = tmp_path / "reference"
    subprocess.run([flexfit_exe, "sweep", str(sweep), "--out", str(reference), "--no-progress"], check=True)
    assert (out / "results.csv").read_bytes() == (reference / "results.csv").read_bytes()


def test_vtk_frames_load_with_vtks_reader_and_glb_with_assimp(tmp_path, examples):
    vtk = pytest.importorskip("vtk")
    summary = flexfit.run_scene(str(examples / "ball_torus.toml"), out=str(tmp_path), duration=0.8, vtk_every=0.2, glb_every=0.4)
    scene = flexfit.load_scene(str(examples / "ball_torus.toml"))
    masses = {name: flexfit.SceneRun(scene).world.part(i).model.mass_count for i, name in enumerate(scene.part_names)}
    frames = sorted(tmp_path.glob("frame_*.vtp"))
    assert len(frames) == 4 and (tmp_path / "frames.pvd").exists()
    pvd = (tmp_path / "frames.pvd").read_text()
    assert all(f.name in pvd for f in frames)
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(frames[1]))
    reader.Update()
    data = reader.GetOutput()
    total = sum(masses.values())
    assert data.GetNumberOfPoints() == total
    fields = data.GetPointData()
    for name, components in [("zone_depth", 1), ("displacement", 3), ("velocity", 3)]:
        array = fields.GetArray(name)
        assert array is not None and array.GetNumberOfTuples() == total and array.GetNumberOfComponents() == components
    depths = [fields.GetArray("zone_depth").GetValue(i) for i in range(total)]
    assert max(depths) >= 0  # at 0.4 s the ball presses the rim: zones are open
    glbs = sorted(tmp_path.glob("frame_*.glb"))
    assert len(glbs) == 2
    mesh, _ = flexfit.read_mesh(str(glbs[0]))  # assimp's glTF 2 importer
    assert mesh.faces.shape[0] == sum(flexfit.SceneRun(scene).world.part(i).model.mesh.faces.shape[0] for i in range(len(masses)))
    assert summary["steps"] == 800


def test_a_diverged_run_is_a_row_and_the_sweep_goes_on(tmp_path, flexfit_exe):
    import pandas

    data = pathlib.Path(__file__).resolve().parents[1] / "apps" / "data"
    subprocess.run([flexfit_exe, "sweep", str(data / "diverging_sweep.toml"), "--out", str(tmp_path), "--no-progress"], check=True,
                   capture_output=True)
    table = pandas.read_csv(tmp_path / "results.csv", dtype={"state_hash": str})
    assert list(table["status"]) == ["ok", "diverged"]
    assert len(table.columns) == 21 and table["state_hash"].isna().tolist() == [False, True]
    assert "diverged at t = " in table["message"][1] and "stability bound" in table["message"][1]
    # The diverged run left only its row (the run's own files are written all or none).
    assert [p.name for p in (tmp_path / "runs" / table["run"][1]).iterdir()] == ["row.csv"]


def test_a_parameter_may_change_a_parts_motion_and_editing_the_sweep_reruns_it(tmp_path, examples):
    sweep = tmp_path / "motion.toml"
    text = f"""scene = "{examples / 'ball_torus.toml'}"
duration = 0.3
[[parameter]]
name = "motion"
key = "part.ball.motion"
values = ["static", "dynamic"]
"""
    sweep.write_text(text)
    table = flexfit.sweep(sweep, tmp_path / "out", workers=1)
    assert list(table["motion"]) == ["static", "dynamic"]
    assert table.loc[0, "ball_y"] == 4.7 and table.loc[1, "ball_y"] < 4.7  # the static ball stays, the pushed one falls
    # Another duration: every run is new (its results would differ), none reused.
    sweep.write_text(text.replace("duration = 0.3", "duration = 0.2"))
    again = flexfit.sweep(sweep, tmp_path / "out", workers=1)
    assert len(again.attrs["ran"]) == 2 and set(again["run"]).isdisjoint(table["run"])
    assert (again["simulated_seconds"] == 0.2).all()


def test_a_sweeps_runs_read_their_scenes_with_the_options_given(tmp_path, examples, flexfit_exe, monkeypatch):
    # Two runs of a scene with a remeshed part: the Dask sweep and the command keep one surface
    # in the remesh cache named (a relative directory is the client's), the file load_scene
    # writes; strict meshes refuse a file's defect in every run.
    sweep = tmp_path / "remeshed.toml"
    sweep.write_text(f'scene = "{examples / "contact_remeshed.toml"}"\nduration = 0.01\n'
                     '[[parameter]]\nname = "damping"\nkey = "part.blue.global_damping"\nvalues = [0.5, 0.6]\n')
    monkeypatch.chdir(tmp_path)
    table = flexfit.sweep(sweep, tmp_path / "out", workers=1, remesh_cache="cache")
    assert (table["status"] == "ok").all() and len(table) == 2
    names = [f.name for f in (tmp_path / "cache").iterdir()]
    flexfit.load_scene(str(examples / "contact_remeshed.toml"), remesh_cache=str(tmp_path / "alone"))
    assert names == [f.name for f in (tmp_path / "alone").iterdir()] and len(names) == 1
    subprocess.run([flexfit_exe, "sweep", str(sweep), "--out", str(tmp_path / "cmd"), "--no-progress", "--remesh-cache", "cmd_cache"],
                   check=True, capture_output=True)
    assert [f.name for f in (tmp_path / "cmd_cache").iterdir()] == names
    assert (tmp_path / "cmd" / "results.csv").read_bytes() == (tmp_path / "out" / "results.csv").read_bytes()
    defects = pathlib.Path(__file__).resolve().parents[1] / "apps" / "data" / "defects_sweep.toml"
    repaired = flexfit.load_sweep(str(defects), remesh_cache="")
    # Each repair once (the runs share the base scene's part), as loading the scene alone says them.
    assert len(repaired) == 2 and repaired.warnings == flexfit.load_scene(str(defects.parent / "defects_scene.toml")).warnings
    assert any("1 duplicate face" in w for w in repaired.warnings)
    with pytest.raises(flexfit.InputError, match=r"defects.tri:13: face 4"):
        flexfit.load_sweep(str(defects), strict=True)
    with pytest.raises(flexfit.InputError, match=r"defects.tri:13: face 4"):
        flexfit.sweep(defects, tmp_path / "strict", workers=1, strict=True)
