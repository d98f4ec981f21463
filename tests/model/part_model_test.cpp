// Tests buildPartModel and materialPreset against Euclidean rest lengths computed here, the thesis's Table 4.1 presets and the settings-validation contract; and PartState::atRest sharing one model.
#include "flexfit/generators.hpp"
#include "flexfit/part_model.hpp"
#include "flexfit/part_state.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

namespace flexfit {
namespace {

static_assert(std::is_same_v<decltype(buildPartModel(std::declval<TriMesh>())), std::shared_ptr<const PartModel>>,
              "models are shared read-only");

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TriMesh tetrahedron() {
    TriMesh mesh;
    mesh.name = "tet";
    mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {0, 0, 3}};
    mesh.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
    return mesh;
}

// ---------------------------------------------------------------------------------------------
// Materials

TEST(Material, PresetsMatchThesisTable41) {
    EXPECT_EQ(Material::rigid().stiffness, 1.0);
    EXPECT_EQ(Material::rigid().damping, 0.1);
    EXPECT_EQ(Material::elastic().stiffness, 0.1);
    EXPECT_EQ(Material::elastic().damping, 0.01);
    EXPECT_EQ(Material::superelastic().stiffness, 0.01);
    EXPECT_EQ(Material::superelastic().damping, 0.001);
    // The default is the elastic preset.
    EXPECT_EQ(Material{}.stiffness, 0.1);
    EXPECT_EQ(Material{}.damping, 0.01);
}

TEST(Material, PresetByName) {
    const std::vector<std::pair<std::string, Material>> presets = {
        {"rigid", {1.0, 0.1}}, {"elastic", {0.1, 0.01}}, {"superelastic", {0.01, 0.001}}};
    for (const auto& [name, expected] : presets) {
        const std::optional<Material> m = materialPreset(name);
        ASSERT_TRUE(m.has_value()) << name;
        EXPECT_EQ(m->stiffness, expected.stiffness) << name;
        EXPECT_EQ(m->damping, expected.damping) << name;
    }
    EXPECT_FALSE(materialPreset("foo").has_value());
    EXPECT_FALSE(materialPreset("").has_value());
    EXPECT_FALSE(materialPreset("rigid ").has_value());
}

// ---------------------------------------------------------------------------------------------
// The model

TEST(PartModel, DefaultsAndRestLengths) {
    const TriMesh mesh = makeTorus1();
    const auto model = buildPartModel(mesh);
    ASSERT_NE(model, nullptr);
    EXPECT_EQ(model->name, "torus1");
    EXPECT_EQ(model->massCount(), 576u);
    EXPECT_EQ(model->springCount(), 1728u);
    EXPECT_EQ(model->faceCount(), 1152u);
    EXPECT_EQ(model->restPositions, mesh.vertices);
    EXPECT_EQ(model->mesh.vertices, mesh.vertices);
    EXPECT_EQ(model->mesh.faces, mesh.faces);
    EXPECT_EQ(model->springA, model->topology.edgeA);
    EXPECT_EQ(model->springB, model->topology.edgeB);
    ASSERT_EQ(model->restLength.size(), model->springCount());
    ASSERT_EQ(model->stiffness.size(), model->springCount());
    ASSERT_EQ(model->damping.size(), model->springCount());
    for (std::size_t e = 0; e < model->springCount(); ++e) {
        const Vec3 d = mesh.vertices[model->springA[e]] - mesh.vertices[model->springB[e]];
        const double expected = std::sqrt(d.x() * d.x() + d.y() * d.y() + d.z() * d.z());
        EXPECT_NEAR(model->restLength[e], expected, 1e-14 * expected) << "spring " << e;
        EXPECT_GT(model->restLength[e], 0.0);
        EXPECT_EQ(model->stiffness[e], 0.1);
        EXPECT_EQ(model->damping[e], 0.01);
    }
    for (std::size_t v = 0; v < model->massCount(); ++v) {
        EXPECT_EQ(model->mass[v], 1.0);
        EXPECT_EQ(model->inverseMass[v], 1.0);
    }
}

TEST(PartModel, TetrahedronRestLengthsByHand) {
    const auto model = buildPartModel(tetrahedron());
    // Edges in (a, b) order: 0-1, 0-2, 0-3, 1-2, 1-3, 2-3.
    const std::vector<double> expected = {1.0, 2.0, 3.0, std::sqrt(5.0), std::sqrt(10.0), std::sqrt(13.0)};
    ASSERT_EQ(model->restLength.size(), expected.size());
    for (std::size_t e = 0; e < expected.size(); ++e) EXPECT_DOUBLE_EQ(model->restLength[e], expected[e]) << e;
}

TEST(PartModel, UniformMassAndMaterial) {
    PartModelSettings settings;
    settings.vertexMass = 2.5;
    settings.material = Material::rigid();
    const auto model = buildPartModel(tetrahedron(), settings);
    for (std::size_t v = 0; v < model->massCount(); ++v) {
        EXPECT_EQ(model->mass[v], 2.5);
        EXPECT_EQ(model->inverseMass[v], 0.4);
    }
    for (std::size_t e = 0; e < model->springCount(); ++e) {
        EXPECT_EQ(model->stiffness[e], 1.0);
        EXPECT_EQ(model->damping[e], 0.1);
    }
    settings.material = *materialPreset("superelastic");
    const auto soft = buildPartModel(tetrahedron(), settings);
    EXPECT_EQ(soft->stiffness[3], 0.01);
    EXPECT_EQ(soft->damping[3], 0.001);
}

TEST(PartModel, PerVertexMassesAndPerSpringMaterials) {
    PartModelSettings settings;
    settings.vertexMass = 7.0;  // ignored: per-vertex masses win
    settings.vertexMasses = {1.0, 2.0, 4.0, 0.5};
    settings.material = Material::rigid();  // ignored: per-spring materials win
    for (int e = 0; e < 6; ++e) settings.springMaterials.push_back({0.5 + e, 0.25 * e});
    const auto model = buildPartModel(tetrahedron(), settings);
    EXPECT_EQ(model->mass, settings.vertexMasses);
    EXPECT_EQ(model->inverseMass, (std::vector<double>{1.0, 0.5, 0.25, 2.0}));
    for (std::size_t e = 0; e < 6; ++e) {
        EXPECT_EQ(model->stiffness[e], 0.5 + double(e)) << e;
        EXPECT_EQ(model->damping[e], 0.25 * double(e)) << e;
    }
}

TEST(PartModel, ZeroStiffnessAndDampingAreAllowed) {
    PartModelSettings settings;
    settings.material = {0.0, 0.0};
    const auto model = buildPartModel(tetrahedron(), settings);
    EXPECT_EQ(model->stiffness[0], 0.0);
    EXPECT_EQ(model->damping[0], 0.0);
}

TEST(PartModel, BadSettingsThrowInputError) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double inf = std::numeric_limits<double>::infinity();
    auto withMasses = [](std::vector<double> masses) {
        PartModelSettings s;
        s.vertexMasses = std::move(masses);
        return s;
    };
    auto withMass = [](double m) {
        PartModelSettings s;
        s.vertexMass = m;
        return s;
    };
    auto withMaterial = [](Material m) {
        PartModelSettings s;
        s.material = m;
        return s;
    };
    auto withSprings = [](std::vector<Material> springs) {
        PartModelSettings s;
        s.springMaterials = std::move(springs);
        return s;
    };
    const std::vector<std::tuple<std::string, PartModelSettings, std::string>> cases = {
        {"too few masses", withMasses({1, 1, 1}), "3 values for 4 vertices"},
        {"too many masses", withMasses({1, 1, 1, 1, 1}), "5 values for 4 vertices"},
        {"zero mass", withMasses({1, 0, 1, 1}), "mass of vertex 1"},
        {"negative mass", withMasses({1, 1, -2, 1}), "mass of vertex 2"},
        {"NaN mass", withMasses({1, 1, 1, nan}), "mass of vertex 3"},
        {"infinite mass", withMasses({inf, 1, 1, 1}), "mass of vertex 0"},
        {"zero uniform mass", withMass(0.0), "vertex mass"},
        {"negative uniform mass", withMass(-1.0), "vertex mass"},
        {"NaN uniform mass", withMass(nan), "vertex mass"},
        {"infinite uniform mass", withMass(inf), "vertex mass"},
        {"negative stiffness", withMaterial({-0.1, 0.01}), "stiffness"},
        {"NaN stiffness", withMaterial({nan, 0.01}), "stiffness"},
        {"infinite stiffness", withMaterial({inf, 0.01}), "stiffness"},
        {"negative damping", withMaterial({0.1, -0.01}), "damping"},
        {"NaN damping", withMaterial({0.1, nan}), "damping"},
        {"too few spring materials", withSprings(std::vector<Material>(5)), "5 values for 6 springs"},
        {"too many spring materials", withSprings(std::vector<Material>(7)), "7 values for 6 springs"},
        {"bad spring material", withSprings({{}, {}, {}, {}, {nan, 0.0}, {}}), "spring 4 stiffness"},
        {"bad spring damping", withSprings({{}, {0.1, -1.0}, {}, {}, {}, {}}), "spring 1 damping"},
    };
    for (const auto& [label, settings, phrase] : cases) {
        try {
            buildPartModel(tetrahedron(), settings);
            ADD_FAILURE() << label << ": accepted";
        } catch (const InputError& e) {
            EXPECT_EQ(e.source(), "part model settings") << label;
            EXPECT_TRUE(contains(e.problem(), phrase)) << label << ": " << e.problem();
        } catch (...) {
            ADD_FAILURE() << label << ": not an InputError";
        }
    }
}

