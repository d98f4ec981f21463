// Scripted scene runs against analytic mechanics (impulse of a push, the interpolated grab
// target), the thesis's ball-through-torus cases with the shipped example scene, the contact
// solver's example scenes (incline, peg in hole, stack, ball-torus with friction) against
// Coulomb's law, and determinism of a whole scene run.
#include "collision/sampling_kernel.hpp"
#include "core/fnv1a.hpp"
#include "core/lanes256.hpp"
#include "flexfit/scene_file.hpp"
#include "flexfit/scene_run.hpp"
#include "flexfit/frame_export.hpp"
#include "flexfit/mesh_io.hpp"
#include "golden.hpp"
#include "shuffled_mesh.hpp"
#include "temp_dir.hpp"
#include "test_bodies.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <vector>

using namespace flexfit;

namespace {

const char* kFreeBall = R"(
[world]
time_step = 0.001
gravity = [0, 0, 0]
duration = 1.0

[[part]]
name = "ball"
generator = { type = "sphere", radius = 1.0, level = 2 }
mode = "rigid"
motion = "dynamic"

[[part]]
name = "hand"
generator = { type = "sphere", radius = 1.0, level = 1 }
mode = "rigid"
motion = "kinematic"
position = [10, 0, 0]

[[action]]
time = 0.1
type = "push"
part = "ball"
force = [3, 0, 0]
duration = 0.25

[[action]]
time = 0.2
type = "grab"
part = "hand"

[[action]]
time = 0.2
type = "move"
part = "hand"
position = [10, 4, 0]
duration = 0.4
)";

Scene exampleScene(const std::string& file) { return loadScene(std::string(FLEXFIT_EXAMPLES_DIR) + "/" + file); }

// The steps `seconds` of the scene take.
int stepsFor(const SceneRun& run, double seconds) { return int(std::lround(seconds / run.scene().world.timeStep)); }

void runFor(SceneRun& run, double seconds) {
    for (int i = 0, steps = stepsFor(run, seconds); i < steps; ++i) run.step();
}

BodyId partNamed(const Scene& scene, std::string_view name) {
    const std::optional<BodyId> id = scene.find(name);
    if (!id) throw std::runtime_error("no part named " + std::string(name));
    return *id;
}

// The pair's coefficients by the combining rule (body.hpp): geometric mean.
double pairStaticFriction(const Scene& scene, BodyId a, BodyId b) {
    return std::sqrt(scene.parts[a].body.staticFriction * scene.parts[b].body.staticFriction);
}
double pairKineticFriction(const Scene& scene, BodyId a, BodyId b) {
    return std::sqrt(scene.parts[a].body.kineticFriction * scene.parts[b].body.kineticFriction);
}

// The push the scene gives `body` (its only one).
Vec3 pushOn(const Scene& scene, BodyId body) {
    for (const SceneAction& a : scene.actions)
        if (a.kind == SceneAction::Kind::Push && a.body == body) return a.force;
    throw std::runtime_error("no push on body " + std::to_string(body));
}

// Lowest and highest y of the part's vertices in the world.
std::pair<double, double> heightRange(const World& world, BodyId id) {
    std::vector<Vec3> positions;
    world.part(id).worldPositions(positions);
    double lo = positions[0].y(), hi = lo;
    for (const Vec3& x : positions) {
        lo = std::min(lo, x.y());
        hi = std::max(hi, x.y());
    }
    return {lo, hi};
}

}  // namespace

TEST(SceneRun, PushActsForItsDurationExactly) {
    SceneRun run(parseScene(kFreeBall, "free.toml", "."));
    runFor(run, 1.0);
    // Impulse F D over the mass: the push acts in the 250 steps starting in [0.1, 0.35).
    const RigidBody& ball = run.world().body(0);
    EXPECT_NEAR(ball.linearVelocity.x(), 3.0 * 0.25 * ball.inverseMass, 1e-12);
}

