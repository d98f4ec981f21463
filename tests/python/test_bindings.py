"""The bindings against the C++ library: every binding used at least once, NumPy views alias
the C++ state, errors carry file and line, step() releases the GIL."""

import gc
import threading
import time

import numpy as np
import pytest

import flexfit
from conftest import ROOT


def ball_on_torus():
    world = flexfit.World(time_step=1e-3, gravity=[0, -9.81, 0])
    mouth = flexfit.PartModel(flexfit.torus(10, 2.5, 32, 12), material="elastic")
    ball = flexfit.PartModel(flexfit.sphere(8.5, 2))
    m = world.add(mouth, mode="rigid-deformable", motion="static", contact_level=3)
    b = world.add(ball, mode="rigid", motion="dynamic", position=[0, 4.7, 0], density=0.01)
    return world, m, b


def test_meshes_from_arrays_files_and_generators(tmp_path):
    mesh = flexfit.Mesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]]), np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]), "tet")
    assert mesh.vertices.shape == (4, 3) and mesh.faces.shape == (4, 3) and mesh.name == "tet"
    flexfit.write_mesh(mesh, str(tmp_path / "tet.obj"))
    back, warnings = flexfit.read_mesh(str(tmp_path / "tet.obj"))
    assert back.faces.shape == (4, 3) and warnings == []
    np.testing.assert_allclose(np.sort(back.vertices, axis=0), np.sort(mesh.vertices, axis=0))
    for m, vertices in [(flexfit.box([1, 2, 3], 2), 26), (flexfit.heart(), 7349), (flexfit.container_mouth(), 64 * 24)]:
        assert m.vertices.shape == (vertices, 3)
    remeshed, quality = flexfit.remesh(flexfit.torus(10, 2.5, 64, 24), 1.5)
    assert quality["min_angle_degrees"] > 20 and quality["hausdorff_share"] < 0.01
    assert "Mesh" in repr(remeshed)
    # A box whose edge at x = y = 1 is chamfered 0.028 wide (the CLI tests' file): the chamfer's
    # sharp edges are closer than half of a 0.25 edge, kept as asked (slivers between them) or rounded.
    chamfered, _ = flexfit.read_mesh(ROOT / "tests" / "apps" / "data" / "chamfered_box.obj")
    _, kept = flexfit.remesh(chamfered, 0.25, thin_features="keep")
    _, rounded = flexfit.remesh(chamfered, 0.25, thin_features="round")
    assert kept["slivers"] > 0.01 and not kept["thin_features_rounded"]
    assert rounded["slivers"] == 0 and rounded["thin_features_rounded"] and rounded["hausdorff_share"] < 0.01
    with pytest.raises(flexfit.InputError, match="unknown value 'never'"):
        flexfit.remesh(chamfered, 0.25, thin_features="never")
    with pytest.raises(flexfit.InputError):
        flexfit.Mesh(np.zeros((3, 3)), np.array([[0, 1, 5]]))


def test_part_alone_views_alias_the_state():
    model = flexfit.PartModel(flexfit.torus(2, 0.5, 12, 8), springs=(0.1, 0.01), vertex_mass=1.0)
    assert model.mass_count == 96 and model.spring_count == 288
    np.testing.assert_array_equal(model.rest_positions, model.mesh.vertices)
    part = flexfit.Part(model, mode="rigid-deformable")
    positions = part.positions
    assert not positions.flags.writeable and positions.flags.c_contiguous is True
    with pytest.raises(ValueError):
        positions[0, 0] = 1.0
    address = positions.__array_interface__["data"][0]
    before = positions[5].copy()
    zone = part.open_zone(5, 2)
    part.apply_force(5, [0, 0.5, 0])
    part.kick_mass(6, [0, 0.1, 0])
    for _ in range(10):
        part.step()
    # The same memory, now holding the moved mass: a view, not a copy.
    assert part.positions.__array_interface__["data"][0] == address
    assert positions[5, 1] > before[1]
    assert zone >= 0 and part.zone_count == 1 and part.time == pytest.approx(0.01)
    depths = part.zone_depths
    assert depths[5] == 0 and depths.max() >= 1 and (depths >= 0).sum() == len(part.moving_masses)
    assert set(part.moving_masses) == set(np.nonzero(depths >= 0)[0])
    assert np.abs(part.velocities).max() > 0
    np.testing.assert_allclose(part.world_positions(), part.positions)  # identity pose
    assert part.mode == "rigid-deformable" and part.model.mass_count == 96
    assert isinstance(part.state_hash(), int) and part.pose["rotation_wxyz"][0] == 1


