// Sweep files (src/io/sweep.cpp): the product of the parameters, each run's scene, stable ids,
// and errors that name the sweep file and line.
#include "flexfit/scene_file.hpp"
#include "flexfit/sweep.hpp"
#include "temp_dir.hpp"

#include <gtest/gtest.h>

#include <set>

namespace flexfit {
namespace {

using testing::TempDir;

constexpr const char* kScene = R"(
[world]
time_step = 0.001
duration = 1.0

[[part]]
name = "mouth"
generator = { type = "torus", major = 10, minor = 2.5, u = 12, v = 8 }
mode = "rigid-deformable"
static_friction = 0.1

[[part]]
name = "ball"
generator = { type = "sphere", radius = 3, level = 1 }
motion = "dynamic"
position = [0, 6, 0]

[[action]]
time = 0.0
type = "push"
part = "ball"
force = [0, -10, 0]
duration = 0.5
)";

std::string sweepText(const std::string& parameters) { return "scene = \"scene.toml\"\nduration = 0.25\n" + parameters; }

Sweep load(TempDir& dir, const std::string& parameters) {
    dir.write("scene.toml", kScene);
    return loadSweep(dir.write("sweep.toml", sweepText(parameters)));
}

TEST(Sweep, RunsAreTheProductFirstParameterSlowest) {
    TempDir dir;
    const Sweep s = load(dir, R"(
[[parameter]]
name = "radius"
key = "part.ball.generator.radius"
values = [2.0, 3.0]
[[parameter]]
name = "push"
key = "action.0.force.1"
range = { start = -10, stop = -30, count = 3 }
)");
    ASSERT_EQ(s.runs.size(), 6u);
    EXPECT_EQ(s.labels(0), (std::vector<std::string>{"2.0", "-10.0"}));
    EXPECT_EQ(s.labels(1), (std::vector<std::string>{"2.0", "-20.0"}));
    EXPECT_EQ(s.labels(5), (std::vector<std::string>{"3.0", "-30.0"}));
    std::set<std::string> ids;
    for (const SweepRun& r : s.runs) ids.insert(r.id);
    EXPECT_EQ(ids.size(), 6u);
    const Scene fifth = sweepScene(s, 4);  // radius 3, push -20 (an element of the force array)
    EXPECT_EQ(fifth.actions[0].force, Vec3(0, -20, 0));
}

TEST(Sweep, EachRunsSceneHoldsItsValuesAndTheRestOfTheBase) {
    TempDir dir;
    const Sweep s = load(dir, R"(
[[parameter]]
name = "friction"
key = ["part.ball.static_friction", "part.mouth.static_friction"]
values = [[0.0, 0.0], [0.5, 0.7]]
labels = ["none", "some"]
[[parameter]]
name = "mode"
key = "part.1.mode"
values = ["rigid", "full-deformable"]
)");
    ASSERT_EQ(s.runs.size(), 4u);
    const Scene base = loadScene(dir.path() / "scene.toml");
    const Scene last = sweepScene(s, 3);
    EXPECT_DOUBLE_EQ(last.parts[1].body.staticFriction, 0.5);
    EXPECT_DOUBLE_EQ(last.parts[0].body.staticFriction, 0.7);
    EXPECT_EQ(last.parts[1].part.mode, PartMode::FullDeformable);
    EXPECT_DOUBLE_EQ(last.duration, 0.25);  // the sweep's
    EXPECT_EQ(last.parts[0].part.mode, base.parts[0].part.mode);
    EXPECT_EQ(last.parts[1].pose.translation, base.parts[1].pose.translation);
    EXPECT_EQ(last.actions.size(), base.actions.size());
    const Scene first = sweepScene(s, 0);
    EXPECT_DOUBLE_EQ(first.parts[1].body.staticFriction, 0.0);
    EXPECT_EQ(first.parts[1].part.mode, PartMode::Rigid);
    EXPECT_EQ(s.labels(2), (std::vector<std::string>{"some", "rigid"}));
}

TEST(Sweep, IdsDependOnValuesNotOnPositions) {
    TempDir dir;
    const Sweep small = load(dir, "[[parameter]]\nname = \"r\"\nkey = \"part.ball.generator.radius\"\nvalues = [2.0, 3.0]\n");
    const Sweep large = load(dir, "[[parameter]]\nname = \"r\"\nkey = \"part.ball.generator.radius\"\nvalues = [1.5, 3.0, 2.0]\n");
    EXPECT_EQ(small.runs[0].id, large.runs[2].id);  // radius 2
    EXPECT_EQ(small.runs[1].id, large.runs[1].id);  // radius 3
    const Sweep renamed = load(dir, "[[parameter]]\nname = \"radius\"\nkey = \"part.ball.generator.radius\"\nvalues = [2.0, 3.0]\n");
    EXPECT_NE(small.runs[0].id, renamed.runs[0].id);
}

void expectError(const std::string& parameters, std::size_t line, const std::string& words) {
    TempDir dir;
    try {
        load(dir, parameters);
        FAIL() << "no error for: " << parameters;
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), line) << e.what();
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        EXPECT_NE(e.source().find("sweep.toml"), std::string::npos) << e.what();
    }
}