// What the world refuses when the scene runs (a part's mass properties, the operator's coupling)
// names the scene file and the part's or action's line, not "p:" or "world:".
TEST(SceneRun, WhatTheWorldRefusesNamesTheScenesLine) {
    flexfit::testing::TempDir dir;
    const auto flat = dir.write("flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    const std::string oneTriangle = "[world]\nduration = 0.1\n\n[[part]]\nname = \"p\"\nmesh = \"" + flat.string() +
                                    "\"\nmode = \"rigid\"\nmotion = \"dynamic\"\n";
    try {
        SceneRun run(parseScene(oneTriangle, "scene.toml", "."));
        FAIL() << "a dynamic part of no volume was accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.source(), "scene.toml");
        EXPECT_EQ(e.line(), 4u);
        EXPECT_EQ(e.problem().rfind("part 'p': ", 0), 0u) << e.what();
    }
    // A sweep's run: the lines are its base scene's, the run is named beside them.
    Scene sweepRun = parseScene(oneTriangle, "sweep.toml run 1a2b", ".");
    sweepRun.linesFile = "scene.toml";
    try {
        SceneRun refused(sweepRun);
        FAIL() << "a dynamic part of no volume was accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.source(), "scene.toml");
        EXPECT_EQ(e.line(), 4u);
        EXPECT_EQ(e.problem().rfind("part 'p' (in sweep.toml run 1a2b): ", 0), 0u) << e.what();
    }
    const std::string base = kFreeBall;
    const auto grabLine = std::size_t(std::count(base.begin(), base.end(), '\n')) + 1;  // the appended table's first line
    SceneRun run(parseScene(base + "[[action]]\ntime = 0.7\ntype = \"grab\"\npart = \"ball\"\nstiffness = 1e300\n", "free.toml", "."));
    try {
        runFor(run, 1.0);
        FAIL() << "a grab of stiffness 1e300 was accepted";
    } catch (const InputError& e) {
        EXPECT_EQ(e.source(), "free.toml");
        EXPECT_EQ(e.line(), grabLine) << e.what();
        EXPECT_EQ(e.problem().rfind("action 'grab' of part 'ball': ", 0), 0u) << e.what();
    }
}

// The thesis's perturbation as a scene action: each listed mass's velocity changes at once, and a
// free full-deformable part (no restoration, no gravity) keeps the momentum sum m_i dv.
TEST(SceneRun, AKickActionGivesTheMassesTheirVelocityChange) {
    const char* text = R"(
[world]
time_step = 0.001
gravity = [0, 0, 0]
duration = 0.3

[[part]]
name = "ring"
generator = "torus1"
mode = "full-deformable"
restoration = "none"
vertex_mass = 0.5

[[action]]
time = 0.1
type = "kick"
part = "ring"
masses = [3, 40]
velocity = [0.4, 0, -0.2]
)";
    SceneRun run(parseScene(text, "kick.toml", "."));
    runFor(run, 0.05);
    const Part& ring = run.world().part(0);
    EXPECT_EQ(ring.state().velocities[3], Vec3::Zero());
    runFor(run, 0.2);
    Vec3 momentum = Vec3::Zero();
    for (Index i = 0; i < ring.model().massCount(); ++i) momentum += ring.model().mass[i] * ring.state().velocities[i];
    EXPECT_LT((momentum - 2 * 0.5 * Vec3(0.4, 0, -0.2)).norm(), 1e-12);
}

// The stiff clip example: a plastic arm (E = 2.2 GPa, springs ~1e6 N/m on ~1e-5 kg masses) pressed
// by the tool deforms only around it, with the implicit integrator at 1 ms, and is back exactly at
// rest after the tool leaves; the same scene with the explicit integrator diverges and says to
// use the implicit one.
TEST(SceneRun, StiffClipDeformsLocallyUnderTheToolAndRestores) {
    const Scene scene = exampleScene("stiff_clip.toml");
    SceneRun run(scene);
    runFor(run, 0.45);  // held 0.6 mm into the top face
    const Part& clip = run.world().part(0);
    double deepest = 0.0;
    for (Index m : clip.movingMasses()) deepest = std::max(deepest, (clip.state().positions[m] - clip.model().restPositions[m]).norm());
    EXPECT_GT(deepest, 1e-4);  // the masses under the tool moved over 0.1 mm
    EXPECT_LT(deepest, 6e-4);  // and not beyond the tool's depth
    EXPECT_GT(clip.movingMasses().size(), 0u);
    EXPECT_LT(clip.movingMasses().size(), clip.model().massCount() / 10);  // locally
    runFor(run, 1.0);
    EXPECT_EQ(clip.zoneCount(), 0u);
    EXPECT_EQ(clip.state().positions, clip.model().restPositions);

    Scene explicitClip = scene;
    explicitClip.parts[0].part.simulation.integrator = Integrator::SemiImplicitEuler;
    SceneRun diverging(explicitClip);
    try {
        runFor(diverging, 1.0);
        ADD_FAILURE() << "the explicit step ran the stiff clip";
    } catch (const DivergenceError& e) {
        EXPECT_NE(std::string(e.what()).find("use the implicit integrator"), std::string::npos) << e.what();
    }
}

TEST(SceneRun, MoveInterpolatesTheGrabTargetLinearly) {
    SceneRun run(parseScene(kFreeBall, "free.toml", "."));
    runFor(run, 0.4);  // halfway through the move (0.2 .. 0.6)
    EXPECT_NEAR(run.world().part(1).pose().translation.y(), 2.0, 1e-9);
    runFor(run, 0.4);
    EXPECT_NEAR(run.world().part(1).pose().translation.y(), 4.0, 1e-12);
    EXPECT_FALSE(run.finished());
    runFor(run, 0.2);
    EXPECT_TRUE(run.finished());
}

class SceneRunWithQuery : public ::testing::TestWithParam<RigidDeformableQuery> {};

