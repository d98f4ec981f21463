// Collision queries and refits, Flexfit's hierarchies against FCL's (Debian's libfcl-dev) on
// the same meshes and poses, with contact generation on, in one run.
//   Scenes: two torus1 in contact, two heart-size meshes in contact, the same separated.
//   Query: all triangle-triangle contacts (FCL: OBBRSS, exhaustive contacts; Flexfit: spheres
//          and boxes, triangle-triangle test). The counter same_contacts is 1 when both report
//          exactly the same face pairs.
//   Refit after a local deformation (a zone of a few dozen faces on the heart): Flexfit refits
//          the changed leaves and their ancestors; FCL's AABB model refits in endUpdateModel.
//   Broad phase over 200 moving parts: refit against rebuild.
//   A deforming pair per step (issue 15's reference): a ball pressed into the heart while a
//          zone there deforms, 60 steps. Each step, timed: Flexfit refits the changed leaves
//          and queries the pair; FCL (OBBRSS or AABB, the same triangles) takes the part's
//          positions (beginUpdateModel / updateSubModel / endUpdateModel, bottom-up refit) and
//          collides.
//          The deformation itself is stepped untimed; same_contacts compares the face pairs of
//          the last step.
//   A tool pressed into a deforming part, as users deliver parts (issue 15's goals): Wuson, a
//          third-party mesh (Debian's assimp-testmodels, 3,732 faces, open), its vertices
//          shuffled, at 1x, 4x and 16x its faces (midpoint subdivision). A level-3 icosphere of
//          radius 4 % of the part's box diagonal is pressed 20 % of its radius into the surface
//          and slides slowly along it while a zone under it deforms, 60 steps. Timed per step:
//          the part's refit and the pair query, coherent (queryPairCoherent), full (queryPair,
//          the traversal 6d7824d made every step) and FCL AABB (endUpdateModel + collide).
//          same_contacts: the coherent query's face pairs equal the full query's at every step
//          and FCL's at the last.
#include "collision/pair_query.hpp"
#include "flexfit/flexfit.hpp"

#include <benchmark/benchmark.h>
#include <fcl/fcl.h>

#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <set>

#include "shuffled_mesh.hpp"