// ---------------------------------------------------------------------------------------------
// One model, several states

TEST(PartModel, SharedByTwoStates) {
    const std::shared_ptr<const PartModel> model = buildPartModel(makeIcoSphere(1.0, 2));
    std::shared_ptr<const PartModel> other = model;  // a second part using the same model
    EXPECT_EQ(model.use_count(), 2);

    PartState a = PartState::atRest(*model);
    PartState b = PartState::atRest(*other);
    for (const PartState* s : {&a, &b}) {
        EXPECT_EQ(s->positions, model->restPositions);
        ASSERT_EQ(s->velocities.size(), model->massCount());
        ASSERT_EQ(s->forces.size(), model->massCount());
        for (std::size_t v = 0; v < model->massCount(); ++v) {
            EXPECT_EQ(s->velocities[v], Vec3::Zero());
            EXPECT_EQ(s->forces[v], Vec3::Zero());
        }
        EXPECT_EQ(s->time, 0.0);
        EXPECT_EQ(s->stepCount, 0u);
    }
    EXPECT_EQ(stateHash(a), stateHash(b));

    // States are independent of each other and of the model.
    const std::vector<Vec3> rest = model->restPositions;
    a.positions[3] += Vec3(0.5, 0.0, 0.0);
    a.velocities[7] = Vec3(1.0, 2.0, 3.0);
    a.time = 0.25;
    EXPECT_NE(stateHash(a), stateHash(b));
    EXPECT_EQ(b.positions, rest);
    EXPECT_EQ(model->restPositions, rest);
    EXPECT_EQ(other->restPositions, rest);
    EXPECT_EQ(PartState::atRest(*model).positions, rest);
    EXPECT_EQ(stateHash(PartState::atRest(*model)), stateHash(b));

    other.reset();
    EXPECT_EQ(model.use_count(), 1);
}

}  // namespace
}  // namespace flexfit