TEST_P(SceneRunWithQuery, DeformableMouthLetsThePushedBallThroughAndRestores) {
    Scene scene = exampleScene("ball_torus.toml");  // diameter 17, pushed with 2,500, elastic rim
    scene.world.collision.rigidDeformable = GetParam();
    SceneRun run(scene);
    std::size_t deformedMost = 0;
    while (!run.finished()) {
        run.step();
        deformedMost = std::max(deformedMost, run.world().part(0).movingMasses().size());
    }
    const World& w = run.world();
    ASSERT_EQ(w.assemblyEvents().size(), 1u);
    EXPECT_EQ(w.assemblyEvents()[0].technique, SnapTechnique::ZoneSnap);
    EXPECT_LT(w.assemblyEvents()[0].primaryPoseBefore.translation.y(), -8.5 + 1e-9);  // its top below the rim plane
    EXPECT_LT((w.centreOfMass(1) - Vec3(0, -12, 0)).norm(), 1e-9);
    EXPECT_GT(deformedMost, 100u);                                  // the rim deformed to let it through
    EXPECT_EQ(w.part(0).movingMasses().size(), 0u);                 // and is rigid again:
    EXPECT_EQ(w.part(0).computedSprings().size(), 0u);              // zero active springs
    for (Index m = 0; m < w.part(0).model().massCount(); ++m)
        ASSERT_EQ(w.part(0).state().positions[m], w.part(0).model().restPositions[m]) << "mass " << m;
}

TEST_P(SceneRunWithQuery, StiffMouthStopsTheBallUnderGravity) {
    Scene scene = exampleScene("ball_torus.toml");
    scene.world.collision.rigidDeformable = GetParam();
    scene.actions.clear();  // gravity alone
    scene.duration = 1.5;
    PartModelSettings stiff;
    stiff.material = Material::rigid();
    scene.parts[0].model = buildPartModel(scene.parts[0].model->mesh, stiff);
    scene.parts[0].part.simulation.restoration = {RestorationMethod::AnchorSprings, 100.0, 20.0, 1e-3};
    SceneRun run(scene);
    runFor(run, scene.duration);
    EXPECT_TRUE(run.world().assemblyEvents().empty());
    EXPECT_GT(run.world().centreOfMass(1).y(), 3.0);  // resting on the rim (touches at 4.58 when rigid)
    EXPECT_GT(run.world().part(0).movingMasses().size(), 0u);  // the rim is deformed under it
    EXPECT_GT(run.world().body(1).linearVelocity.y(), -0.01);  // not sinking (the anchors push back up)
}

INSTANTIATE_TEST_SUITE_P(EveryQuery, SceneRunWithQuery,
                         ::testing::Values(RigidDeformableQuery::Faces, RigidDeformableQuery::PointShell, RigidDeformableQuery::Auto),
                         [](const auto& param) {
                             switch (param.param) {
                                 case RigidDeformableQuery::Faces: return "Faces";
                                 case RigidDeformableQuery::PointShell: return "PointShell";
                                 case RigidDeformableQuery::Auto: break;
                             }
                             return "Auto";
                         });

// --- The contact solver's example scenes, against Coulomb's law. ---

TEST(SceneRun, InclineHoldsOneBoxAndSlidesTheOtherWithTheKineticAcceleration) {
    const Scene scene = exampleScene("incline.toml");
    const BodyId slope = partNamed(scene, "slope"), holding = partNamed(scene, "holding"), sliding = partNamed(scene, "sliding");
    const Eigen::Quaterniond tilt = scene.parts[slope].pose.rotation;
    const Vec3 up = tilt * Vec3::UnitY(), down = -(tilt * Vec3::UnitX());
    const double g = scene.world.gravity.norm();
    const double theta = std::acos(up.dot(-scene.world.gravity / g));
    // The premises the scene states: tan theta between the two boxes' static coefficients.
    ASSERT_LT(std::tan(theta), pairStaticFriction(scene, slope, holding));
    ASSERT_GT(std::tan(theta), pairStaticFriction(scene, slope, sliding));
    ASSERT_LT(down.y(), 0.0);
    const double muK = pairKineticFriction(scene, slope, sliding);
    const double expected = g * (std::sin(theta) - muK * std::cos(theta));

    SceneRun run(scene);
    const World& w = run.world();
    const Vec3 holdingStart = w.centreOfMass(holding);
    double holdingMoved = 0.0, v1 = 0.0, t1 = 0.0;
    while (!run.finished()) {
        run.step();
        holdingMoved = std::max(holdingMoved, (w.centreOfMass(holding) - holdingStart).norm());
        if (std::abs(w.time() - 0.2) < 1e-9) {  // past the first contact's settling
            v1 = w.body(sliding).linearVelocity.dot(down);
            t1 = w.time();
        }
    }
    EXPECT_LT(holdingMoved, 1e-3);
    const double a = (w.body(sliding).linearVelocity.dot(down) - v1) / (w.time() - t1);
    EXPECT_NEAR(a / expected, 1.0, 0.02) << "a = " << a << ", g (sin theta - mu_k cos theta) = " << expected;
    // It slid the distance that acceleration gives (4.7 in the 2 s), not a little.
    EXPECT_GT((w.centreOfMass(sliding) - scene.parts[sliding].pose.translation).dot(down), 0.4 * expected * w.time() * w.time());
}