namespace {

using namespace flexfit;

struct Scene {
    std::string name;
    std::shared_ptr<const PartModel> a, b;
    Pose poseA, poseB;
};

const Scene& sceneByIndex(int which) {
    static const std::vector<Scene> scenes = [] {
        const auto torus = buildPartModel(makeTorus1());
        const auto heart = buildPartModel(makeHeart());
        const Pose identity;
        const Pose torusContact{Eigen::Quaterniond(Eigen::AngleAxisd(1.3, Vec3(0.3, 1.0, 0.2).normalized())), Vec3(23.3, 0.37, -0.21)};
        const Pose heartContact{Eigen::Quaterniond(Eigen::AngleAxisd(0.9, Vec3(1.0, 0.2, 0.5).normalized())), Vec3(9.0, 1.3, 0.7)};
        Pose torusApart = torusContact, heartApart = heartContact;
        torusApart.translation.x() += 6.0;
        heartApart.translation.x() += 20.0;
        return std::vector<Scene>{{"torus1 contact", torus, torus, identity, torusContact},
                                  {"heart contact", heart, heart, identity, heartContact},
                                  {"torus1 apart", torus, torus, identity, torusApart},
                                  {"heart apart", heart, heart, identity, heartApart}};
    }();
    return scenes[std::size_t(which)];
}

fcl::Transform3d toFcl(const Pose& p) {
    fcl::Transform3d t = fcl::Transform3d::Identity();
    t.linear() = p.rotation.toRotationMatrix();
    t.translation() = p.translation;
    return t;
}

template <class BV>
std::shared_ptr<fcl::BVHModel<BV>> fclModel(const PartModel& model) {
    auto m = std::make_shared<fcl::BVHModel<BV>>();
    std::vector<fcl::Vector3d> vertices(model.restPositions.begin(), model.restPositions.end());
    std::vector<fcl::Triangle> triangles;
    for (const Face& f : model.mesh.faces) triangles.emplace_back(f[0], f[1], f[2]);
    m->beginModel();
    m->addSubModel(vertices, triangles);
    m->endModel();
    return m;
}

template <class BV>
std::set<std::pair<Index, Index>> fclContacts(const Scene& s, const std::shared_ptr<fcl::BVHModel<BV>>& a, const std::shared_ptr<fcl::BVHModel<BV>>& b,
                                              std::size_t* count) {
    fcl::CollisionObjectd oa(a, toFcl(s.poseA)), ob(b, toFcl(s.poseB));
    fcl::CollisionRequestd request(1000000, true);
    fcl::CollisionResultd result;
    fcl::collide(&oa, &ob, request, result);
    std::set<std::pair<Index, Index>> pairs;
    for (std::size_t i = 0; i < result.numContacts(); ++i)
        pairs.insert({Index(result.getContact(i).b1), Index(result.getContact(i).b2)});
    *count = result.numContacts();
    return pairs;
}

std::set<std::pair<Index, Index>> ourContacts(const Part& a, const PartCollider& ca, const Part& b, const PartCollider& cb,
                                              QueryStats& stats) {
    std::vector<Contact> contacts;
    queryPair(0, a, ca, 1, b, cb, ExactTest::TriangleTriangle, contacts, stats);
    std::set<std::pair<Index, Index>> pairs;
    for (const Contact& c : contacts) pairs.insert({c.faceA, c.faceB});
    return pairs;
}

void setQueryCounters(benchmark::State& state, const std::string& label, std::size_t contacts, std::size_t volumeTests, bool same) {
    state.SetLabel(label);
    state.counters["contacts"] = double(contacts);
    state.counters["volume_tests"] = double(volumeTests);
    state.counters["same_contacts"] = same ? 1.0 : 0.0;
}

// range(0): the scene; range(1): 0 spheres, 1 boxes; range(2): the leaf group (pair_query.hpp).
void BM_FlexfitQuery(benchmark::State& state) {
    const flexfit::detail::ScopedLeafGroup group(std::size_t(state.range(2)));
    const Scene& s = sceneByIndex(int(state.range(0)));
    const auto kind = state.range(1) == 0 ? BoundingVolumeKind::Sphere : BoundingVolumeKind::Aabb;
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    Part a(s.a, rigid), b(s.b, rigid);
    a.setPose(s.poseA);
    b.setPose(s.poseB);
    const PartCollider ca(a, kind), cb(b, kind);
    QueryStats stats;
    std::vector<Contact> contacts;
    for (auto _ : state) {
        contacts.clear();
        stats = {};
        queryPair(0, a, ca, 1, b, cb, ExactTest::TriangleTriangle, contacts, stats);
        benchmark::DoNotOptimize(contacts.data());
    }
    std::size_t fclCount = 0;
    const auto fa = fclModel<fcl::OBBRSSd>(*s.a), fb = fclModel<fcl::OBBRSSd>(*s.b);
    QueryStats check;
    const bool same = ourContacts(a, ca, b, cb, check) == fclContacts(s, fa, fb, &fclCount);
    setQueryCounters(state, s.name + " / " + toString(kind) + ", leaf group " + std::to_string(state.range(2)), contacts.size(),
                     stats.volumeTests, same);
}

void BM_FclObbrssQuery(benchmark::State& state) {
    const Scene& s = sceneByIndex(int(state.range(0)));
    const auto fa = fclModel<fcl::OBBRSSd>(*s.a), fb = fclModel<fcl::OBBRSSd>(*s.b);
    fcl::CollisionObjectd oa(fa, toFcl(s.poseA)), ob(fb, toFcl(s.poseB));
    const fcl::CollisionRequestd request(1000000, true);
    std::size_t contacts = 0;
    for (auto _ : state) {
        fcl::CollisionResultd result;
        fcl::collide(&oa, &ob, request, result);
        contacts = result.numContacts();
        benchmark::DoNotOptimize(contacts);
    }
    setQueryCounters(state, s.name + " / fcl obbrss", contacts, 0, true);
}

// A zone of a few dozen faces on the heart, deformed; the refit of the changed faces.
void BM_FlexfitRefitLocal(benchmark::State& state) {
    const auto model = sceneByIndex(1).a;
    const auto kind = state.range(0) == 0 ? BoundingVolumeKind::Sphere : BoundingVolumeKind::Aabb;
    Part part(model);
    PartCollider collider(part, kind);
    part.openZone(ZoneSeed::mass(3000), 3);
    for (int i = 0; i < 50; ++i) {
        part.applyForce(3000, Vec3(0, 80.0, 0));
        part.step();
    }
    const std::vector<Index> changed(part.changedMasses().begin(), part.changedMasses().end());
    std::set<Index> faces;
    for (Index m : changed)
        for (Index f : model->topology.facesOf(m)) faces.insert(f);
    for (auto _ : state) collider.refit(part, changed);
    setQueryCounters(state, fmt::format("heart: {} moved masses and {} faces / {}", changed.size(), faces.size(), toString(kind)),
                     faces.size(), 0, true);
}

void BM_FclAabbRefit(benchmark::State& state) {
    const auto model = sceneByIndex(1).a;
    auto m = fclModel<fcl::AABBd>(*model);
    std::vector<fcl::Vector3d> vertices(model->restPositions.begin(), model->restPositions.end());
    vertices[3000].y() += 0.1;
    for (auto _ : state) {
        m->beginUpdateModel();
        m->updateSubModel(vertices);
        m->endUpdateModel(true, true);
        benchmark::DoNotOptimize(m.get());
    }
    setQueryCounters(state, "heart / fcl aabb endUpdateModel", model->faceCount(), 0, true);
}

// The deforming pair: the heart, rigid-deformable, with a zone at mass 3000 pushed outwards, and
// a ball of radius 2 pressed 0.3 into it there. Each benchmark replays the same steps.
struct DeformingPair {
    std::shared_ptr<const PartModel> heart = sceneByIndex(1).a;
    std::shared_ptr<const PartModel> ballModel = buildPartModel(makeIcoSphere(2.0, 3));
    Part part{heart}, ball{ballModel, [] {
                           PartSettings s;
                           s.mode = PartMode::Rigid;
                           return s;
                       }()};
    Vec3 push;
    static constexpr Index kMass = 3000;
    DeformingPair() {
        const Vec3 at = heart->restPositions[kMass];
        Vec3 normal = Vec3::Zero();
        for (Index f : heart->topology.facesOf(kMass)) {
            const Face& face = heart->mesh.faces[f];
            normal += (heart->restPositions[face[1]] - heart->restPositions[face[0]]).cross(heart->restPositions[face[2]] - heart->restPositions[face[0]]);
        }
        normal.normalize();
        push = 40.0 * normal;
        ball.setPose(Pose{Eigen::Quaterniond::Identity(), at + (2.0 - 0.3) * normal});
        part.openZone(ZoneSeed::mass(kMass), 3);
    }
    void deform() {
        part.applyForce(kMass, push);
        part.step();
    }
    std::vector<fcl::Vector3d> positions() const { return {part.state().positions.begin(), part.state().positions.end()}; }
};

constexpr int kDeformingSteps = 60;

// The CSV reporter needs every benchmark's counters alike: the time per step is real_time / 60.
void setPairCounters(benchmark::State& state, const std::string& label, std::size_t contacts, bool same) {
    setQueryCounters(state, label + fmt::format(" ({} steps a run)", kDeformingSteps), contacts, 0, same);
}

template <class BV>
std::set<std::pair<Index, Index>> fclPairContacts(const DeformingPair& d, const std::shared_ptr<fcl::BVHModel<BV>>& ball,
                                                  const std::shared_ptr<fcl::BVHModel<BV>>& heart, std::size_t* count) {
    const Scene s{"", d.ballModel, d.heart, d.ball.pose(), d.part.pose()};
    return fclContacts(s, ball, heart, count);
}

void BM_DeformingPairFlexfit(benchmark::State& state) {
    std::size_t contacts = 0;
    bool same = false;
    for (auto _ : state) {
        DeformingPair d;
        PartCollider heart(d.part, BoundingVolumeKind::Aabb), ball(d.ball, BoundingVolumeKind::Aabb);
        std::vector<Contact> found;
        QueryStats stats;
        double iteration = 0.0;
        for (int i = 0; i < kDeformingSteps; ++i) {
            d.deform();
            const auto start = std::chrono::steady_clock::now();
            heart.refit(d.part, d.part.changedMasses());
            found.clear();
            queryPair(0, d.ball, ball, 1, d.part, heart, ExactTest::TriangleTriangle, found, stats);
            iteration += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            d.part.clearChangedMasses();
        }
        state.SetIterationTime(iteration);
        contacts = found.size();
        std::set<std::pair<Index, Index>> ours;
        for (const Contact& c : found) ours.insert({c.faceA, c.faceB});
        const auto fb = fclModel<fcl::OBBRSSd>(*d.ballModel);
        auto fh = fclModel<fcl::OBBRSSd>(*d.heart);
        fh->beginUpdateModel();
        fh->updateSubModel(d.positions());
        fh->endUpdateModel(true, true);
        std::size_t fclCount = 0;
        same = ours == fclPairContacts(d, fb, fh, &fclCount);
    }
    setPairCounters(state, "heart deforming under a ball / flexfit aabb, local refit", contacts, same);
}

// FCL's two choices: OBBRSS (its fastest query, costly to refit) and AABB (cheap to refit).
template <class BV>
void BM_DeformingPairFcl(benchmark::State& state, const char* label) {
    std::size_t contacts = 0;
    bool same = false;
    for (auto _ : state) {
        DeformingPair d;
        const auto fb = fclModel<BV>(*d.ballModel);
        auto fh = fclModel<BV>(*d.heart);
        std::vector<fcl::Vector3d> positions;
        std::set<std::pair<Index, Index>> found;
        double iteration = 0.0;
        for (int i = 0; i < kDeformingSteps; ++i) {
            d.deform();
            positions = d.positions();  // the part's state, as a user's mesh would hand it over
            const auto start = std::chrono::steady_clock::now();
            fh->beginUpdateModel();
            fh->updateSubModel(positions);
            fh->endUpdateModel(true, true);
            std::size_t count = 0;
            found = fclPairContacts(d, fb, fh, &count);
            iteration += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            contacts = count;
        }
        state.SetIterationTime(iteration);
        // The same pair in Flexfit's hierarchies, at the last step.
        PartCollider heart(d.part, BoundingVolumeKind::Aabb), ball(d.ball, BoundingVolumeKind::Aabb);
        std::vector<Contact> ours;
        QueryStats stats;
        queryPair(0, d.ball, ball, 1, d.part, heart, ExactTest::TriangleTriangle, ours, stats);
        std::set<std::pair<Index, Index>> pairs;
        for (const Contact& c : ours) pairs.insert({c.faceA, c.faceB});
        same = pairs == found;
    }
    setPairCounters(state, label, contacts, same);
}
void BM_DeformingPairFclObbrss(benchmark::State& s) { BM_DeformingPairFcl<fcl::OBBRSSd>(s, "heart deforming under a ball / fcl obbrss, endUpdateModel + collide"); }
void BM_DeformingPairFclAabb(benchmark::State& s) { BM_DeformingPairFcl<fcl::AABBd>(s, "heart deforming under a ball / fcl aabb, endUpdateModel + collide"); }

// Each face split in four at its edges' midpoints (shared by the faces of an edge).
TriMesh subdivided(const TriMesh& mesh) {
    TriMesh out;
    out.name = mesh.name;
    out.vertices = mesh.vertices;
    std::map<std::pair<Index, Index>, Index> midpoints;
    auto midpoint = [&](Index a, Index b) {
        const auto key = std::minmax(a, b);
        const auto [it, added] = midpoints.try_emplace({key.first, key.second}, Index(out.vertices.size()));
        if (added) out.vertices.push_back(0.5 * (mesh.vertices[a] + mesh.vertices[b]));
        return it->second;
    };
    for (const Face& f : mesh.faces) {
        const Index ab = midpoint(f[0], f[1]), bc = midpoint(f[1], f[2]), ca = midpoint(f[2], f[0]);
        out.faces.push_back({f[0], ab, ca});
        out.faces.push_back({ab, f[1], bc});
        out.faces.push_back({ca, bc, f[2]});
        out.faces.push_back({ab, bc, ca});
    }
    return out;
}

const char* const kThirdPartyPart = "/usr/share/assimp/models/OFF/Wuson.off";

// Wuson subdivided `levels` times (1x, 4x, 16x the faces), vertices shuffled; null when the
// file is not installed.
std::shared_ptr<const PartModel> thirdPartyPart(int levels) {
    static std::map<int, std::shared_ptr<const PartModel>> cache;
    if (!std::filesystem::exists(kThirdPartyPart)) return nullptr;
    auto& model = cache[levels];
    if (!model) {
        TriMesh mesh = readMesh(kThirdPartyPart).mesh;
        for (int i = 0; i < levels; ++i) mesh = subdivided(mesh);
        model = buildPartModel(flexfit::testing::shuffledVertices(std::move(mesh), 7));
    }
    return model;
}

// The tool and the part, pressed together; each step pushes the zone and slides the tool.
struct ToolIntoPart {
    std::shared_ptr<const PartModel> partModel;
    std::shared_ptr<const PartModel> toolModel;
    Part part, tool;
    Index pressed = 0;
    Vec3 normal, slide, push;
    double radius = 0.0;