TEST(Sweep, ErrorsNameTheSweepFileAndLine) {
    // The sweep text starts with two lines (scene, duration): [[parameter]] is on line 3.
    expectError("[[parameter]]\nname = \"x\"\nkey = \"part.nobody.density\"\nvalues = [1.0]\n", 3, "no element 'nobody'");
    expectError("[[parameter]]\nname = \"x\"\nkey = \"world.nothing.deeper\"\nvalues = [1.0]\n", 3, "has no 'nothing'");
    expectError("[[parameter]]\nname = \"x\"\nkey = \"part.ball.density\"\nvalues = [-1.0]\n", 3, "density");
    expectError("[[parameter]]\nname = \"x\"\nkey = \"part.ball.densty\"\nvalues = [1.0]\n", 3, "densty");
    expectError("[[parameter]]\nname = \"x\"\nkey = \"part.ball.density\"\nvalues = [1.0, 1.0]\n", 3, "listed twice");
    expectError("[[parameter]]\nname = \"x\"\nkey = \"part.ball.density\"\nvalues = [1.0]\nlabels = [\"a\", \"b\"]\n", 7, "2 labels for 1 values");
    expectError("[[parameter]]\nname = \"x\"\nkey = \"part.ball.density\"\nrange = { start = 1, stop = 2, count = 0 }\n", 6, "count");
    expectError("[[parameter]]\nname = \"x\"\nkey = [\"part.ball.density\", \"part.mouth.density\"]\nvalues = [1.0]\n", 3, "one per key");
    expectError("[[parameter]]\nname = \"x\"\nkey = \"part.ball.density\"\n", 3, "either 'values'");
    expectError("[[parameter]]\nname = \"x\"\nkey = \"part.ball.density\"\nvalues = [1.0]\nstep = 2\n", 7, "unknown key 'step'");
    expectError("[[parameter]]\nname = \"x\"\nkey = \"part.ball.density\"\nvalues = [1.0]\n[[parameter]]\nname = \"x\"\nkey = \"world.duration\"\nvalues = [1.0]\n",
                7, "used twice");
    expectError("bogus = 1\n", 3, "unknown key 'bogus'");
}

TEST(Sweep, ARunOfNoStepOrOfTooManyIsRefusedWithTheSweepsDuration) {
    // The sweep's own duration (0.25 s) is the one its runs take: a time step of 1 s there runs
    // no step, and is refused at load naming the parameter; 1e-9 s (2.5e8 steps) is a run, though
    // the base scene's 1 s at that step would have been 1e9.
    const std::string timeSteps = "[[parameter]]\nname = \"h\"\nkey = \"world.time_step\"\nvalues = [";
    expectError(timeSteps + "0.001, 1.0]\n", 3, "shorter than half the time step 1 s");
    TempDir dir;
    EXPECT_NO_THROW(load(dir, timeSteps + "1e-9]\n"));
}