TEST(SceneRun, PegSticksInItsHoleWhenPushedTooWeaklyAndPassesWhenPushedHarder) {
    // A peg pushed with a side force Fs on the hole's wall and a down force Fd slides down iff
    // Fd + m g > mu_s Fs (mu: the pair's, by the combining rule).
    const Scene scene = exampleScene("peg_in_hole.toml");
    const BodyId weakPlate = partNamed(scene, "plate_weak"), strongPlate = partNamed(scene, "plate_strong");
    const BodyId weak = partNamed(scene, "weak"), strong = partNamed(scene, "strong");
    SceneRun run(scene);
    const World& w = run.world();
    const double g = scene.world.gravity.norm();
    auto downLoad = [&](BodyId peg) { return -pushOn(scene, peg).y() + w.body(peg).mass * g; };
    auto friction = [&](BodyId peg, BodyId plate) { return pairStaticFriction(scene, peg, plate) * pushOn(scene, peg).x(); };
    ASSERT_LT(downLoad(weak), 0.9 * friction(weak, weakPlate));      // 15.0 against 20
    ASSERT_GT(downLoad(strong), 1.1 * friction(strong, strongPlate));  // 35.0 against 20

    const Vec3 weakStart = w.centreOfMass(weak);
    const auto [weakPlateBottom, weakPlateTop] = heightRange(w, weakPlate);
    const double strongPlateBottom = heightRange(w, strongPlate).first;
    // The strong peg slides down the wall with a = (Fd + m g - mu_k Fs) / m while it is wholly in
    // the hole (the first 0.1 s: 0.19 of its 0.9 to go).
    runFor(run, 0.1);
    const double a = (downLoad(strong) - pairKineticFriction(scene, strong, strongPlate) * pushOn(scene, strong).x()) / w.body(strong).mass;
    EXPECT_NEAR(-w.body(strong).linearVelocity.y() / (a * w.time()), 1.0, 0.02) << "a = " << a;
    double weakMoved = 0.0;
    while (!run.finished()) {
        run.step();
        weakMoved = std::max(weakMoved, (w.centreOfMass(weak) - weakStart).norm());
    }
    EXPECT_LT(weakMoved, 1e-3);                                // stuck where it was put
    EXPECT_GT(heightRange(w, weak).first, weakPlateBottom);    // still in its hole
    EXPECT_LT(heightRange(w, weak).second, weakPlateTop);
    EXPECT_LT(heightRange(w, strong).second, strongPlateBottom);  // wholly below its plate: through
}

TEST(SceneRun, StackStaysInItsSettledPose) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "Release only: the same scene runs whole under the sanitizers in GoldenHashWithEveryKernel/stack"
                    " (make test-sanitizer-long)";
#endif
    const Scene scene = exampleScene("stack.toml");
    std::vector<BodyId> boxes;
    for (const char* name : {"bottom", "middle", "top"}) boxes.push_back(partNamed(scene, name));
    SceneRun run(scene);
    const World& w = run.world();
    runFor(run, 0.2);  // settle into the contacts (each box starts 1e-4 above the one below)
    flexfit::testing::PoseDrift drift(w, boxes);
    EXPECT_LT((drift.rest[0].translation - scene.parts[boxes[0]].pose.translation).norm(), 1e-3);  // settled where it was put
    while (!run.finished()) {
        run.step();
        drift.record(w);
    }
    EXPECT_LT(drift.translation, 1e-3);
    EXPECT_LT(drift.rotation, 1e-3);
}

TEST(SceneRun, FrictionSlowsTheBallThroughTheMouthButItStillPasses) {
#if defined(__SANITIZE_ADDRESS__)
    GTEST_SKIP() << "Release only: both scenes run whole under the sanitizers in GoldenHashWithEveryKernel";
#endif
    auto assembled = [](const char* file) {
        const Scene scene = exampleScene(file);
        SceneRun run(scene);
        runFor(run, scene.duration);
        const World& w = run.world();
        EXPECT_EQ(w.part(0).movingMasses().size(), 0u) << file;  // the rim restored
        EXPECT_LT((w.centreOfMass(1) - Vec3(0, -12, 0)).norm(), 1e-9) << file;
        return w.assemblyEvents();
    };
    const Scene scene = exampleScene("ball_torus_friction.toml");
    ASSERT_GT(pairStaticFriction(scene, 0, 1), 0.0);
    ASSERT_GT(pairKineticFriction(scene, 0, 1), 0.0);
    const std::vector<AssemblyEvent> withFriction = assembled("ball_torus_friction.toml");
    const std::vector<AssemblyEvent> without = assembled("ball_torus.toml");
    ASSERT_EQ(withFriction.size(), 1u);
    ASSERT_EQ(without.size(), 1u);
    EXPECT_EQ(withFriction[0].technique, SnapTechnique::ZoneSnap);
    EXPECT_LT(withFriction[0].primaryPoseBefore.translation.y(), -8.5 + 1e-9);  // its top below the rim plane
    EXPECT_GT(withFriction[0].time, without[0].time + 0.1);  // friction held it back (0.99 s against 0.62 s)
    EXPECT_LT(withFriction[0].time, 1.5);                     // through while the push lasts
}