def test_a_worlds_part_is_read_only_and_moving_masses_a_copy():
    world, m, _ = ball_on_torus()
    view = world.part(m)
    assert type(view).__name__ == "PartView"
    for change in ("apply_force", "kick_mass", "open_zone", "step"):
        assert not hasattr(view, change)  # through the World only
    world.open_zone(m, 0, 1)
    masses = view.moving_masses
    before = masses.copy()
    world.open_zone(m, 200, 6)  # the region's own list grows (and may move in memory)
    np.testing.assert_array_equal(masses, before)  # a copy: unaffected
    assert len(view.moving_masses) > len(before)


def test_keyword_of_the_wrong_type_names_the_key():
    with pytest.raises(flexfit.InputError, match="contact_level"):
        flexfit.World().add(flexfit.PartModel(flexfit.sphere(1, 1)), contact_level="three")


def test_reserved_zones_are_a_part_keyword_checked_like_the_others():
    world = flexfit.World()
    world.add(flexfit.PartModel(flexfit.sphere(1, 1)), mode="rigid-deformable", reserved_zones=8)
    with pytest.raises(flexfit.InputError, match="reserved zones must be in"):
        flexfit.World().add(flexfit.PartModel(flexfit.sphere(1, 1)), reserved_zones=70000)


def test_views_keep_their_owner_alive():
    world, m, _ = ball_on_torus()
    positions = world.part(m).positions
    expected = positions.copy()
    del world
    gc.collect()
    np.testing.assert_array_equal(positions, expected)  # the world lives while its view does


def test_world_contacts_grab_coupling_and_events(tmp_path):
    world, m, b = ball_on_torus()
    assert world.body_count == 2
    for _ in range(250):  # a force lasts one step
        world.apply_force(b, [0, -2500, 0])
        world.step()
    assert world.step_count == 250 and world.time == pytest.approx(0.25)
    contacts = world.contacts()
    assert contacts and {"point", "normal", "depth", "mass_b"} <= set(contacts[0])
    assert world.part(m).zone_count > 0
    world.grab(b, frequency=10.0)
    world.set_grab_target([0, 8, 0])
    world.step(50)
    coupling = world.coupling()
    assert coupling["active"] and coupling["body"] == b and np.linalg.norm(coupling["force"]) > 0
    world.release()
    world.set_velocity(b, [0, 0, 0])
    world.apply_mass_force(m, 3, [0, 1, 0])
    world.kick_mass(m, 4, [0, 0.1, 0])
    assert world.open_zone(m, 7, 1) >= 0
    world.step()
    profile = world.profile()
    assert set(profile["last_seconds"]) >= {"narrow_phase", "zone_dynamics"} and profile["steps"] == 301
    assert world.pose(b)["position"].shape == (3,) and world.centre_of_mass(b).shape == (3,)
    assert world.assembly_events() == []
    assert isinstance(world.state_hash(), int)
    world.write_vtk(str(tmp_path / "w.vtp"), ["mouth", "ball"])
    world.write_glb(str(tmp_path / "w.glb"))
    assert (tmp_path / "w.vtp").stat().st_size > 0 and (tmp_path / "w.glb").stat().st_size > 0
    with pytest.raises(flexfit.InputError):
        world.write_vtk(str(tmp_path / "x.vtp"), ["only one name"])


def test_scene_errors_carry_file_and_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[world]\ntime_step = 0.001\n\n[[part]]\nname = "p"\ngenerator = "torus1"\nmodee = "rigid"\n')
    with pytest.raises(flexfit.InputError) as error:
        flexfit.load_scene(str(bad))
    assert error.value.source == str(bad) and error.value.line == 7 and "modee" in error.value.problem
    assert str(bad) in str(error.value) and ":7:" in str(error.value)
    assert isinstance(error.value, ValueError)
    with pytest.raises(flexfit.InputError):
        flexfit.World(time_step=-1.0)
    with pytest.raises(flexfit.InputError):
        flexfit.World().add(flexfit.PartModel(flexfit.sphere(1, 1)), mode="bendy")


