// Scene files: every error class names the file, the line and the key, and nothing is built;
// a valid scene gives exactly the values it states (checked key by key against the text).
#include "flexfit/scene_file.hpp"

#include <gtest/gtest.h>

#include <string>

using namespace flexfit;

namespace {

const char* kBall = R"(
[world]
time_step = 0.002
gravity = [0, -9.81, 0]
duration = 2.5

[[part]]
name = "mouth"
generator = "container-mouth"
mode = "rigid-deformable"
material = { stiffness = 2.0, damping = 0.3 }
restoration = "anchors"
anchor_stiffness = 10
contact_level = 3

[[part]]
name = "ball"
generator = { type = "sphere", radius = 8.5, level = 2 }
mode = "rigid"
motion = "dynamic"
density = 0.01
position = [0, 11, 0]
rotation = [0, 90, 0]

[[assembly]]
primary = "ball"
secondary = "mouth"
technique = "zone"
area = { shape = "cylinder", position = [0, -10, 0], radius = 7.5, half_height = 10 }
final_position = [0, -12, 0]

[[action]]
time = 0.5
type = "push"
part = "ball"
force = [0, -2500, 0]
duration = 1.5

[[action]]
time = 0.1
type = "grab"
part = "ball"
)";

// Parses `text` and returns the error, or "" when it parses.
std::string errorOf(const std::string& text) {
    try {
        parseScene(text, "scene.toml", ".");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

// The base scene with `line` appended to the table that starts at `after`.
std::string withLine(const std::string& after, const std::string& line) {
    std::string text = kBall;
    const auto at = text.find(after);
    text.insert(text.find('\n', at) + 1, line + "\n");
    return text;
}

}  // namespace

TEST(SceneFile, ParsesEveryValueItStates) {
    const Scene s = parseScene(kBall, "scene.toml", ".");
    EXPECT_EQ(s.world.timeStep, 0.002);
    EXPECT_EQ(s.duration, 2.5);
    ASSERT_EQ(s.parts.size(), 2u);
    EXPECT_EQ(s.parts[0].part.mode, PartMode::RigidDeformable);
    EXPECT_EQ(s.parts[0].model->stiffness[0], 2.0);
    EXPECT_EQ(s.parts[0].model->damping[0], 0.3);
    EXPECT_EQ(s.parts[0].model->massCount(), 64u * 24u);
    EXPECT_EQ(s.parts[0].part.simulation.restoration.method, RestorationMethod::AnchorSprings);
    EXPECT_EQ(s.parts[0].part.zones.contactLevel, 3);
    EXPECT_EQ(s.parts[1].body.motion, MotionType::Dynamic);
    EXPECT_EQ(s.parts[1].body.density, 0.01);
    EXPECT_EQ(s.parts[1].pose.translation, Vec3(0, 11, 0));
    // 90 degrees about y maps x to -z.
    EXPECT_LT((s.parts[1].pose.rotation * Vec3::UnitX() - Vec3(0, 0, -1)).norm(), 1e-12);
    ASSERT_EQ(s.assemblies.size(), 1u);
    EXPECT_EQ(s.assemblies[0].primary, 1u);
    EXPECT_EQ(s.assemblies[0].area.shape, AssemblyArea::Shape::Cylinder);
    EXPECT_EQ(s.assemblies[0].area.halfHeight, 10.0);
    ASSERT_EQ(s.actions.size(), 2u);
    EXPECT_EQ(s.actions[0].kind, SceneAction::Kind::Grab);  // sorted by time
    EXPECT_EQ(s.actions[1].force, Vec3(0, -2500, 0));
    EXPECT_EQ(s.actions[1].line, 32u);  // the [[action]] header
}

TEST(SceneFile, SyntaxErrorNamesTheLine) {
    EXPECT_NE(errorOf(withLine("[world]", "time_step = = 3")).find("scene.toml:3: TOML syntax"), std::string::npos)
        << errorOf(withLine("[world]", "time_step = = 3"));
}

TEST(SceneFile, UnknownKeyIsReported) {
    const std::string e = errorOf(withLine("name = \"ball\"", "densty = 2"));
    EXPECT_NE(e.find("scene.toml:18: part 2, key 'densty': unknown key"), std::string::npos) << e;
}

TEST(SceneFile, WrongTypeIsReported) {
    const std::string e = errorOf(withLine("name = \"ball\"", "vertex_mass = \"heavy\""));
    EXPECT_NE(e.find(":18: part 2, key 'vertex_mass': expected a number"), std::string::npos) << e;
}

TEST(SceneFile, OutOfRangeValueIsReported) {
    const std::string e = errorOf(withLine("name = \"ball\"", "vertex_mass = -1"));
    EXPECT_NE(e.find(":18: part 2, key 'vertex_mass': must be > 0"), std::string::npos) << e;
    const std::string level = errorOf(withLine("name = \"ball\"", "contact_level = 300"));
    EXPECT_NE(level.find("key 'contact_level': must be in [0, 255]"), std::string::npos) << level;
}

TEST(SceneFile, UnknownChoiceListsTheOptions) {
    const std::string e = errorOf(withLine("name = \"ball\"", "bounding_volume = \"capsule\""));
    EXPECT_NE(e.find(":18: part 2, key 'bounding_volume': unknown value 'capsule' (expected one of 'sphere', 'aabb')"),
              std::string::npos)
        << e;
}

TEST(SceneFile, ContactQueryIsAChoice) {
    EXPECT_EQ(parseScene(kBall, "scene.toml", ".").world.collision.rigidDeformable, RigidDeformableQuery::Faces);  // default
    const std::string text = withLine("duration = 2.5", "rigid_deformable_query = \"point-shell\"");
    EXPECT_EQ(parseScene(text, "scene.toml", ".").world.collision.rigidDeformable, RigidDeformableQuery::PointShell);
    const std::string e = errorOf(withLine("duration = 2.5", "rigid_deformable_query = \"voxels\""));
    EXPECT_NE(e.find(":6: scene.world, key 'rigid_deformable_query': unknown value 'voxels' (expected one of 'faces', 'point-shell')"),
              std::string::npos)
        << e;
}

TEST(SceneFile, VectorNeedsThreeNumbers) {
    const std::string e = errorOf(withLine("name = \"ball\"", "velocity = [1, 2]"));
    EXPECT_NE(e.find(":18: part 2, key 'velocity': expected an array of 3 numbers"), std::string::npos) << e;
}

TEST(SceneFile, MissingKeyNamesTheTable) {
    std::string text = kBall;
    text.replace(text.find("name = \"mouth\""), 14, "");
    const std::string e = errorOf(text);
    EXPECT_NE(e.find("scene.toml:7: part 1: missing key 'name'"), std::string::npos) << e;
}

TEST(SceneFile, UnknownPartReference) {
    std::string text = kBall;
    text.replace(text.find("secondary = \"mouth\""), 19, "secondary = \"mug\"");
    const std::string e = errorOf(text);
    EXPECT_NE(e.find(":27: assembly 1, key 'secondary': no part named 'mug'"), std::string::npos) << e;
}

TEST(SceneFile, DuplicatePartName) {
    std::string text = kBall;
    text.replace(text.find("name = \"ball\""), 13, "name = \"mouth\"");
    const std::string e = errorOf(text);
    EXPECT_NE(e.find(":17: part 2, key 'name': duplicate part name 'mouth'"), std::string::npos) << e;
}

TEST(SceneFile, MeshAndGeneratorAreExclusive) {
    const std::string e = errorOf(withLine("name = \"ball\"", "mesh = \"ball.tri\""));
    EXPECT_NE(e.find(":16: part 2: needs exactly one of 'mesh' and 'generator'"), std::string::npos) << e;
}

TEST(SceneFile, MissingMeshFileNamesBothFiles) {
    std::string text = kBall;
    text.replace(text.find("generator = \"container-mouth\""), 29, "mesh = \"no_such_mouth.tri\"");
    const std::string e = errorOf(text);
    EXPECT_NE(e.find("scene.toml:9: part 1, key 'mesh': "), std::string::npos) << e;
    EXPECT_NE(e.find("no_such_mouth.tri"), std::string::npos) << e;
}

TEST(SceneFile, OperatorScriptMustHoldThePart) {
    const std::string e = errorOf(std::string(kBall) + "\n[[action]]\ntime = 0.05\ntype = \"move\"\npart = \"ball\"\nposition = [0, 0, 0]\n");
    EXPECT_NE(e.find("scene.toml:44: action 'move': part 'ball' is not grabbed at that time"), std::string::npos) << e;
}

TEST(SceneFile, ActionIndicesAreChecked) {
    const std::string e =
        errorOf(std::string(kBall) + "\n[[action]]\ntime = 1\ntype = \"force\"\npart = \"ball\"\nforce = [1, 0, 0]\nfaces = [0, 100000]\n");
    EXPECT_NE(e.find(":49: action 3, key 'faces': index 100000 out of range (the part has 320)"), std::string::npos) << e;
}

TEST(SceneFile, StaticPartCannotBeGrabbed) {
    const std::string e = errorOf(std::string(kBall) + "\n[[action]]\ntime = 1\ntype = \"grab\"\npart = \"mouth\"\n");
    EXPECT_NE(e.find(":47: action 3, key 'part': a static part cannot be grabbed"), std::string::npos) << e;
}

TEST(SceneFile, EmptySceneIsRefused) {
    const std::string e = errorOf("[world]\ntime_step = 0.001\n");
    EXPECT_NE(e.find("scene.toml:1: scene: no [[part]]"), std::string::npos) << e;
}

TEST(SceneFile, UnreadableFileIsReported) {
    EXPECT_THROW(loadScene("/no/such/scene.toml"), InputError);
}

TEST(SceneFile, OldSpellingsAreReadWithAWarningNamingTheNewOne) {
    std::string text = kBall;
    text.replace(text.find("mode = \"rigid-deformable\""), std::string("mode = \"rigid-deformable\"").size(), "mode = \"zones\"");
    text.replace(text.find("restoration = \"anchors\""), std::string("restoration = \"anchors\"").size(), "restoration = \"anchor\"");
    const Scene s = parseScene(text, "scene.toml", ".");
    EXPECT_EQ(s.parts[0].part.mode, PartMode::RigidDeformable);
    EXPECT_EQ(s.parts[0].part.simulation.restoration.method, RestorationMethod::AnchorSprings);
    ASSERT_EQ(s.warnings.size(), 2u);
    EXPECT_EQ(s.warnings[0].line, 10u);
    EXPECT_EQ(s.warnings[0].message, "part 1, key 'mode': 'zones' is deprecated: write 'rigid-deformable'");
    EXPECT_EQ(s.warnings[1].line, 12u);
    EXPECT_EQ(s.warnings[1].message, "part 1, key 'restoration': 'anchor' is deprecated: write 'anchors'");
    EXPECT_TRUE(parseScene(kBall, "scene.toml", ".").warnings.empty());
}