TEST(SceneRun, WholeRunIsDeterministic) {
#if defined(__SANITIZE_ADDRESS__)
    // Five runs of one scene check no memory the golden runs do not (GoldenHashWithEveryKernel
    // runs it under the sanitizers); determinism is checked by the Release build.
    GTEST_SKIP() << "Release only: the same scene runs under the sanitizers in GoldenHashWithEveryKernel";
#endif
    auto hashOf = [](double startOffset, RigidDeformableQuery query = RigidDeformableQuery::Faces) {
        Scene scene = exampleScene("ball_torus.toml");
        scene.world.collision.rigidDeformable = query;
        scene.parts[1].pose.translation.x() += startOffset;
        SceneRun run(scene);
        runFor(run, 0.7);  // through contact, deformation and the snap
        return std::make_pair(run.world().stateHash(), run.world().assemblyEvents().size());
    };
    const auto a = hashOf(0.0), b = hashOf(0.0), c = hashOf(1e-9);
    EXPECT_EQ(a.first, b.first);
    EXPECT_EQ(a.second, 1u);
    EXPECT_NE(a.first, c.first);  // the hash sees a nanometre
    // Point-shell contacts fill the distance grid lazily: still the same run twice.
    const auto d = hashOf(0.0, RigidDeformableQuery::PointShell), e = hashOf(0.0, RigidDeformableQuery::PointShell);
    EXPECT_EQ(d, e);
    EXPECT_EQ(d.second, 1u);
    EXPECT_NE(d.first, a.first);
}

// --- Pinned hashes (golden.hpp): every example scene for its whole duration, with each block
// kernel the CPU has. `hash` is the final state's, the number `flexfit run examples/<scene>.toml`
// prints; `path` is the run's way there (runHashed): a scene that restores ends in the state it
// began in whatever happened on the way, which its final hash alone does not see (a change to
// stiff_clip's contacts moved its deformation from 0.30 to 0.45 mm and kept its final hash). ---

namespace {

struct GoldenScene {
    const char* file;
    const char* hash;
    const char* path;
};

struct RunHashes {
    std::string final, path;
};

// Runs `seconds` of the scene. The path hash mixes every step's contact count and body poses,
// and the whole state hash every 100 steps.
RunHashes runHashed(SceneRun& run, double seconds) {
    const World& w = run.world();
    detail::Fnv1a path;
    for (int i = 0, steps = stepsFor(run, seconds); i < steps; ++i) {
        run.step();
        const std::uint64_t contacts = w.contacts().size();
        path.mix(&contacts, sizeof contacts);
        for (BodyId id = 0; id < w.bodyCount(); ++id) {
            const Pose& pose = w.part(id).pose();
            path.mix(pose.translation.data(), 3 * sizeof(double));
            path.mix(pose.rotation.coeffs().data(), 4 * sizeof(double));
        }
        if (i % 100 == 99) {
            const std::uint64_t state = w.stateHash();
            path.mix(&state, sizeof state);
        }
    }
    return {flexfit::testing::hex(w.stateHash()), flexfit::testing::hex(path.value())};
}

const GoldenScene kGoldenScenes[] = {
    {"ball_torus.toml", "fbc9ecabec83ec5c", "706a151f6916cc5d"},
    {"ball_torus_haptic.toml", "0725a3112c0fb200", "31816a2871413e0c"},
    {"ball_torus_rigid.toml", "4477548f5d76ac88", "8e4f69b2e2aaa38a"},
    {"contact.toml", "6f71c49d7327c00a", "b940cc0f5dd66393"},
    {"restoration.toml", "9d482c652726a54e", "8f0068dd99bfe7b3"},
    {"snap_vector.toml", "9ae6d4634631f9cc", "799210fa56c9faaa"},
    {"zones.toml", "a2708df36460c7d3", "6c2e1cca2d50ed7f"},
    {"incline.toml", "be4bf8a503ce3d17", "b3cb01b01e86e97d"},
    {"peg_in_hole.toml", "356986eccaa91ab3", "745218e3ffa6d3a1"},
    {"stack.toml", "e5e1b0d789281d4b", "d29b3a273c14b154"},
    {"ball_torus_friction.toml", "48041e611fddb539", "576977e569949991"},
    {"stiff_clip.toml", "b1a97775ad8c4992", "6592a675ff4084ae"},
    // On CGAL's remeshed surfaces (the remeshing is deterministic: exact predicates, no threads),
    // their masses renumbered for locality (vertex_order.hpp).
    {"ball_torus_remeshed.toml", "c8f1ac90a535dc7d", "6cb90e020d8b1613"},
    {"contact_remeshed.toml", "4c36e049ea25e3c2", "8f7291f2930ab59e"},
};

[[maybe_unused]] bool remeshed(const GoldenScene& scene) { return std::string(scene.file).find("remeshed") != std::string::npos; }

void PrintTo(const GoldenScene& scene, std::ostream* out) { *out << scene.file; }

class GoldenSceneRun : public ::testing::TestWithParam<GoldenScene> {};

}  // namespace

// Sanitizer builds run ~10x slower: they check the scalar kernel only (the Release build checks
// every kernel against the same numbers).
#if defined(__SANITIZE_ADDRESS__)
const std::vector<detail::BlockKernel> kSceneKernels = {detail::BlockKernel::Scalar};
#else
const std::vector<detail::BlockKernel> kSceneKernels = flexfit::testing::availableBlockKernels();
#endif