def test_a_mesh_built_in_python_is_validated_by_its_model():
    faces = np.array([[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]])
    corner = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    nan_vertex = corner.copy()
    nan_vertex[3, 2] = np.nan
    with pytest.raises(flexfit.InputError, match="vertex 3 has a NaN") as error:
        flexfit.PartModel(flexfit.Mesh(nan_vertex, faces, "tet"), material="elastic")
    assert error.value.source == "tet"
    with pytest.raises(flexfit.InputError, match="magnitude 1e\\+30"):
        flexfit.PartModel(flexfit.Mesh(corner * 1e30, faces, "tet"), material="elastic")
    with pytest.raises(flexfit.InputError, match="beyond the 1e\\+20 units"):
        flexfit.PartModel(flexfit.sphere(1e30, 2), material="elastic")
    assert flexfit.PartModel(flexfit.Mesh(corner, faces, "tet"), material="elastic").mass_count == 4


def test_prepare_changes_no_result():
    hashes = []
    for prepared in (False, True):
        world, m, b = ball_on_torus()
        if prepared:
            world.prepare()
            assert world.step_count == 0 and world.contacts() == []
        for _ in range(250):
            world.apply_force(b, [0, -2500, 0])
            world.step()
        assert world.contacts()
        hashes.append(world.state_hash())
    assert hashes[0] == hashes[1]


def test_divergence_is_an_exception():
    world = flexfit.World()
    torus = world.add(flexfit.PartModel(flexfit.torus(10, 2.5, 24, 24)), mode="rigid-deformable")
    with pytest.raises(flexfit.DivergenceError) as error:
        for _ in range(10):
            world.apply_mass_force(torus, 100, [0, 1e300, 0])
            world.step()
    assert error.value.body == torus and error.value.time >= 0
    assert "diverged" in str(error.value) and error.value.problem


def test_step_releases_the_gil(examples):
    runs = [flexfit.SceneRun(flexfit.load_scene(str(examples / "ball_torus.toml"))) for _ in range(2)]
    # While one thread is inside step(), this thread keeps running Python: with the GIL held it
    # would be blocked for the whole call and count next to nothing.
    worker = threading.Thread(target=runs[0].step, args=(300,))
    worker.start()
    count = 0
    while worker.is_alive():
        count += 1
    worker.join()
    assert count > 200, count
    # Two threads stepping two worlds at once give the same run as one alone.
    threads = [threading.Thread(target=r.step, args=(150,)) for r in runs]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    alone = flexfit.SceneRun(flexfit.load_scene(str(examples / "ball_torus.toml")))
    alone.step(450)
    assert runs[0].world.state_hash() == alone.world.state_hash()
    assert runs[1].world.step_count == 150


def longest_pause(call):
    """This thread's longest pause between two loop turns while another thread runs `call`, and
    the whole time: a call holding the GIL pauses this thread for about all of it."""
    done = threading.Event()
    worker = threading.Thread(target=lambda: (call(), done.set()))
    start = last = time.perf_counter()
    longest = 0.0
    worker.start()
    while not done.is_set():
        now = time.perf_counter()
        longest, last = max(longest, now - last), now
    worker.join()
    return longest, time.perf_counter() - start


def test_remeshing_loading_and_building_models_release_the_gil(examples):
    torus = flexfit.torus(10, 2.5, 64, 24)
    # The remeshed-mouth scene remeshes its part while loading, and run_scene loads it too.
    scene = str(examples / "ball_torus_remeshed.toml")
    large = flexfit.torus(10, 2.5, 400, 200)
    haptic = flexfit.load_scene(str(examples / "ball_torus_haptic.toml"))  # a world building the ball's distance field
    for name, call in [("remesh", lambda: flexfit.remesh(torus, 0.4)), ("load_scene", lambda: flexfit.load_scene(scene)),
                       ("run_scene", lambda: flexfit.run_scene(scene, duration=0.001)),
                       ("PartModel", lambda: flexfit.PartModel(large, material="elastic", vertex_order="locality")),
                       ("SceneRun", lambda: flexfit.SceneRun(haptic))]:
        longest, whole = longest_pause(call)
        assert whole > 0.05 and longest < 0.25 * whole, (name, longest, whole)


def described(obj):
    """A docstring beyond pybind11's generated signature."""
    doc = getattr(obj, "__doc__", None) or ""
    lines = [line for line in doc.splitlines() if line.strip()]
    if isinstance(obj, (property, type)):
        return bool(lines)
    return len(lines) >= 2 or (len(lines) == 1 and "(" not in lines[0])