TEST(Sweep, SetGivesEveryRunTheSameValues) {
    TempDir dir;
    dir.write("scene.toml", kScene);
    const Sweep s = loadSweep(dir.write("sweep.toml", R"(scene = "scene.toml"
set = { "world.time_step" = 0.0005, "part.mouth.static_friction" = 0.3 }
[[parameter]]
name = "density"
key = "part.ball.density"
values = [1.0, 2.0]
)"));
    for (std::size_t r = 0; r < 2; ++r) {
        const Scene scene = sweepScene(s, r);
        EXPECT_EQ(scene.world.timeStep, 0.0005);
        EXPECT_EQ(scene.parts[0].body.staticFriction, 0.3);
        EXPECT_EQ(scene.parts[1].body.density, r == 0 ? 1.0 : 2.0);
    }
    try {
        loadSweep(dir.write("bad.toml", "scene = \"scene.toml\"\n\nset = { \"part.nobody.x\" = 1 }\n"));
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 3u) << e.what();
        EXPECT_NE(std::string(e.what()).find("set: no element 'nobody'"), std::string::npos) << e.what();
    }
}

TEST(Sweep, AnErrorInTheBaseSceneNamesItsOwnLine) {
    TempDir dir;
    std::string bad = kScene;
    bad.replace(bad.find("static_friction = 0.1"), 21, "static_friction = -0.1");  // line 10 of the base scene
    dir.write("scene.toml", bad);
    try {
        loadSweep(dir.write("sweep.toml", sweepText("[[parameter]]\nname = \"r\"\nkey = \"part.ball.density\"\nvalues = [1.0]\n")));
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(e.source().find("scene.toml"), std::string::npos) << e.what();
        EXPECT_EQ(e.line(), 10u) << e.what();
        EXPECT_NE(std::string(e.what()).find("sweep.toml"), std::string::npos) << e.what();  // and which sweep ran it
    }
}

TEST(Sweep, SetTakesTomlsOwnDottedKeysWithoutReplacingTables) {
    TempDir dir;
    dir.write("scene.toml", kScene);
    const Sweep s = loadSweep(dir.write("sweep.toml", "scene = \"scene.toml\"\n[set]\nworld.duration = 0.5\npart.ball.density = 3.0\n"));
    const Scene scene = sweepScene(s, 0);
    EXPECT_EQ(scene.duration, 0.5);
    EXPECT_EQ(scene.world.timeStep, 0.001);  // the rest of [world] kept
    EXPECT_EQ(scene.parts[1].body.density, 3.0);
    EXPECT_EQ(scene.parts[1].pose.translation, Vec3(0, 6, 0));
}

TEST(Sweep, IdsChangeWithWhatTheRunsShare) {
    TempDir dir;
    const std::string parameter = "[[parameter]]\nname = \"r\"\nkey = \"part.ball.density\"\nvalues = [1.0]\n";
    dir.write("scene.toml", kScene);
    const std::string base = loadSweep(dir.write("a.toml", sweepText(parameter))).runs[0].id;
    EXPECT_EQ(loadSweep(dir.write("b.toml", sweepText(parameter))).runs[0].id, base);  // the same sweep, another file
    EXPECT_NE(loadSweep(dir.write("c.toml", "scene = \"scene.toml\"\nduration = 0.5\n" + parameter)).runs[0].id, base);
    EXPECT_NE(loadSweep(dir.write("d.toml", sweepText(parameter) + "[set]\n\"world.time_step\" = 0.002\n")).runs[0].id, base);
    EXPECT_NE(loadSweep(dir.write("e.toml", sweepText("[[parameter]]\nname = \"r\"\nkey = \"part.mouth.density\"\nvalues = [1.0]\n"))).runs[0].id, base);
    dir.write("scene.toml", std::string(kScene) + "\n# edited\n");
    EXPECT_NE(loadSweep(dir.path() / "a.toml").runs[0].id, base);
}

TEST(Sweep, MissingBaseSceneIsAnError) {
    TempDir dir;
    try {
        loadSweep(dir.write("sweep.toml", "scene = \"absent.toml\"\n"));
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("absent.toml"), std::string::npos) << e.what();
    }
}

TEST(Sweep, NoParametersIsOneRunOfTheBase) {
    TempDir dir;
    const Sweep s = load(dir, "");
    ASSERT_EQ(s.runs.size(), 1u);
    EXPECT_EQ(sweepScene(s, 0).parts.size(), 2u);
}

