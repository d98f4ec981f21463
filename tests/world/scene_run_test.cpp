// Scripted scene runs against analytic mechanics (impulse of a push, the interpolated grab
// target), the thesis's ball-through-torus cases with the shipped example scene, and
// determinism of a whole scene run.
#include "flexfit/scene_file.hpp"
#include "flexfit/scene_run.hpp"
#include "golden.hpp"

#include <gtest/gtest.h>

#include <cmath>

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

void runFor(SceneRun& run, double seconds) {
    const int steps = int(std::lround(seconds / run.scene().world.timeStep));
    for (int i = 0; i < steps; ++i) run.step();
}

}  // namespace

TEST(SceneRun, PushActsForItsDurationExactly) {
    SceneRun run(parseScene(kFreeBall, "free.toml", "."));
    runFor(run, 1.0);
    // Impulse F D over the mass: the push acts in the 250 steps starting in [0.1, 0.35).
    const RigidBody& ball = run.world().body(0);
    EXPECT_NEAR(ball.linearVelocity.x(), 3.0 * 0.25 * ball.inverseMass, 1e-12);
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

INSTANTIATE_TEST_SUITE_P(BothQueries, SceneRunWithQuery,
                         ::testing::Values(RigidDeformableQuery::Faces, RigidDeformableQuery::PointShell),
                         [](const auto& param) { return param.param == RigidDeformableQuery::Faces ? "Faces" : "PointShell"; });

TEST(SceneRun, WholeRunIsDeterministic) {
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
// kernel the CPU has. The same numbers as `flexfit run examples/<scene>.toml` prints. ---

namespace {

struct GoldenScene {
    const char* file;
    const char* hash;
};

const GoldenScene kGoldenScenes[] = {
    {"ball_torus.toml", "4372e99d59cae164"},   {"ball_torus_haptic.toml", "0725a3112c0fb200"},
    {"ball_torus_rigid.toml", "b4498b85a813732e"}, {"contact.toml", "6f71c49d7327c00a"},
    {"restoration.toml", "2bc6f95d3b2e0cfe"},  {"snap_vector.toml", "9ae6d4634631f9cc"},
    {"zones.toml", "8256e010fa0e79ca"},
};

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
    const Scene scene = exampleScene(GetParam().file);
    for (const auto kernel : kSceneKernels) {
        const detail::ScopedBlockKernel chosen(kernel);
        SceneRun run(scene);
        runFor(run, scene.duration);
        EXPECT_EQ(flexfit::testing::hex(run.world().stateHash()), GetParam().hash) << detail::toString(kernel);
    }
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