def test_load_scene_keeps_remeshed_surfaces_in_the_remesh_cache(tmp_path, examples):
    # The first load remeshes and writes one file; the second reads it (the file is not written
    # again: same inode) and builds the same world; "" turns the cache off.
    scene = str(examples / "contact_remeshed.toml")
    cache = tmp_path / "cache"
    first = flexfit.load_scene(scene, remesh_cache=str(cache))
    files = list(cache.iterdir())
    assert len(files) == 1 and files[0].suffix == ".remesh"
    inode = files[0].stat().st_ino
    second = flexfit.load_scene(scene, remesh_cache=cache)
    assert files[0].stat().st_ino == inode
    off = flexfit.load_scene(scene, remesh_cache="")
    hashes = {flexfit.SceneRun(s).world.state_hash() for s in (first, second, off)}
    assert len(hashes) == 1
    assert first.warnings == second.warnings == off.warnings == []
    # run_scene takes the same keyword.
    other = tmp_path / "other"
    flexfit.run_scene(scene, duration=0.01, remesh_cache=str(other))
    assert [f.name for f in other.iterdir()] == [files[0].name]


def test_every_binding_has_a_docstring():
    missing = []
    for name in dir(flexfit._flexfit):
        if name.startswith("_"):
            continue
        obj = getattr(flexfit._flexfit, name)
        if not described(obj):
            missing.append(name)
        if isinstance(obj, type):
            for member, value in vars(obj).items():
                if member.startswith("_") and member != "__len__":
                    continue
                if (callable(value) or isinstance(value, property)) and not described(value):
                    missing.append(f"{name}.{member}")
    assert missing == []


def test_sweep_bindings(tmp_path, examples):
    path = tmp_path / "sweep.toml"
    path.write_text((examples / "sweeps" / "ball_torus_friction.toml").read_text().replace('"../ball_torus.toml"', f'"{examples / "ball_torus.toml"}"')
                    .replace("duration = 2.0", "duration = 0.02"))
    sweep = flexfit.load_sweep(str(path))
    assert len(sweep) == 12 and sweep.parameter_names == ["diameter", "rim", "friction"]
    assert sweep.labels(0) == ["14", "rigid", "0"] and len(set(sweep.run_ids)) == 12
    assert sweep.file.name == "sweep.toml" and sweep.scene.name == "ball_torus.toml"
    scene = sweep.scene_of(11)
    assert scene.part_names == ["mouth", "ball"] and scene.duration == 0.02 and scene.time_step == 0.001 and scene.warnings == []
    assert "run " + sweep.run_ids[11] in scene.source
    out = tmp_path / "out"
    assert flexfit.missing_sweep_runs(sweep, str(out)) == list(range(12))
    assert flexfit.run_sweep_run(sweep, 3, str(out)) is True
    assert flexfit.run_sweep_run(sweep, 3, str(out)) is False  # already done
    with pytest.raises(flexfit.InputError):
        flexfit.write_sweep_table(sweep, str(out))  # runs missing
    ran = flexfit.run_sweep_threads(sweep, str(out), 2)
    assert ran == [r for r in range(12) if r != 3]
    table = flexfit.write_sweep_table(sweep, str(out))
    assert table.read_text().count("\n") == 13
    series = flexfit.VtkSeries(str(tmp_path / "vtk"), "ball")
    (tmp_path / "vtk").mkdir()
    run = flexfit.SceneRun(scene)
    run.step(10)
    assert not run.finished()
    first = series.write(run.world, ["mouth", "ball"])
    assert first.name == "ball_000000.vtp" and series.collection.name == "ball.pvd"


PUSHED_BALL = """
[world]
time_step = 0.001
gravity = [0, -9.81, 0]
duration = 0.6

[[part]]
name = "mouth"
generator = "container-mouth"
mode = "rigid-deformable"
material = "elastic"
restoration = "anchors"
anchor_stiffness = 10.0
anchor_damping = 6.0
global_damping = 1.0
contact_level = 3
static_friction = 0.4
kinetic_friction = 0.3

[[part]]
name = "ball"
generator = { type = "sphere", radius = 8.5, level = 2 }
mode = "rigid"
motion = "dynamic"
density = 0.01
position = [0, 4.7, 0]
static_friction = 0.4

[[action]]
time = 0.0
type = "push"
part = "ball"
force = [0, -2500, 0]
duration = 0.5
"""