TEST_P(GoldenSceneRun, GoldenHashWithEveryKernel) {
#if defined(__SANITIZE_ADDRESS__)
    // CGAL's remeshing of a whole part under the sanitizers takes minutes; its memory is checked
    // by remesh_test on small meshes. The Release build pins these two hashes.
    if (remeshed(GetParam())) GTEST_SKIP() << "Release only: a remeshed scene";
#endif
    const Scene scene = exampleScene(GetParam().file);
    for (const auto kernel : kSceneKernels) {
        const detail::ScopedBlockKernel chosen(kernel);
        // The scalar kernel runs as on a CPU without vector units: the point shell's masses are
        // sampled one by one too, and the lane paths run one at a time (lanes256.hpp) (under the sanitizers,
        // the vector paths the CPU has).
        std::optional<detail::ScopedScalarSampling> scalarSampling;
        std::optional<detail::ScopedScalarLanes> scalarLanes;
#if !defined(__SANITIZE_ADDRESS__)
        if (kernel == detail::BlockKernel::Scalar) {
            scalarSampling.emplace();
            scalarLanes.emplace();
        }
#endif
        SceneRun run(scene);
        const RunHashes hashes = runHashed(run, scene.duration);
        EXPECT_EQ(hashes.final, GetParam().hash) << detail::toString(kernel);
        EXPECT_EQ(hashes.path, GetParam().path) << detail::toString(kernel);
    }
}

// The coherent narrow phase answers exactly what full traversals answer: the same trajectory,
// bit for bit, with it turned off (one kernel), by face and by point-shell queries.
TEST_P(GoldenSceneRun, TheSameHashWithoutCoherentCollision) {
#if defined(__SANITIZE_ADDRESS__)
    // A second whole run of every scene adds no memory check the first does not make (the plain
    // query also runs in the coherent query's own tests); the Release run compares the hashes.
    GTEST_SKIP() << "Release only: the same scenes run whole under the sanitizers in GoldenHashWithEveryKernel";
#endif
    Scene scene = exampleScene(GetParam().file);
    scene.world.collision.coherent = false;
    const detail::ScopedBlockKernel chosen(kSceneKernels.front());
    SceneRun run(scene);
    const RunHashes hashes = runHashed(run, scene.duration);
    EXPECT_EQ(hashes.final, GetParam().hash);
    EXPECT_EQ(hashes.path, GetParam().path);
}

INSTANTIATE_TEST_SUITE_P(Examples, GoldenSceneRun, ::testing::ValuesIn(kGoldenScenes), [](const auto& param) {
    std::string name = param.param.file;
    name = name.substr(0, name.find('.'));
    return name;
});

TEST(SceneRun, ADivergenceNamesThePartOfTheScene) {
    const Scene scene = parseScene(R"(
[world]
time_step = 0.001
gravity = [0, 0, 0]
duration = 1.0

[[part]]
name = "bystander"
generator = { type = "sphere", radius = 1.0, level = 1 }
mode = "rigid"
position = [40, 0, 0]

[[part]]
name = "rim"
generator = "torus1"

[[action]]
time = 0.0
type = "force"
part = "rim"
masses = [3]
force = [0, 1e300, 0]
duration = 0.1
)",
                                   "diverging.toml", ".");
    SceneRun run(scene);
    try {
        runFor(run, 0.1);
        FAIL() << "a force of 1e300 did not diverge";
    } catch (const DivergenceError& e) {
        EXPECT_EQ(e.body(), BodyId(1));
        EXPECT_EQ(e.name(), "rim");
        EXPECT_EQ(std::string(e.what()).rfind("body 1 'rim' diverged at t = ", 0), 0u) << e.what();
    }
}

// A mesh file in no useful vertex order (a shuffled torus): the scene renumbers its masses for
// locality (vertex_order = "locality", the default), yet its mass indices, drawn positions and
// VTK frames are the file's, and the run is the one vertex_order = "as_given" gives up to the
// summation order.
namespace {

std::string vtkSection(const std::string& text, const std::string& opening) {
    const std::size_t start = text.find(opening);
    if (start == std::string::npos) return {};
    const std::size_t body = text.find('>', start + opening.size()) + 1;
    return text.substr(body, text.find("</DataArray>", body) - body);
}

std::vector<double> numbers(const std::string& text) {
    std::istringstream in(text);
    std::vector<double> out;
    for (double x; in >> x;) out.push_back(x);
    return out;
}

// A ring read from `mesh`, pushed at two vertices and kicked at a third.
std::string ringScene(const std::string& mesh, Index pushed1, Index pushed2, Index kicked) {
    return R"(
[world]
time_step = 0.001
gravity = [0, 0, 0]
duration = 0.2

[[part]]
name = "ring"
mesh = ")" + mesh + R"("
mode = "rigid-deformable"
restoration = "none"
global_damping = 0.5

[[action]]
time = 0.0
type = "force"
part = "ring"
masses = [)" + std::to_string(pushed1) + ", " + std::to_string(pushed2) + R"(]
force = [0.3, -0.1, 0.2]
duration = 0.1

[[action]]
time = 0.05
type = "kick"
part = "ring"
masses = [)" + std::to_string(kicked) + R"(]
velocity = [0, 0.5, 0]
)";
}

}  // namespace

