// The viewer's GL-free core against independent references: projection against the camera's
// own ray (round trip) and the analytic centre of the view, picking against projected
// vertices, incremental normals against a full recomputation, and the fixed-step session
// against the scene stepped directly.
#include "viewer_core.hpp"

#include "flexfit/generators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

using namespace flexfit;
using namespace flexfit::viewer;

namespace {

Scene exampleScene(const std::string& file) { return loadScene(std::string(FLEXFIT_EXAMPLES_DIR) + "/" + file); }

}  // namespace

TEST(Camera, TargetProjectsToTheCentreAndRaysUnproject) {
    Camera c;
    c.width = 1000;
    c.height = 600;
    c.target = Vec3(1, 2, 3);
    c.distance = 20;
    c.yaw = 0.7;
    c.pitch = -0.3;
    const auto centre = c.project(c.target);
    ASSERT_TRUE(centre);
    EXPECT_NEAR(centre->x(), 500.0, 1e-9);
    EXPECT_NEAR(centre->y(), 300.0, 1e-9);
    EXPECT_NEAR((c.eye() - c.target).norm(), 20.0, 1e-12);
    // Any pixel's ray passes through the points that project to that pixel.
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> px(0, 1000), py(0, 600), t(5, 40);
    for (int i = 0; i < 200; ++i) {
        const double x = px(rng), y = py(rng);
        const Camera::Ray ray = c.rayThrough(x, y);
        const auto back = c.project(ray.origin + t(rng) * ray.direction);
        ASSERT_TRUE(back);
        EXPECT_NEAR(back->x(), x, 1e-6);
        EXPECT_NEAR(back->y(), y, 1e-6);
    }
    // Up in the world is up on the screen.
    EXPECT_LT(c.project(c.target + Vec3::UnitY())->y(), 300.0);
}

TEST(Camera, DragInTheViewPlaneFollowsThePointer) {
    Camera c;
    c.width = 800;
    c.height = 800;
    const Vec3 anchor = c.target + Vec3(1, 0.5, -0.5);
    const auto before = c.project(anchor);
    const auto after = c.project(c.dragInViewPlane(anchor, 40, -25));
    EXPECT_NEAR(after->x() - before->x(), 40.0, 0.5);
    EXPECT_NEAR(after->y() - before->y(), -25.0, 0.5);
}

TEST(Picking, AClickAtAProjectedVertexSelectsThatVertex) {
    SceneRun run(exampleScene("ball_torus.toml"));
    const World& w = run.world();
    const Camera camera = initialCamera(w, 1280, 800);
    std::vector<Vec3> positions;
    int tested = 0;
    for (BodyId id = 0; id < w.bodyCount(); ++id) {
        w.part(id).worldPositions(positions);
        for (Index m = 0; m < positions.size(); m += 5) {
            const auto pixel = camera.project(positions[m]);
            if (!pixel) continue;
            // A vertex hidden behind another part, or seen edge-on, cannot be clicked: only
            // those whose own ray reaches them first count.
            const Camera::Ray ray = camera.rayThrough(pixel->x(), pixel->y());
            const auto hit = pick(w, ray);
            ASSERT_TRUE(hit);
            if (std::abs(hit->distance - (positions[m] - ray.origin).norm()) > 1e-6) continue;
            EXPECT_EQ(hit->body, id);
            EXPECT_EQ(hit->mass, m) << "part " << id;
            ++tested;
        }
    }
    EXPECT_GT(tested, 100);
    // Away from every part: nothing.
    EXPECT_FALSE(pick(w, camera.rayThrough(2, 2)));
}