def test_keyword_settings_build_the_world_a_scene_file_builds(tmp_path):
    """The keywords are the scene file's keys: the same world from both, the same run bit for bit."""
    path = tmp_path / "pushed.toml"
    path.write_text(PUSHED_BALL)
    scene_run = flexfit.SceneRun(flexfit.load_scene(str(path)))
    scene_run.step(600)

    world = flexfit.World(time_step=0.001, gravity=[0, -9.81, 0])
    mouth = flexfit.PartModel(flexfit.container_mouth(), material="elastic")
    ball = flexfit.PartModel(flexfit.sphere(8.5, 2))
    world.add(mouth, mode="rigid-deformable", restoration="anchors", anchor_stiffness=10.0, anchor_damping=6.0, global_damping=1.0,
              contact_level=3, static_friction=0.4, kinetic_friction=0.3)
    b = world.add(ball, position=[0, 4.7, 0], mode="rigid", motion="dynamic", density=0.01, static_friction=0.4)
    for step in range(600):
        if step < 500:
            world.apply_force(b, [0, -2500, 0])
        world.step()
    assert world.state_hash() == scene_run.world.state_hash()
    assert world.part(0).zone_count > 0  # the rim still restores at 0.6 s

    with pytest.raises(flexfit.InputError, match="anchor_stifness"):
        world.add(ball, anchor_stifness=1.0)
    with pytest.raises(flexfit.InputError):
        world.add(ball, restoration="elastic-band")
    with pytest.raises(flexfit.InputError):
        world.add(ball, motion="dynamic", static_friction=0.1, kinetic_friction=0.5)  # kinetic above static


def test_physical_material_and_a_part_alone_with_its_own_settings():
    mesh = flexfit.torus(0.05, 0.01, 24, 12)
    plain = flexfit.PartModel(mesh, youngs_modulus=2e9, thickness=0.001, density=1200)
    bent = flexfit.PartModel(mesh, youngs_modulus=2e9, thickness=0.001, density=1200, bending_springs=True)
    assert plain.spring_count == 3 * 24 * 12 and bent.spring_count == 2 * plain.spring_count
    with pytest.raises(flexfit.InputError, match="thickness and density"):
        flexfit.PartModel(mesh, youngs_modulus=2e9)
    with pytest.raises(flexfit.InputError, match="one of"):
        flexfit.PartModel(mesh, material="elastic", youngs_modulus=2e9, thickness=0.001, density=1200)
    part = flexfit.Part(bent, integrator="implicit", implicit_iterations=30, time_step=1e-3, restoration="constraint", constraint_rate=20.0)
    part.open_zone(0, 3)
    part.apply_force(0, [0, 0.5, 0])
    for _ in range(20):
        part.step()
    assert np.isfinite(part.positions).all() and part.positions[0, 1] > bent.rest_positions[0, 1]
    with pytest.raises(flexfit.InputError):
        flexfit.Part(bent, density=1.0)  # a body's key: not for a part alone


SNAPPED_BALL = PUSHED_BALL.replace("duration = 0.6", "duration = 0.3") + """
[[assembly]]
name = "ball into the container"
primary = "ball"
secondary = "mouth"
technique = "zone"
primary_vector = { origin = [0, -8.5, 0], end = [0, 8.5, 0] }
area = { shape = "cylinder", position = [0, 0, 0], radius = 7.5, half_height = 14 }
final_position = [0, -12, 0]
snap_duration = 0.1
"""


def pushed_ball_world():
    world = flexfit.World(time_step=0.001, gravity=[0, -9.81, 0])
    mouth = flexfit.PartModel(flexfit.container_mouth(), material="elastic")
    ball = flexfit.PartModel(flexfit.sphere(8.5, 2))
    m = world.add(mouth, mode="rigid-deformable", restoration="anchors", anchor_stiffness=10.0, anchor_damping=6.0, global_damping=1.0,
                  contact_level=3, static_friction=0.4, kinetic_friction=0.3)
    b = world.add(ball, position=[0, 4.7, 0], mode="rigid", motion="dynamic", density=0.01, static_friction=0.4)
    return world, m, b