TEST(SceneRun, AFileMeshRenumberedForLocalityKeepsTheFilesOrderInEveryOutput) {
    flexfit::testing::TempDir dir;
    const TriMesh file = flexfit::testing::shuffledVertices(makeTorus(3.0, 1.0, 24, 16), 9);
    writeMesh(file, dir.path() / "torus.tri");
    const std::string scene = ringScene("torus.tri", 5, 200, 77);
    const Scene local = parseScene(scene, "scene.toml", dir.path());
    ASSERT_TRUE(local.parts[0].model->renumbered());
    const Scene asGiven = parseScene(
        std::string(scene).insert(scene.find("mode ="), "vertex_order = \"as_given\"\n"), "scene.toml", dir.path());
    ASSERT_FALSE(asGiven.parts[0].model->renumbered());

    SceneRun a(local), b(asGiven);
    std::vector<Vec3> drawnA, drawnB;
    a.world().part(0).drawnWorldPositions(drawnA);
    EXPECT_EQ(drawnA, file.vertices) << "at rest, the file's vertices in its order";
    EXPECT_EQ(a.world().part(0).model().drawnMesh().faces, file.faces);
    runFor(a, 0.2);
    runFor(b, 0.2);
    a.world().part(0).drawnWorldPositions(drawnA);
    b.world().part(0).drawnWorldPositions(drawnB);
    ASSERT_EQ(drawnA.size(), drawnB.size());
    double largest = 0.0;
    for (std::size_t v = 0; v < drawnA.size(); ++v) largest = std::max(largest, (drawnA[v] - drawnB[v]).norm());
    EXPECT_LT(largest, 1e-12);
    // The loaded and kicked vertices are the file's 5, 200 and 77: they moved most.
    EXPECT_GT((drawnA[77] - file.vertices[77]).norm(), 0.01);
    EXPECT_GT((drawnA[5] - file.vertices[5]).norm(), 1e-4);

    // VTK frames: the same connectivity (the file's faces), the same points up to rounding.
    writeVtkFrame(dir.path() / "a.vtp", {{"ring", &a.world().part(0)}});
    writeVtkFrame(dir.path() / "b.vtp", {{"ring", &b.world().part(0)}});
    auto read = [&](const char* name) {
        std::ifstream in(dir.path() / name);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const std::string vtkA = read("a.vtp"), vtkB = read("b.vtp");
    EXPECT_EQ(vtkSection(vtkA, "Name=\"connectivity\""), vtkSection(vtkB, "Name=\"connectivity\""));
    const std::vector<double> depths = numbers(vtkSection(vtkA, "Name=\"zone_depth\""));
    EXPECT_EQ(depths, numbers(vtkSection(vtkB, "Name=\"zone_depth\"")));
    ASSERT_EQ(depths.size(), file.vertices.size());
    EXPECT_EQ(depths[5], 0.0) << "a zone is seeded at the loaded file vertex";
    EXPECT_EQ(depths[77], 0.0) << "a zone is seeded at the kicked file vertex";
    for (const char* field : {"Name=\"displacement\"", "<Points>\n<DataArray"}) {
        const std::vector<double> x = numbers(vtkSection(vtkA, field)), y = numbers(vtkSection(vtkB, field));
        ASSERT_EQ(x.size(), 3 * file.vertices.size()) << field;
        ASSERT_EQ(x.size(), y.size()) << field;
        for (std::size_t i = 0; i < x.size(); ++i) ASSERT_NEAR(x[i], y[i], 1e-12) << field << " " << i;
    }
}

// A file whose vertices the read welds and removes (a repeated vertex, a stray one no face uses,
// in the middle of the list): the scene, the frames and the drawn positions speak the file's
// vertex indices. Reference: the same run on the clean file, whose vertex c is the damaged
// file's vertex c + (c >= 10): the repaired mesh is the clean one, so every mass moves as in the
// clean run, bit for bit.
TEST(SceneRun, AFileThatLosesVerticesToTheRepairKeepsItsNumberingInEveryOutput) {
    flexfit::testing::TempDir dir;
    const TriMesh clean = flexfit::testing::shuffledVertices(makeTorus(3.0, 1.0, 24, 16), 9);
    TriMesh damaged = clean;
    const Vec3 stray(7.0, 0.5, -2.0);
    damaged.vertices.insert(damaged.vertices.begin() + 10, stray);
    for (Face& f : damaged.faces)
        for (Index& v : f) v += v >= 10 ? 1 : 0;
    const Index repeated = damaged.faces[30][0];
    damaged.vertices.push_back(damaged.vertices[repeated]);
    damaged.faces[30][0] = Index(damaged.vertices.size() - 1);
    writeMesh(clean, dir.path() / "clean.tri");
    writeMesh(damaged, dir.path() / "damaged.tri");
    const auto fileOf = [](Index c) { return c + (c >= 10 ? 1u : 0u); };
    const Scene cleanScene = parseScene(ringScene("clean.tri", 5, 200, 77), "scene.toml", dir.path());
    const Scene damagedScene = parseScene(ringScene("damaged.tri", fileOf(5), fileOf(200), fileOf(77)), "scene.toml", dir.path());
    const PartModel& model = *damagedScene.parts[0].model;
    ASSERT_TRUE(model.file);
    EXPECT_EQ(model.vertexCount(), damaged.vertices.size());
    EXPECT_EQ(model.massCount(), clean.vertices.size());
    EXPECT_EQ(model.vertexOf(model.massOf(fileOf(200))), fileOf(200));
    EXPECT_EQ(model.massOf(Index(damaged.vertices.size() - 1)), model.massOf(repeated)) << "a repeat is its first vertex's mass";

    SceneRun a(cleanScene), b(damagedScene);
    std::vector<Vec3> drawnA, drawnB;
    b.world().part(0).drawnWorldPositions(drawnB);
    EXPECT_EQ(drawnB, damaged.vertices) << "at rest, the file's vertices in its order";
    EXPECT_EQ(b.world().part(0).model().drawnMesh().faces.size(), clean.faces.size());
    runFor(a, 0.2);
    runFor(b, 0.2);
    a.world().part(0).drawnWorldPositions(drawnA);
    b.world().part(0).drawnWorldPositions(drawnB);
    ASSERT_EQ(drawnB.size(), damaged.vertices.size());
    for (Index c = 0; c < clean.vertices.size(); ++c) ASSERT_EQ(drawnB[fileOf(c)], drawnA[c]) << c;
    EXPECT_EQ(drawnB.back(), drawnB[repeated]) << "the repeat follows its first vertex";
    EXPECT_EQ(drawnB[10], b.world().part(0).pose().apply(stray)) << "the stray vertex is carried with the part";
    EXPECT_GT((drawnB[fileOf(77)] - damaged.vertices[fileOf(77)]).norm(), 0.01) << "the kicked file vertex moved";

    // VTK frames: the file's vertices (points and fields) and its faces, the repeat's corner
    // named by its first vertex.
    writeVtkFrame(dir.path() / "b.vtp", {{"ring", &b.world().part(0)}});
    std::ifstream in(dir.path() / "b.vtp");
    const std::string vtk((std::istreambuf_iterator<char>(in)), {});
    const std::vector<double> depths = numbers(vtkSection(vtk, "Name=\"zone_depth\""));
    ASSERT_EQ(depths.size(), damaged.vertices.size());
    EXPECT_EQ(depths[fileOf(77)], 0.0) << "a zone is seeded at the kicked file vertex";
    EXPECT_EQ(depths[10], -1.0) << "the stray vertex is in no zone";
    for (const char* field : {"Name=\"displacement\"", "Name=\"velocity\""}) {
        const std::vector<double> values = numbers(vtkSection(vtk, field));
        ASSERT_EQ(values.size(), 3 * damaged.vertices.size()) << field;
        EXPECT_EQ(Vec3(values[30], values[31], values[32]), Vec3::Zero()) << field << ": the stray vertex does not deform";
        EXPECT_GT(Vec3(values[3 * fileOf(77)], values[3 * fileOf(77) + 1], values[3 * fileOf(77) + 2]).norm(), 0.0) << field;
    }
    const std::vector<double> points = numbers(vtkSection(vtk, "<Points>\n<DataArray"));
    ASSERT_EQ(points.size(), 3 * damaged.vertices.size());
    for (std::size_t v = 0; v < damaged.vertices.size(); ++v)
        for (int k = 0; k < 3; ++k) ASSERT_NEAR(points[3 * v + std::size_t(k)], drawnB[v][k], 1e-12 * (1.0 + std::abs(drawnB[v][k])));
    TriMesh expectedFaces = damaged;
    expectedFaces.faces[30][0] = repeated;
    const std::vector<double> connectivity = numbers(vtkSection(vtk, "Name=\"connectivity\""));
    ASSERT_EQ(connectivity.size(), 3 * expectedFaces.faces.size());
    for (std::size_t f = 0; f < expectedFaces.faces.size(); ++f)
        for (int k = 0; k < 3; ++k) ASSERT_EQ(connectivity[3 * f + std::size_t(k)], double(expectedFaces.faces[f][std::size_t(k)])) << f;

    // Naming the stray vertex is an error at its line: it has no mass.
    try {
        parseScene(ringScene("damaged.tri", 10, 1, 2), "scene.toml", dir.path());
        ADD_FAILURE() << "a force on a removed vertex was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("key 'masses': vertex 10 of the part's mesh file was removed by the repair"), std::string::npos)
            << e.what();
        EXPECT_EQ(e.line(), 18u);
    }
    EXPECT_THROW(model.massOf(10), InputError);
}

TEST(SceneRun, VertexOrderIsCheckedAndAppliesToMeshFilesOnly) {
    flexfit::testing::TempDir dir;
    writeMesh(makeTorus(3.0, 1.0, 12, 8), dir.path() / "torus.tri");
    const std::string part = "[[part]]\nname = \"ring\"\nmesh = \"torus.tri\"\n";
    try {
        parseScene(part + "vertex_order = \"sorted\"\n", "scene.toml", dir.path());
        ADD_FAILURE() << "accepted vertex_order = \"sorted\"";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("scene.toml:4: part 1, key 'vertex_order': unknown value 'sorted'"), std::string::npos) << e.what();
    }
    try {
        parseScene("[[part]]\nname = \"ring\"\ngenerator = \"torus1\"\nvertex_order = \"as_given\"\n", "scene.toml", dir.path());
        ADD_FAILURE() << "accepted vertex_order on a generated part";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("key 'vertex_order': applies only to a part read from a 'mesh' file"), std::string::npos)
            << e.what();
    }
}