TEST(SurfaceNormals, IncrementalUpdateEqualsFullRecomputationAndStaysLocal) {
    const auto model = buildPartModel(makeTorus1());
    Part part(model);
    SurfaceNormals normals(part);
    EXPECT_FALSE(normals.update(part));  // nothing moves: nothing to do
    for (int i = 0; i < 200; ++i) {
        part.applyForce(0, Vec3(1.0, 0.5, 0.0));
        part.step();
        ASSERT_TRUE(normals.update(part));
        EXPECT_LT(normals.recomputed(), model->massCount() / 4);
    }
    const std::vector<Vec3> reference = SurfaceNormals::computeAll(part);
    for (Index v = 0; v < model->massCount(); ++v) EXPECT_LT((normals.normals()[v] - reference[v]).norm(), 1e-12) << v;
    // As the viewer calls it: once a frame, about 16 steps apart, while the zone grows and shrinks.
    for (int frame = 0; frame < 40; ++frame) {
        for (int i = 0; i < 16; ++i) {
            if (frame < 20) part.applyForce(7, Vec3(0.0, -2.0, 1.0));
            part.step();
        }
        normals.update(part);
        const std::vector<Vec3> now = SurfaceNormals::computeAll(part);
        for (Index v = 0; v < model->massCount(); ++v) ASSERT_LT((normals.normals()[v] - now[v]).norm(), 1e-12) << "frame " << frame;
    }
    // After the zone retires, the last update puts the rest normals back.
    for (int i = 0; i < 200000 && !part.movingMasses().empty(); ++i) part.step();
    ASSERT_TRUE(part.movingMasses().empty());
    normals.update(part);
    const std::vector<Vec3> rest = SurfaceNormals::computeAll(part);
    for (Index v = 0; v < model->massCount(); ++v) EXPECT_LT((normals.normals()[v] - rest[v]).norm(), 1e-12) << v;
}

// A part with a drawn mesh of its own shows that mesh: its vertices at rest, unit normals
// pointing out of the sphere, each vertex in its nearest mass's colour; a plain part shows its masses.
TEST(ShowPart, ADrawnMeshIsWhatIsShown) {
    PartModelSettings settings;
    settings.drawnMesh = makeIcoSphere(1.01, 3);
    Part drawnPart(buildPartModel(makeIcoSphere(1.0, 1), settings));
    const std::size_t masses = drawnPart.model().massCount();
    std::vector<Vec3> massColours(masses);
    for (std::size_t m = 0; m < masses; ++m) massColours[m] = Vec3(double(m), 0.0, 0.0);
    ShownSurface shown;
    showPart(drawnPart, SurfaceNormals::computeAll(drawnPart), massColours, shown);
    EXPECT_EQ(shown.positions, settings.drawnMesh.vertices);
    ASSERT_EQ(shown.normals.size(), shown.positions.size());
    for (std::size_t v = 0; v < shown.positions.size(); ++v) {
        EXPECT_GT(shown.normals[v].dot(shown.positions[v].normalized()), 0.95) << v;
        // The colour names the mass: the simulated vertex nearest to the drawn one, among its face's corners.
        const Index mass = Index(shown.colours[v].x());
        EXPECT_LT((drawnPart.model().mesh.vertices[mass] - shown.positions[v]).norm(), 0.6) << v;
    }
    Part plain(buildPartModel(makeIcoSphere(1.0, 1)));
    const std::vector<Vec3> normals = SurfaceNormals::computeAll(plain);
    showPart(plain, normals, massColours, shown);
    EXPECT_EQ(shown.positions, std::vector<Vec3>(plain.state().positions.begin(), plain.state().positions.end()));
    EXPECT_EQ(shown.normals, normals);
    EXPECT_EQ(shown.colours, massColours);
}

// A model renumbered for locality shows its masses in the given mesh's order: the shuffled
// mesh's own vertices at rest, each in its own mass's colour; a material change (the viewer's
// restart) keeps the renumbering, the masses on their vertices and the drawn mesh.
TEST(ShowPart, ARenumberedModelShowsTheGivenMeshsOrder) {
    const TriMesh torus = makeTorus(3.0, 1.0, 24, 16);
    std::vector<Index> order(torus.vertices.size());
    for (std::size_t v = 0; v < order.size(); ++v) order[v] = Index(v);
    std::shuffle(order.begin(), order.end(), std::mt19937(4));
    TriMesh shuffled = torus;
    for (std::size_t v = 0; v < order.size(); ++v) shuffled.vertices[order[v]] = torus.vertices[v];
    for (Face& f : shuffled.faces)
        for (Index& v : f) v = order[v];
    PartModelSettings settings;
    settings.vertexOrder = VertexOrder::Locality;
    for (std::size_t v = 0; v < order.size(); ++v) settings.vertexMasses.push_back(1.0 + 0.001 * double(v));
    const auto model = buildPartModel(shuffled, settings);
    ASSERT_TRUE(model->renumbered());
    Part part(model);
    std::vector<Vec3> massColours(model->massCount());
    for (std::size_t m = 0; m < massColours.size(); ++m) massColours[m] = Vec3(double(m), 0.0, 0.0);
    ShownSurface shown;
    showPart(part, SurfaceNormals::computeAll(part), massColours, shown);
    EXPECT_EQ(shown.positions, shuffled.vertices);
    EXPECT_EQ(model->drawnMesh().faces, shuffled.faces);
    for (Index v = 0; v < shown.colours.size(); ++v) EXPECT_EQ(shown.colours[v].x(), double(model->massOf(v)));

    const auto restarted = withMaterial(*model, Material::superelastic());
    EXPECT_EQ(restarted->massOfVertex, model->massOfVertex);
    EXPECT_EQ(restarted->mass, model->mass);
    EXPECT_EQ(restarted->stiffness.front(), Material::superelastic().stiffness);
    EXPECT_EQ(restarted->drawnMesh().vertices, shuffled.vertices);
    PartModelSettings drawn;
    drawn.drawnMesh = makeIcoSphere(1.01, 2);
    EXPECT_EQ(withMaterial(*buildPartModel(makeIcoSphere(1.0, 1), drawn), Material::rigid())->drawnMesh().vertices, drawn.drawnMesh.vertices);
}