def test_assembly_keywords_are_the_scene_files_keys(tmp_path):
    """A rule from keywords snaps as the same rule read from a scene file: the same event, the same run bit for bit."""
    path = tmp_path / "snapped.toml"
    path.write_text(SNAPPED_BALL)
    scene_run = flexfit.SceneRun(flexfit.load_scene(str(path)))
    scene_run.step(300)
    assert scene_run.world.assembly_events(), "the ball starts inside the area: the rule snaps"

    world, m, b = pushed_ball_world()
    rule = world.add_assembly(b, m, name="ball into the container", technique="zone",
                              primary_vector={"origin": [0, -8.5, 0], "end": [0, 8.5, 0]},
                              area={"shape": "cylinder", "position": np.array([0.0, 0.0, 0.0]), "radius": 7.5, "half_height": 14},
                              final_position=(0, -12, 0), snap_duration=0.1)
    assert rule == 0 and world.assembly_count == 1 and not world.assembled(rule)
    for step in range(300):
        world.apply_force(b, [0, -2500, 0])
        world.step()
    assert world.assembled(rule)
    assert [e["time"] for e in world.assembly_events()] == [e["time"] for e in scene_run.world.assembly_events()]
    assert world.state_hash() == scene_run.world.state_hash()
    np.testing.assert_array_equal(world.pose(b)["position"], [0, -12, 0])

    # NumPy scalars and arrays are the values they hold; other objects are refused naming the key.
    world.add_assembly(b, m, technique="proximity", snap_duration=np.float32(0.25), distance_tolerance=np.int64(2),
                       final_position=np.zeros(3, np.float32), primary_vector={"origin": list(np.zeros(3)), "end": [0, 1, 0]})
    assert world.assembly_count == 2
    with pytest.raises(flexfit.InputError, match="out of range"):
        world.add_assembly(b, m, distance_tolerance=2**70)
    with pytest.raises(flexfit.InputError, match="area.radius") as error:
        world.add_assembly(b, m, area={"shape": "sphere", "radius": object()})
    assert error.value.source == "add_assembly"
    with pytest.raises(flexfit.InputError, match="snap_duraton"):
        world.add_assembly(b, m, snap_duraton=0.1)  # unknown keys are refused as in scene files
    with pytest.raises(flexfit.InputError, match="radius"):
        world.add_assembly(b, m, area={"shape": "sphere", "radius": -1})
    with pytest.raises(flexfit.InputError, match="no body 9"):
        world.add_assembly(b, 9)
    with pytest.raises(flexfit.InputError, match="technique"):
        world.add_assembly(b, m, technique="glue")
    with pytest.raises(flexfit.InputError):
        world.assembled(5)
    assert world.assembly_count == 2  # nothing half-added


def test_forces_at_points_faces_and_kinematic_targets():
    world = flexfit.World(time_step=0.01, gravity=[0, 0, 0])
    box = flexfit.PartModel(flexfit.box([1, 1, 1], 1))
    b = world.add(box, mode="rigid", motion="dynamic", density=1.0)
    mass = 8.0  # a 2 x 2 x 2 box of density 1
    centre = world.centre_of_mass(b)
    # A force at a point off the centre: the body's momentum changes by F h, its angular
    # momentum by (r x F) h (the analytic impulse; the box's inertia is diagonal, (m/6) a^2).
    force, arm = np.array([0.0, 6.0, 0.0]), np.array([1.0, 0.0, 0.0])
    world.apply_force_at(b, force, centre + arm)
    world.step()
    velocity = (world.centre_of_mass(b) - centre) / 0.01
    np.testing.assert_allclose(velocity, force / mass * 0.01, rtol=1e-9, atol=1e-12)
    inertia = mass * (2.0**2 + 2.0**2) / 12.0
    spin = np.cross(arm, force) * 0.01 / inertia  # rad/s, about z
    angle = np.linalg.norm(spin) * 0.01
    np.testing.assert_allclose(world.pose(b)["rotation_wxyz"], [np.cos(angle / 2), 0, 0, np.sin(angle / 2)], atol=1e-9)

    # A face force is the same as a third of it on each of the face's three masses.
    def mouth_with(load):
        w = flexfit.World(time_step=1e-3, gravity=[0, 0, 0])
        mouth = flexfit.PartModel(flexfit.container_mouth(), material="elastic")
        m = w.add(mouth, mode="full-deformable")
        load(w, m, mouth)
        w.step(20)
        return w.state_hash()
    f = np.array([0.3, -0.9, 0.6])
    face = 17
    by_face = mouth_with(lambda w, m, model: w.apply_face_force(m, face, f))
    by_masses = mouth_with(lambda w, m, model: [w.apply_mass_force(m, int(v), f / 3.0) for v in model.mesh.faces[face]])
    assert by_face == by_masses
    with pytest.raises(flexfit.InputError, match="face"):
        world.apply_face_force(b, 10**6, f)

    # A kinematic body reaches its target by the end of the next step.
    k = world.add(box, mode="rigid", motion="kinematic", position=[5, 0, 0])
    world.set_kinematic_target(k, [5, 1, 0], [np.cos(0.1), 0, np.sin(0.1), 0])
    world.step()
    np.testing.assert_allclose(world.pose(k)["position"], [5, 1, 0], atol=1e-12)
    np.testing.assert_allclose(world.pose(k)["rotation_wxyz"], [np.cos(0.1), 0, np.sin(0.1), 0], atol=1e-12)
    with pytest.raises(flexfit.InputError):
        world.set_kinematic_target(k, [np.nan, 0, 0])


