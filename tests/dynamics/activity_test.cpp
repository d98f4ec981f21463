// Activity metrics against hand-computed spring lengths and scripted state sequences.
#include "flexfit/flexfit.hpp"

#include <gtest/gtest.h>

using namespace flexfit;

namespace {
std::shared_ptr<const PartModel> triangle() {
    TriMesh mesh;
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    mesh.faces = {{0, 1, 2}};
    return buildPartModel(mesh);
}
}  // namespace

TEST(Activity, CountsSpringsBeyondThreshold) {
    const auto model = triangle();  // springs (0,1) L=1, (0,2) L=1, (1,2) L=sqrt 2
    std::vector<Vec3> x(model->restPositions.begin(), model->restPositions.end());
    EXPECT_EQ(countActiveSprings(*model, x, 0.01), 0u);
    x[1].x() = 1.02;  // (0,1) +0.02; (1,2) changes by about 0.014
    const double d12 = (x[1] - x[2]).norm() - std::sqrt(2.0);
    EXPECT_EQ(countActiveSprings(*model, x, 0.01), d12 > 0.01 ? 2u : 1u);
    EXPECT_EQ(countActiveSprings(*model, x, 0.05), 0u);
    x[1].x() = 0.98;  // compression counts too
    EXPECT_GE(countActiveSprings(*model, x, 0.01), 1u);
}

TEST(Activity, TrackerKeepsMaxTotalAndRestorationTime) {
    const auto model = triangle();
    ActivityTracker tracker(*model, 0.01);
    PartState state = PartState::atRest(*model);
    auto observeAt = [&](double t, Vec3 p1, Vec3 p2) {
        state.time = t;
        state.positions[1] = p1;
        state.positions[2] = p2;
        return tracker.observe(*model, state);
    };
    EXPECT_EQ(observeAt(0.1, {1.05, 0, 0}, {0, 1, 0}), 2u);   // (0,1) and (1,2)
    EXPECT_EQ(observeAt(0.2, {1, 0, 0}, {0, 1.05, 0}), 2u);   // (0,2) and (1,2)
    tracker.markRelease(0.2);
    EXPECT_FALSE(tracker.restorationTime());
    EXPECT_EQ(observeAt(0.3, {1, 0, 0}, {0, 1.005, 0}), 0u);
    EXPECT_EQ(tracker.maxActive(), 2u);
    EXPECT_EQ(tracker.totalDistinct(), 3u);
    ASSERT_TRUE(tracker.restorationTime());
    EXPECT_NEAR(*tracker.restorationTime(), 0.1, 1e-12);
    // Later activity does not change the restoration time already measured.
    observeAt(0.4, {1.2, 0, 0}, {0, 1, 0});
    EXPECT_NEAR(*tracker.restorationTime(), 0.1, 1e-12);
}

TEST(Activity, ReleaseOfAnUndeformedPartIsRestoredAtOnce) {
    const auto model = triangle();
    ActivityTracker tracker(*model, 0.1);
    tracker.observe(*model, PartState::atRest(*model));
    tracker.markRelease(1.0);
    ASSERT_TRUE(tracker.restorationTime());
    EXPECT_EQ(*tracker.restorationTime(), 0.0);
}

// A kick deforms nothing at once: the part is restored at the first quiet observation after an
// active one, never before.
TEST(Activity, AKickedPartIsRestoredOnlyAfterItWasActive) {
    const auto model = triangle();
    ActivityTracker tracker(*model, 0.01);
    PartState state = PartState::atRest(*model);
    tracker.observe(*model, state);
    tracker.markKick(0.0);
    EXPECT_FALSE(tracker.restorationTime());
    state.time = 0.1;
    tracker.observe(*model, state);  // still undeformed: not yet restored
    EXPECT_FALSE(tracker.restorationTime());
    state.time = 0.2;
    state.positions[1].x() = 1.05;
    tracker.observe(*model, state);
    EXPECT_FALSE(tracker.restorationTime());
    state.time = 0.5;
    state.positions[1].x() = 1.0;
    tracker.observe(*model, state);
    ASSERT_TRUE(tracker.restorationTime());
    EXPECT_NEAR(*tracker.restorationTime(), 0.5, 1e-12);
}

TEST(Activity, RejectsBadThreshold) {
    const auto model = triangle();
    EXPECT_THROW(ActivityTracker(*model, 0.0), InputError);
    EXPECT_THROW(ActivityTracker(*model, std::nan("")), InputError);
}

TEST(Activity, AStateOrSpringNotOfTheModelIsAnError) {
    const auto model = triangle();
    const PartState state = PartState::atRest(*model);
    ActivityTracker tracker(*model, 0.01);
    const std::vector<Vec3> two(2, Vec3::Zero());
    EXPECT_THROW((void)countActiveSprings(*model, two, 0.01), InputError);
    const Index missing[] = {0, 99999};
    EXPECT_THROW((void)tracker.observe(*model, state, missing), InputError);
    PartState small = state;
    small.positions.pop_back();
    EXPECT_THROW((void)tracker.observe(*model, small), InputError);
    const auto other = buildPartModel(makeIcoSphere(1.0, 1));
    EXPECT_THROW((void)tracker.observe(*other, PartState::atRest(*other)), InputError);  // a tracker of 3 springs
    EXPECT_EQ(tracker.observe(*model, state), 0u);
}