// loadSweep's read options reach every run's scene, as loadScene's reach one: the remesh cache
// (one surface for every run and the check) and strict meshes (the file's defect refused).
TEST(Sweep, ReadOptionsReachEveryRunsScene) {
    TempDir dir;
    // A tetrahedron with an unreferenced vertex (a defect repaired with a warning).
    dir.write("tet.tri", "tet\n5 4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n5 5 5\n0 2 1\n0 1 3\n0 3 2\n1 2 3\n");
    const std::string scene = "[world]\ntime_step = 0.001\nduration = 0.01\n[[part]]\nname = \"tet\"\nmesh = \"tet.tri\"\nremesh = 0.2\n";
    dir.write("scene.toml", scene);
    const auto sweepFile = dir.write("sweep.toml", "scene = \"scene.toml\"\n[[parameter]]\nname = \"damping\"\nkey = \"part.tet.global_damping\"\nvalues = [0.0, 0.1]\n");
    const std::filesystem::path cache = dir.path() / "cache";
    SceneReadOptions read;
    read.remeshCache = cache;
    const Sweep s = loadSweep(sweepFile, true, read);
    ASSERT_EQ(s.runs.size(), 2u);
    const auto cacheFiles = [&] {
        std::size_t n = 0;
        for ([[maybe_unused]] const auto& entry : std::filesystem::directory_iterator(cache)) ++n;
        return n;
    };
    EXPECT_EQ(cacheFiles(), 1u);
    const Scene alone = loadScene(dir.path() / "scene.toml", read);
    for (std::size_t run = 0; run < 2; ++run) {
        const Scene runScene = sweepScene(s, run);
        EXPECT_EQ(runScene.parts[0].model->mesh.vertices, alone.parts[0].model->mesh.vertices);
        ASSERT_EQ(runScene.warnings.size(), alone.warnings.size());
    }
    EXPECT_EQ(cacheFiles(), 1u);
    read.strictMeshes = true;
    try {
        loadSweep(sweepFile, true, read);
        FAIL() << "strict meshes: the defect is refused";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("scene.toml:6: part 1, key 'mesh'"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("tet.tri"), std::string::npos) << e.what();
    }
    read = {};
    read.remeshCache = std::filesystem::path();
    const Sweep uncached = loadSweep(sweepFile, true, read);
    EXPECT_EQ(sweepScene(uncached, 1).parts[0].model->mesh.vertices, alone.parts[0].model->mesh.vertices);
    EXPECT_EQ(cacheFiles(), 1u);
}

// The runs' scene warnings are kept once each, in the base scene's lines: a mesh repair every
// run meets once, a warning only some runs meet (the per-step restoration at other time steps)
// once per distinct message; none without the check.
TEST(Sweep, TheRunsWarningsAreKeptOnceEach) {
    TempDir dir;
    dir.write("tet.tri", "tet\n5 4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n5 5 5\n0 2 1\n0 1 3\n0 3 2\n1 2 3\n");
    dir.write("scene.toml", "[world]\ntime_step = 0.001\nduration = 0.01\n[[part]]\nname = \"tet\"\nmesh = \"tet.tri\"\n");
    const auto file = dir.write("sweep.toml", "scene = \"scene.toml\"\n[[parameter]]\nname = \"dt\"\nkey = \"world.time_step\"\n"
                                              "values = [0.001, 0.002, 0.0005]\n[[parameter]]\nname = \"damping\"\n"
                                              "key = \"part.tet.global_damping\"\nvalues = [0.0, 0.1]\n");
    const Scene alone = loadScene(dir.path() / "scene.toml");
    ASSERT_EQ(alone.warnings.size(), 1u);  // the repair
    const Sweep s = loadSweep(file);
    ASSERT_EQ(s.runs.size(), 6u);
    ASSERT_EQ(s.warnings.size(), 3u);
    EXPECT_EQ(s.warnings[0].line, alone.warnings[0].line);
    EXPECT_EQ(s.warnings[0].message, alone.warnings[0].message);
    EXPECT_NE(s.warnings[1].message.find("at time_step = 0.002 the part restores 0.5 times"), std::string::npos) << s.warnings[1].message;
    EXPECT_NE(s.warnings[2].message.find("at time_step = 0.0005 the part restores 2 times"), std::string::npos) << s.warnings[2].message;
    EXPECT_TRUE(loadSweep(file, false).warnings.empty());
}

}  // namespace
}  // namespace flexfit