def test_grab_with_explicit_coupling_stiffness():
    """Stiffness and damping as the scene's grab action takes them: the coupling force is k (target - position) at rest."""
    world = flexfit.World(time_step=1e-3, gravity=[0, 0, 0])
    ball = flexfit.PartModel(flexfit.sphere(1.0, 2))
    b = world.add(ball, mode="rigid", motion="dynamic", density=1.0)
    world.grab(b, stiffness=200.0, damping=0.0, angular_stiffness=5.0, angular_damping=0.0)
    world.set_grab_target([0.01, 0, 0])
    world.step()
    coupling = world.coupling()
    np.testing.assert_allclose(coupling["force"], [200.0 * 0.01, 0, 0], rtol=1e-6)
    world.release()
    with pytest.raises(flexfit.InputError):
        world.grab(b, stiffness=1e12, damping=0.0)  # a coupling the time step cannot integrate


def test_a_model_renumbered_for_locality_speaks_the_meshs_own_vertex_order():
    torus = flexfit.torus(3, 1, 24, 16)
    shuffle = np.random.default_rng(4).permutation(len(torus.vertices))  # vertex v goes to row shuffle[v]
    vertices = np.empty_like(torus.vertices)
    vertices[shuffle] = torus.vertices
    mesh = flexfit.Mesh(vertices, shuffle[torus.faces], "shuffled")
    local = flexfit.PartModel(mesh, springs=(0.1, 0.01), vertex_order="locality")
    given = flexfit.PartModel(mesh, springs=(0.1, 0.01))
    assert local.renumbered and not given.renumbered
    assert sorted(local.mass_of_vertex) == list(range(len(vertices))) and list(given.mass_of_vertex) == list(range(len(vertices)))
    np.testing.assert_array_equal(local.mesh.vertices, vertices)
    np.testing.assert_array_equal(local.mesh.faces, mesh.faces)
    np.testing.assert_array_equal(local.rest_positions, vertices)
    runs = []
    for model in (local, given):
        part = flexfit.Part(model, mode="rigid-deformable", restoration="none", global_damping=0.5)
        part.open_zone(40, 1)
        for _ in range(30):
            part.apply_force(7, [0, 0.3, 0.1])
            part.step()
        part.kick_mass(9, [0.2, 0, 0])
        part.step()
        runs.append(part)
    a, b = runs
    np.testing.assert_allclose(a.positions, b.positions, rtol=0, atol=1e-12)
    np.testing.assert_allclose(a.velocities, b.velocities, rtol=0, atol=1e-12)
    np.testing.assert_allclose(a.world_positions(), b.world_positions(), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.zone_depths, b.zone_depths)
    assert set(a.moving_masses) == set(b.moving_masses) and 7 in set(a.moving_masses)
    assert np.linalg.norm(b.positions[7] - vertices[7]) > 1e-5  # the load moved vertex 7
    with pytest.raises(flexfit.InputError, match="vertex_order"):
        flexfit.PartModel(mesh, vertex_order="sorted")


def test_a_worlds_mass_calls_name_the_meshs_vertices_when_renumbered():
    torus = flexfit.torus(3, 1, 24, 16)
    shuffle = np.random.default_rng(6).permutation(len(torus.vertices))
    vertices = np.empty_like(torus.vertices)
    vertices[shuffle] = torus.vertices
    mesh = flexfit.Mesh(vertices, shuffle[torus.faces], "shuffled")
    parts = []
    for order in ("locality", "as_given"):
        world = flexfit.World(time_step=1e-3, gravity=[0, 0, 0])
        model = flexfit.PartModel(mesh, springs=(0.1, 0.01), vertex_order=order)
        body = world.add(model, mode="rigid-deformable", motion="static", restoration="none")
        world.open_zone(body, 40, 1)
        for _ in range(20):
            world.apply_mass_force(body, 7, [0, 0.3, 0.1])
            world.step()
        world.kick_mass(body, 9, [0.2, 0, 0])
        world.step()
        parts.append((world, world.part(body)))
    (wa, a), (wb, b) = parts
    assert a.model.renumbered and not b.model.renumbered
    np.testing.assert_allclose(a.positions, b.positions, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.zone_depths, b.zone_depths)
    assert a.zone_depths[7] == 0 and a.zone_depths[9] >= 0  # zones at the loaded and kicked file vertices