TEST(Session, FixedStepWhateverTheFrameTimes) {
    // Irregular frames (20-90 Hz) for 1.2 s of wall time: the world takes exactly the steps
    // that fit, and ends where the scene stepped directly ends after as many steps.
    const Scene scene = exampleScene("snap_vector.toml");
    Session session(scene);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> frame(1.0 / 90.0, 1.0 / 20.0);
    double wall = 0.0;
    while (wall < 1.2) {
        const double dt = frame(rng);
        session.advance(dt);
        wall += dt;
    }
    const double h = scene.world.timeStep;
    EXPECT_NEAR(double(session.steps()), std::floor(wall / h + 1e-6), 1.0);
    SceneRun direct(scene);
    for (std::uint64_t i = 0; i < session.steps(); ++i) direct.step();
    EXPECT_EQ(session.world().stateHash(), direct.world().stateHash());
    ASSERT_EQ(session.world().assemblyEvents().size(), direct.world().assemblyEvents().size());
    // Paused: no steps; single step: one.
    session.paused = true;
    const std::uint64_t before = session.steps();
    session.advance(0.5);
    EXPECT_EQ(session.steps(), before);
    session.singleStep();
    EXPECT_EQ(session.steps(), before + 1);
}

TEST(Session, GrabAndDragMoveTheGrabbedPointToTheTarget) {
    Scene scene = exampleScene("snap_vector.toml");
    scene.actions.clear();
    scene.assemblies.clear();
    scene.world.gravity = Vec3::Zero();
    Session session(scene);
    const BodyId ball = *scene.find("ball");
    const Vec3 point = session.world().centreOfMass(ball) + Vec3(0.1, 0.2, 0.0);
    const Vec3 offset = session.world().part(ball).pose().applyInverse(point);  // in the ball's frame
    const Vec3 target = point + Vec3(0.0, 2.0, 0.0);
    session.grab(ball, point);
    session.dragTo(target);
    session.rotateGrabbed(Vec3::UnitZ(), 0.3);  // turns about the grabbed point: it stays put
    for (int i = 0; i < 3000; ++i) session.singleStep();
    // Critically damped coupling: after 3 s the grabbed point sits at the target.
    EXPECT_LT((session.world().part(ball).pose().apply(offset) - target).norm(), 1e-3);
    const Eigen::AngleAxisd turn(session.world().part(ball).pose().rotation * scene.parts[ball].pose.rotation.conjugate());
    EXPECT_NEAR(turn.angle(), 0.3, 1e-3);
    session.release();
    EXPECT_FALSE(session.grabbed());
}

TEST(Session, KeyboardForceOnASelectionActsAsTheWorldsForceEveryStep) {
    Scene scene = exampleScene("ball_torus.toml");
    scene.actions.clear();
    for (bool onFace : {false, true}) {
        Session session(scene);
        SceneRun direct(scene);
        const Vec3 force(0.0, -3.0, 1.0);
        if (onFace)
            session.setFaceForce(0, 100, force);
        else
            session.setMassForce(0, 100, force);
        for (int i = 0; i < 150; ++i) {
            session.singleStep();
            if (onFace)
                direct.world().applyFaceForce(0, 100, force);
            else
                direct.world().applyMassForce(0, 100, force);
            direct.step();
        }
        EXPECT_FALSE(session.world().part(0).movingMasses().empty());  // the rim deforms under it
        EXPECT_EQ(session.world().stateHash(), direct.world().stateHash());
        session.clearMassForce();
        direct.step();
        session.singleStep();
        EXPECT_EQ(session.world().stateHash(), direct.world().stateHash());  // and stops with the key
    }
}