    explicit ToolIntoPart(std::shared_ptr<const PartModel> model)
        : partModel(std::move(model)), toolModel(buildPartModel(makeIcoSphere(toolRadius(*partModel), 3))), part(partModel),
          tool(toolModel, [] {
              PartSettings s;
              s.mode = PartMode::Rigid;
              return s;
          }()) {
        radius = toolRadius(*partModel);
        // The mass nearest the top of the part's box (a surface point the tool can reach).
        const auto& rest = partModel->restPositions;
        for (Index m = 0; m < rest.size(); ++m)
            if (!partModel->topology.facesOf(m).empty() && rest[m].y() > rest[pressed].y()) pressed = m;
        normal = Vec3::UnitY();
        slide = 0.002 * radius * Vec3::UnitX();
        push = -0.5 * normal;
        tool.setPose(Pose{Eigen::Quaterniond::Identity(), rest[pressed] + (0.8 * radius) * normal});
        part.openZone(ZoneSeed::mass(pressed), 3);
    }
    static double toolRadius(const PartModel& m) { return 0.04 * Aabb::around(m.restPositions).size(); }
    void step() {
        part.applyForce(pressed, push);
        part.step();
        tool.translate(slide);
    }
    std::vector<fcl::Vector3d> positions() const { return {part.state().positions.begin(), part.state().positions.end()}; }
};

constexpr int kToolSteps = 60;

std::set<std::pair<Index, Index>> facePairs(const std::vector<Contact>& contacts) {
    std::set<std::pair<Index, Index>> pairs;
    for (const Contact& c : contacts) pairs.insert({c.faceA, c.faceB});
    return pairs;
}

// range(0): subdivision levels (0, 1, 2); range(1): 0 coherent, 1 full, 2 FCL AABB; range(2):
// the traversal's leaf group (pair_query.hpp; 1: every node pair descended).
void BM_ToolIntoPart(benchmark::State& state) {
    const flexfit::detail::ScopedLeafGroup group(std::size_t(state.range(2)));
    const auto model = thirdPartyPart(int(state.range(0)));
    if (!model) {
        state.SkipWithError("assimp-testmodels is not installed (Debian package)");
        return;
    }
    const int method = int(state.range(1));
    std::size_t contacts = 0;
    bool same = true;
    QueryStats totals;
    for (auto _ : state) {
        ToolIntoPart t(model);
        PartCollider part(t.part, BoundingVolumeKind::Aabb), tool(t.tool, BoundingVolumeKind::Aabb);
        const auto fclTool = fclModel<fcl::AABBd>(*t.toolModel);
        auto fclPart = fclModel<fcl::AABBd>(*t.partModel);
        PairCoherence coherence;
        std::vector<Contact> found, full;
        std::set<std::pair<Index, Index>> fclFound;
        QueryStats stats;
        double seconds = 0.0;
        for (int i = 0; i < kToolSteps; ++i) {
            t.step();
            std::vector<fcl::Vector3d> positions = method == 2 ? t.positions() : std::vector<fcl::Vector3d>{};
            found.clear();
            const auto start = std::chrono::steady_clock::now();
            if (method == 2) {
                fclPart->beginUpdateModel();
                fclPart->updateSubModel(positions);
                fclPart->endUpdateModel(true, true);
                const Scene s{"", t.toolModel, t.partModel, t.tool.pose(), t.part.pose()};
                fclFound = fclContacts(s, fclTool, fclPart, &contacts);
            } else {
                part.refit(t.part, t.part.changedMasses());
                if (method == 0)
                    queryPairCoherent(0, t.tool, tool, 1, t.part, part, ExactTest::TriangleTriangle, coherence, found, stats);
                else
                    queryPair(0, t.tool, tool, 1, t.part, part, ExactTest::TriangleTriangle, found, stats);
            }
            seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            t.part.clearChangedMasses();
            if (method != 2) {
                contacts = found.size();
                full.clear();
                QueryStats ignored;
                queryPair(0, t.tool, tool, 1, t.part, part, ExactTest::TriangleTriangle, full, ignored);
                same = same && facePairs(found) == facePairs(full);
            }
        }
        state.SetIterationTime(seconds);
        totals += stats;
        if (method != 2) {
            std::size_t count = 0;
            fclPart->beginUpdateModel();
            fclPart->updateSubModel(t.positions());
            fclPart->endUpdateModel(true, true);
            const Scene s{"", t.toolModel, t.partModel, t.tool.pose(), t.part.pose()};
            same = same && facePairs(found) == fclContacts(s, fclTool, fclPart, &count);
        }
    }
    if (method != 2) {  // the query's work a step: what the exact tests and the traversal cost
        const double steps = double(state.iterations()) * kToolSteps;
        state.counters["volume_tests_a_step"] = double(totals.volumeTests) / steps;
        state.counters["exact_tests_a_step"] = double(totals.exactTests) / steps;
    }
    static const char* const kMethods[] = {"coherent", "full query", "fcl aabb, endUpdateModel + collide"};
    setPairCounters(state, fmt::format("wuson x{} ({} faces) pressed by a tool / {}{}", 1 << (2 * state.range(0)), model->faceCount(), kMethods[method],
                                       method == 2 ? "" : fmt::format(", leaf group {}", state.range(2))),
                    contacts, same);
}

// 200 parts moving every step: refit the broad-phase tree, or rebuild it.
void BM_BroadPhase(benchmark::State& state) {
    const auto model = buildPartModel(makeIcoSphere(1.0, 1));
    std::vector<std::unique_ptr<Part>> parts;
    CollisionSettings settings;
    settings.broadPhase = state.range(0) == 0 ? BroadPhaseUpdate::Refit : BroadPhaseUpdate::Rebuild;
    CollisionWorld world(settings);
    for (int i = 0; i < 200; ++i) {
        parts.push_back(std::make_unique<Part>(model));
        parts.back()->translate(Vec3(i % 10, (i / 10) % 10, i / 100) * 2.5);
        world.add(BodyId(parts.size() - 1), *parts.back());
    }
    std::size_t pairs = 0;
    double t = 0.0;
    for (auto _ : state) {
        t += 0.01;
        for (std::size_t i = 0; i < parts.size(); ++i) parts[i]->translate(Vec3(std::sin(t + double(i)), std::cos(t * 1.3 + double(i)), 0.0) * 0.01);
        world.update();
        pairs = world.candidatePairs().size();
    }
    setQueryCounters(state, settings.broadPhase == BroadPhaseUpdate::Refit ? "200 parts / refit" : "200 parts / rebuild", pairs, 0, true);
}

// A ball moving over a floor of N static boxes (rigid, 0.9 x 0.2 x 0.9 on a 1-unit grid: each
// box's sphere reaches its neighbours'), one update and narrow phase a step: range(0) N,
// range(1) 0 the boxes registered Fixed (as the world registers static rigid bodies), 1 Moving
// (as every body was before Mobility). The ball touches the boxes below it.
void BM_BallOverStaticParts(benchmark::State& state) {
    const int count = int(state.range(0));
    const Mobility mobility = state.range(1) == 0 ? Mobility::Fixed : Mobility::Moving;
    PartSettings rigid;
    rigid.mode = PartMode::Rigid;
    const auto boxModel = buildPartModel(makeBox(Vec3(0.45, 0.1, 0.45), 1));
    std::vector<std::unique_ptr<Part>> parts;
    CollisionWorld world;
    const int side = int(std::ceil(std::sqrt(double(count))));
    for (int i = 0; i < count; ++i) {
        parts.push_back(std::make_unique<Part>(boxModel, rigid));
        parts.back()->translate(Vec3(i % side, 0.0, i / side));
        world.add(BodyId(i), *parts.back(), BoundingVolumeKind::Aabb, mobility);
    }
    parts.push_back(std::make_unique<Part>(buildPartModel(makeIcoSphere(0.3, 2)), rigid));
    Part& ball = *parts.back();
    world.add(BodyId(count), ball);
    auto placeBall = [&](double t) {
        ball.setPose(Pose{Eigen::Quaterniond::Identity(), Vec3(0.5 * side + 0.3 * std::sin(t), 0.35, 0.5 * side + 0.3 * std::cos(t))});
    };
    double t = 0.0;
    for (auto _ : state) {
        placeBall(t += 0.001);
        world.update();
        benchmark::DoNotOptimize(world.narrowPhase().size());
    }
    placeBall(0.5);  // the counters at one pose, the same for both mobilities
    world.update();
    const std::size_t contacts = world.narrowPhase().size(), pairs = world.candidatePairs().size();
    state.SetLabel(fmt::format("ball over {} static boxes / {}", count, mobility == Mobility::Fixed ? "fixed" : "moving"));
    state.counters["contacts"] = double(contacts);
    state.counters["pairs"] = double(pairs);
}

BENCHMARK(BM_FlexfitQuery)->ArgsProduct({{0, 1, 2, 3}, {0, 1}, {1, 4}});
BENCHMARK(BM_BallOverStaticParts)->ArgsProduct({{100, 500, 2000}, {0, 1}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FclObbrssQuery)->Arg(0)->Arg(1)->Arg(2)->Arg(3);
BENCHMARK(BM_FlexfitRefitLocal)->Arg(0)->Arg(1);
BENCHMARK(BM_FclAabbRefit);
BENCHMARK(BM_BroadPhase)->Arg(0)->Arg(1);
BENCHMARK(BM_DeformingPairFlexfit)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(3);
BENCHMARK(BM_DeformingPairFclObbrss)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(1);
BENCHMARK(BM_DeformingPairFclAabb)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(3);
BENCHMARK(BM_ToolIntoPart)
    ->Apply([](benchmark::internal::Benchmark* b) {
        for (int level : {0, 1, 2}) {
            for (int method : {0, 1})
                for (int group : {1, 2, 4, 8}) b->Args({level, method, group});
            b->Args({level, 2, 1});
        }
    })
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond)
    ->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