def test_a_model_built_with_the_files_vertices_speaks_the_files_indices(tmp_path):
    # An icosphere written as OBJ with a stray vertex (no face uses it) as vertex 3 and face 5's
    # first corner written again at the end: the read removes and welds them. With the file's
    # numbering, every per-vertex row and index is the file's; against the clean mesh's run, row
    # for row at the shifted indices, bit for bit (the repaired mesh is the clean one).
    sphere = flexfit.sphere(1.0, 2)
    vertices = np.insert(np.asarray(sphere.vertices), 3, [5.0, 5.0, 5.0], axis=0)
    faces = np.asarray(sphere.faces).astype(np.int64)
    faces = faces + (faces >= 3)
    repeated = int(faces[5, 0])
    vertices = np.vstack([vertices, vertices[repeated]])
    faces[5, 0] = len(vertices) - 1
    path = tmp_path / "damaged.obj"
    path.write_text("".join("v %.17g %.17g %.17g\n" % tuple(v) for v in vertices) + "".join("f %d %d %d\n" % tuple(f + 1) for f in faces))
    mesh, warnings, numbering = flexfit.read_mesh(path, file_vertices=True)
    assert len(mesh.vertices) == len(sphere.vertices) and any("used by no face" in w for w in warnings)
    assert numbering.count == len(vertices)
    expected = list(range(len(sphere.vertices)))
    mesh_vertex = list(numbering.mesh_vertex)
    assert mesh_vertex[3] == -1 and mesh_vertex[-1] == mesh_vertex[repeated]
    assert [mesh_vertex[c + (c >= 3)] for c in expected] == expected
    np.testing.assert_array_equal(numbering.positions, vertices)
    assert flexfit.read_mesh(path)[0].vertices.shape == mesh.vertices.shape  # the two-element form is unchanged

    numbered = flexfit.PartModel(mesh, springs=(0.1, 0.01), vertex_order="locality", file_vertices=numbering)
    clean = flexfit.PartModel(sphere, springs=(0.1, 0.01), vertex_order="locality")
    assert numbered.vertex_count == len(vertices) and numbered.mass_count == len(sphere.vertices)
    assert numbered.mass_of_vertex[3] == -1
    np.testing.assert_array_equal(numbered.rest_positions, vertices)
    parts = []
    for model, at in ((numbered, lambda c: c + (c >= 3)), (clean, lambda c: c)):
        part = flexfit.Part(model, mode="rigid-deformable", restoration="none", global_damping=0.5)
        for _ in range(20):
            part.apply_force(at(7), [0, 0.3, 0.1])
            part.step()
        part.kick_mass(at(40), [0.2, 0, 0])
        part.step()
        parts.append(part)
    a, b = parts
    rows = [c + (c >= 3) for c in expected]
    np.testing.assert_array_equal(a.positions[rows], b.positions)
    np.testing.assert_array_equal(a.positions[3], vertices[3])  # the stray vertex stays where the file has it
    np.testing.assert_array_equal(a.velocities[3], [0, 0, 0])
    np.testing.assert_array_equal(a.positions[-1], a.positions[repeated])
    assert a.zone_depths[3] == -1 and a.zone_depths[7 + 1] == 0
    with pytest.raises(flexfit.InputError, match="removed by the repair"):
        a.apply_force(3, [1, 0, 0])


def test_the_default_per_step_restoration_at_another_time_step_is_a_warning():
    # As scene files and `flexfit simulate --dt` say it: the default fraction was chosen for 1 ms.
    import warnings

    model = flexfit.PartModel(flexfit.torus(10, 2.5, 12, 8))
    with pytest.warns(UserWarning, match=r"default fraction 0.001 is per step, chosen for 1 ms steps: at time_step 0.0002 the part "
                                         r"restores 5 times as fast and resists loads about 25 times as stiffly; constraint_rate=0.5"):
        flexfit.World(time_step=2e-4).add(model, mode="rigid-deformable")
    with pytest.warns(UserWarning, match=r"at time_step 0.002 the part restores 0.5 times as fast"):
        flexfit.Part(model, time_step=2e-3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        world = flexfit.World(time_step=2e-4)
        world.add(model, constraint_rate=0.5)
        world.add(model, constraint_fraction=0.001)
        world.add(model, restoration="anchors")
        world.add(model, mode="rigid")
        flexfit.World().add(model)
        flexfit.Part(model)
        with pytest.raises(flexfit.InputError):
            flexfit.Part(model, time_step=0.0)  # refused, with no warning first
