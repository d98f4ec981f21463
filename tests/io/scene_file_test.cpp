// Scene files: every error class names the file, the line and the key, and nothing is built;
// a valid scene gives exactly the values it states (checked key by key against the text),
// contact materials, the contact solver's settings and the box and plate generators included.
#include "flexfit/mesh_io.hpp"
#include "flexfit/remesh.hpp"
#include "flexfit/scene_file.hpp"
#include "flexfit/scene_run.hpp"
#include "flexfit/world.hpp"
#include "mutations.hpp"
#include "temp_dir.hpp"

#include <sys/stat.h>

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <numeric>
#include <optional>
#include <random>
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
std::string errorOf(const std::string& text, const std::filesystem::path& base = ".") {
    try {
        parseScene(text, "scene.toml", base);
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
    EXPECT_EQ(s.parts[0].part.zones.reservedZones, 0);
    EXPECT_EQ(parseScene(withLine("name = \"mouth\"", "reserved_zones = 64"), "scene.toml", ".").parts[0].part.zones.reservedZones, 64);
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

TEST(SceneFile, AUTF16SceneReadsAsItsUTF8WithItsLines) {
    // What Windows tools write (PowerShell's redirection): little-endian UTF-16 after its mark.
    const auto utf16 = [](const std::string& ascii) {
        std::string out = "\xFF\xFE";
        for (const char c : ascii) out += std::string{c, '\0'};
        return out;
    };
    flexfit::testing::TempDir dir;
    const Scene s = loadScene(dir.write("scene.toml", utf16(kBall)));
    const Scene expected = parseScene(kBall, "scene.toml", dir.path());
    ASSERT_EQ(s.parts.size(), expected.parts.size());
    EXPECT_EQ(s.parts[1].pose.translation, expected.parts[1].pose.translation);
    ASSERT_EQ(s.actions.size(), 2u);
    EXPECT_EQ(s.actions[1].line, 32u);  // the file's line
    try {
        loadScene(dir.write("bad.toml", utf16(withLine("[world]", "time_step = = 3"))));
        FAIL() << "a syntax error was read";
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 3u) << e.what();
    }
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
    const std::string reserved = errorOf(withLine("name = \"ball\"", "reserved_zones = -4"));
    EXPECT_NE(reserved.find(":18: part 2, key 'reserved_zones': must be in [0, 65535]"), std::string::npos) << reserved;
}

TEST(SceneFile, UnknownChoiceListsTheOptions) {
    const std::string e = errorOf(withLine("name = \"ball\"", "bounding_volume = \"capsule\""));
    EXPECT_NE(e.find(":18: part 2, key 'bounding_volume': unknown value 'capsule' (expected one of 'sphere', 'aabb')"),
              std::string::npos)
        << e;
}

TEST(SceneFile, ContactQueryIsAChoice) {
    EXPECT_EQ(parseScene(kBall, "scene.toml", ".").world.collision.rigidDeformable, RigidDeformableQuery::Auto);  // default
    const std::string text = withLine("duration = 2.5", "rigid_deformable_query = \"point-shell\"");
    EXPECT_EQ(parseScene(text, "scene.toml", ".").world.collision.rigidDeformable, RigidDeformableQuery::PointShell);
    const std::string e = errorOf(withLine("duration = 2.5", "rigid_deformable_query = \"voxels\""));
    EXPECT_NE(e.find(":6: scene.world, key 'rigid_deformable_query': unknown value 'voxels' (expected one of 'faces', 'point-shell', 'auto')"),
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

// Names head the columns of metrics.csv: a comma, a quote or a line break would split or break
// its header, and an empty name labels nothing.
TEST(SceneFile, NamesThatWouldBreakACsvHeaderAreReported) {
    for (const std::string bad : {"\"b,all\"", "\"b\\\"all\"", "\"b\\nall\"", "\"\""}) {
        std::string text = kBall;
        text.replace(text.find("name = \"ball\""), 13, "name = " + bad);
        const std::string e = errorOf(text);
        EXPECT_NE(e.find(":17: part 2, key 'name': a name must be non-empty, on one line, with no comma or double quote"), std::string::npos)
            << bad << ": " << e;
    }
    const std::string assembly = errorOf(withLine("[[assembly]]", "name = \"snap, left\""));
    EXPECT_NE(assembly.find(":26: assembly 1, key 'name': a name must"), std::string::npos) << assembly;
}

TEST(SceneFile, DuplicateAssemblyName) {
    std::string text = withLine("[[assembly]]", "name = \"snap\"");
    text += "\n[[assembly]]\nname = \"snap\"\nprimary = \"ball\"\nsecondary = \"mouth\"\n";
    const std::string e = errorOf(text);
    EXPECT_NE(e.find("key 'name': duplicate assembly name 'snap'"), std::string::npos) << e;
}

// A vector of zero length has no direction to snap along: refused at the key that makes it so.
TEST(SceneFile, AZeroLengthAssemblyVectorIsReported) {
    const std::string e = errorOf(withLine("[[assembly]]", "primary_vector = { origin = [0, -8.5, 0], end = [0, -8.5, 0] }"));
    EXPECT_NE(e.find(":26: assembly 1.primary_vector, key 'end': the vector's origin and end coincide"), std::string::npos) << e;
    const std::string byDefault = errorOf(withLine("[[assembly]]", "secondary_vector = { origin = [0, 1, 0] }"));  // end defaults to (0, 1, 0)
    EXPECT_NE(byDefault.find("assembly 1.secondary_vector, key 'origin': the vector's origin and end coincide"), std::string::npos) << byDefault;
    EXPECT_EQ(errorOf(withLine("[[assembly]]", "primary_vector = { origin = [0, -8.5, 0], end = [0, -7.5, 0] }")), "");
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

// A static part does not move: a push or a velocity on it does nothing, which is said at its
// line (not refused: a sweep may make the part static in some of its runs).
TEST(SceneFile, APushOrAVelocityOnAStaticPartIsWarnedOf) {
    for (const std::string& action : {std::string("type = \"push\"\npart = \"mouth\"\nforce = [0, 1, 0]\n"),
                                      std::string("type = \"velocity\"\npart = \"mouth\"\nlinear = [0, 1, 0]\n")}) {
        const Scene s = parseScene(std::string(kBall) + "\n[[action]]\ntime = 1\n" + action, "scene.toml", ".");
        ASSERT_EQ(s.warnings.size(), 1u) << action;
        EXPECT_EQ(s.warnings[0].line, 47u);
        EXPECT_NE(s.warnings[0].message.find("action 3, key 'part': a static part does not move: the "), std::string::npos) << s.warnings[0].message;
    }
}

// An action at or after the scene's end never runs in it: said, at its line, not refused (a
// longer run, --duration, reaches it).
TEST(SceneFile, AnActionAfterTheEndIsWarnedOf) {
    const Scene s = parseScene(std::string(kBall) + "\n[[action]]\ntime = 2.5\ntype = \"release\"\npart = \"ball\"\n", "scene.toml", ".");
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_EQ(s.warnings[0].line, 45u);
    EXPECT_EQ(s.warnings[0].message, "action 3, key 'time': at or after the scene's duration (2.5 s): the action runs only in a longer run");
    EXPECT_TRUE(parseScene(kBall, "scene.toml", ".").warnings.empty());
}

TEST(SceneFile, ADensityWithNoFiniteMassIsReportedAtItsLine) {
    std::string text = kBall;
    text.replace(text.find("density = 0.01"), 14, "density = 1e300");
    const std::string e = errorOf(text);
    EXPECT_NE(e.find(":21: part 2, key 'density': density 1e+300 x the volume"), std::string::npos) << e;
}

TEST(SceneFile, AnEmptyMeshPathAndAnOverlongUnknownKeyAreReportedPlainly) {
    std::string text = kBall;
    const std::string generator = "generator = { type = \"sphere\", radius = 8.5, level = 2 }";
    text.replace(text.find(generator), generator.size(), "mesh = \"\"");
    const std::string empty = errorOf(text);
    EXPECT_NE(empty.find(":18: part 2, key 'mesh': an empty path"), std::string::npos) << empty;
    const std::string key(5000, 'k');
    const std::string unknown = errorOf(withLine("name = \"ball\"", key + " = 1"));
    EXPECT_NE(unknown.find("key '" + key.substr(0, 77) + "...': unknown key"), std::string::npos) << unknown.substr(0, 300);
    EXPECT_LT(unknown.size(), 300u);
}

TEST(SceneFile, APositionBeyondAMeshsCoordinatesIsReported) {
    std::string text = kBall;
    text.replace(text.find("position = [0, 11, 0]"), 21, "position = [0, 1e300, 0]");
    const std::string e = errorOf(text);
    EXPECT_NE(e.find(":22: part 2, key 'position': a coordinate beyond 1e+20 units"), std::string::npos) << e;
    text = kBall;
    text.replace(text.find("position = [0, 11, 0]"), 21, "position = [0, 1e19, 0]");
    EXPECT_EQ(errorOf(text), "");
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

// The restoration constraint's default fraction is per step (chosen for 1 ms): a deforming
// part that takes it at another time step is warned of, at its restoration line or its table,
// with the factors (1 ms / h and its square); a fraction or rate the scene gives, anchors, a
// rigid part or a 1 ms step are not.
TEST(SceneFile, TheDefaultPerStepRestorationAtAnotherTimeStepIsWarnedOf) {
    const auto scene = [](const std::string& world, const std::string& part) {
        return parseScene("[world]\n" + world + "\n[[part]]\nname = \"torus\"\n"
                          "generator = { type = \"torus\", major = 10, minor = 2.5, u = 12, v = 8 }\n" + part,
                          "scene.toml", ".");
    };
    const Scene fast = scene("time_step = 0.0002", "");
    ASSERT_EQ(fast.warnings.size(), 1u);
    EXPECT_EQ(fast.warnings[0].line, 3u);
    EXPECT_EQ(fast.warnings[0].message,
              "part 1: the restoration constraint's default fraction 0.001 is per step, chosen for 1 ms steps: at time_step = 0.0002 "
              "the part restores 5 times as fast and resists loads about 25 times as stiffly; constraint_rate = 0.5 (1/s) keeps the "
              "restoration time, restoration = \"anchors\" a stiffness independent of the step");
    const Scene slow = scene("time_step = 0.002", "mode = \"full-deformable\"\nrestoration = \"constraint\"\n");
    ASSERT_EQ(slow.warnings.size(), 1u);
    EXPECT_EQ(slow.warnings[0].line, 7u);
    EXPECT_NE(slow.warnings[0].message.find("restores 0.5 times as fast and resists loads about 0.25 times"), std::string::npos);
    for (const std::string& chosen : {std::string("constraint_fraction = 0.001\n"), std::string("constraint_rate = 0.5\n"),
                                      std::string("restoration = \"anchors\"\n"), std::string("mode = \"rigid\"\n")})
        EXPECT_TRUE(scene("time_step = 0.0002", chosen).warnings.empty()) << chosen;
    EXPECT_TRUE(scene("time_step = 0.001", "").warnings.empty());
}

// --- Contact materials, the contact solver's settings and the box and plate generators. ---

namespace {

// `text` with `line` inserted after the line holding `after`.
std::string insertedAfter(std::string text, const std::string& after, const std::string& line) {
    text.insert(text.find('\n', text.find(after)) + 1, line + "\n");
    return text;
}

// `text` with `from` (which it holds) replaced by `to`.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
    text.replace(text.find(from), from.size(), to);
    return text;
}

const std::string kSphere = "generator = { type = \"sphere\", radius = 8.5, level = 2 }";  // the ball's, line 18
const std::string kMouth = "generator = \"container-mouth\"";                              // the mouth's, line 9

std::string withBallGenerator(const std::string& generator) { return replaced(kBall, kSphere, generator); }
std::string withMouthGenerator(const std::string& generator) { return replaced(kBall, kMouth, generator); }

Eigen::AlignedBox3d boundsOf(const TriMesh& mesh) {
    Eigen::AlignedBox3d b;
    for (const Vec3& v : mesh.vertices) b.extend(v);
    return b;
}

}  // namespace

TEST(SceneFile, ParsesContactMaterialsAndSolverSettings) {
    const std::string text = insertedAfter(withLine("duration = 2.5", "contact_slop = 0.02\ncontact_damping = 0.5"), "name = \"ball\"",
                                           "static_friction = 0.6\nkinetic_friction = 0.4\nrestitution = 0.3");
    const Scene s = parseScene(text, "scene.toml", ".");
    EXPECT_EQ(s.world.contactSlop, 0.02);
    EXPECT_EQ(s.world.contactDamping, 0.5);
    EXPECT_EQ(s.parts[1].body.staticFriction, 0.6);
    EXPECT_EQ(s.parts[1].body.kineticFriction, 0.4);
    EXPECT_EQ(s.parts[1].body.restitution, 0.3);
    // Left out: frictionless, inelastic, the world's defaults.
    EXPECT_EQ(s.parts[0].body.staticFriction, 0.0);
    EXPECT_EQ(s.parts[0].body.kineticFriction, 0.0);
    EXPECT_EQ(s.parts[0].body.restitution, 0.0);
    const Scene plain = parseScene(kBall, "scene.toml", ".");
    EXPECT_EQ(plain.world.contactSlop, WorldSettings{}.contactSlop);
    EXPECT_EQ(plain.world.contactDamping, WorldSettings{}.contactDamping);
    // The limits themselves are valid: mu_k = mu_s, restitution 1, slop 1, no damping.
    const std::string limits = withLine("duration = 2.5", "contact_slop = 1\ncontact_damping = 0");
    EXPECT_EQ(errorOf(limits), "");
    EXPECT_EQ(errorOf(withLine("name = \"ball\"", "static_friction = 0.5\nkinetic_friction = 0.5\nrestitution = 1")), "");
}

TEST(SceneFile, KineticFrictionDefaultsToTheStaticOne) {
    const Scene s = parseScene(withLine("name = \"ball\"", "static_friction = 0.7"), "scene.toml", ".");
    EXPECT_EQ(s.parts[1].body.staticFriction, 0.7);
    EXPECT_EQ(s.parts[1].body.kineticFriction, 0.7);
}

TEST(SceneFile, KineticFrictionAboveTheStaticOneIsReported) {
    const std::string e = errorOf(withLine("name = \"ball\"", "static_friction = 0.3\nkinetic_friction = 0.5"));
    EXPECT_NE(e.find("scene.toml:19: part 2, key 'kinetic_friction': must not exceed static_friction"), std::string::npos) << e;
    // A kinetic coefficient alone exceeds the static one's default, 0.
    const std::string alone = errorOf(withLine("name = \"ball\"", "kinetic_friction = 0.2"));
    EXPECT_NE(alone.find(":18: part 2, key 'kinetic_friction': must not exceed static_friction"), std::string::npos) << alone;
}

TEST(SceneFile, NegativeFrictionIsReported) {
    const std::string e = errorOf(withLine("name = \"ball\"", "static_friction = -0.1"));
    EXPECT_NE(e.find("scene.toml:18: part 2, key 'static_friction': must be >= 0"), std::string::npos) << e;
    const std::string kinetic = errorOf(withLine("name = \"ball\"", "static_friction = 0.5\nkinetic_friction = -0.1"));
    EXPECT_NE(kinetic.find("scene.toml:19: part 2, key 'kinetic_friction': must be >= 0"), std::string::npos) << kinetic;
}

TEST(SceneFile, RestitutionAboveOneIsReported) {
    const std::string e = errorOf(withLine("name = \"ball\"", "restitution = 1.5"));
    EXPECT_NE(e.find("scene.toml:18: part 2, key 'restitution': must be in [0, 1]"), std::string::npos) << e;
    const std::string negative = errorOf(withLine("name = \"ball\"", "restitution = -0.5"));
    EXPECT_NE(negative.find(":18: part 2, key 'restitution': must be >= 0"), std::string::npos) << negative;
}

TEST(SceneFile, ContactSlopAndDampingOutOfRangeAreReported) {
    const std::string e = errorOf(withLine("duration = 2.5", "contact_slop = 1.5"));
    EXPECT_NE(e.find("scene.toml:6: scene.world, key 'contact_slop': must be in (0, 1]"), std::string::npos) << e;
    const std::string zero = errorOf(withLine("duration = 2.5", "contact_slop = 0"));
    EXPECT_NE(zero.find(":6: scene.world, key 'contact_slop': must be > 0"), std::string::npos) << zero;
    const std::string damping = errorOf(withLine("duration = 2.5", "contact_damping = -1"));
    EXPECT_NE(damping.find(":6: scene.world, key 'contact_damping': must be >= 0"), std::string::npos) << damping;
}

TEST(SceneFile, RunsOfNoStepOrOfTooManyStepsAreReported) {
    // A time step of 1e-300 s had hung the run (duration / time_step rounded past any integer);
    // one longer than the duration had run no step and exited as a success.
    const auto withTimeStep = [](const std::string& value) { return replaced(kBall, "time_step = 0.002", "time_step = " + value); };
    const std::string tiny = errorOf(withTimeStep("1e-300"));
    EXPECT_NE(tiny.find("scene.toml:3: scene.world, key 'time_step': the duration 2.5 s at the time step 1e-300 s is 2.5e+300 steps, more than 1e+10"),
              std::string::npos) << tiny;
    const std::string longer = errorOf(withTimeStep("6"));
    EXPECT_NE(longer.find(":3: scene.world, key 'time_step': the duration 2.5 s is shorter than half the time step 6 s"), std::string::npos)
        << longer;
    EXPECT_EQ(errorOf(withTimeStep("2.5")), "");  // one step
    // At a usual time step the duration is what is off, and its line is named.
    const auto withDuration = [](const std::string& value) { return replaced(kBall, "duration = 2.5", "duration = " + value); };
    const std::string endless = errorOf(withDuration("1e300"));
    EXPECT_NE(endless.find("scene.toml:5: scene.world, key 'duration': the duration 1e+300 s at the time step 0.002 s"), std::string::npos)
        << endless;
    const std::string instant = errorOf(withDuration("1e-9"));
    EXPECT_NE(instant.find("scene.toml:5: scene.world, key 'duration': the duration 1e-09 s is shorter than half the time step"), std::string::npos)
        << instant;
    EXPECT_FALSE(stepCountProblem(1e10 * 1e-3, 1e-3).has_value());
    EXPECT_TRUE(stepCountProblem(1.01e10 * 1e-3, 1e-3).has_value());
}

TEST(SceneFile, AGeneratedTorusOfMoreThan2048x2048VerticesIsReported) {
    const std::string e = errorOf(withMouthGenerator("generator = { type = \"torus\", major = 10, minor = 2.5, u = 4096, v = 2048 }"));
    EXPECT_NE(e.find("key 'u': u x v = 8388608 vertices: at most 4194304 (2048 x 2048)"), std::string::npos) << e;
}

// A generator's parameters it takes but Flexfit cannot compute with (validateMesh's scale
// bounds) are refused at the generator's table, as a mesh file's would be.
TEST(SceneFile, AGeneratedMeshBeyondTheScaleBoundsIsReported) {
    const std::string big = errorOf(withMouthGenerator("generator = { type = \"sphere\", radius = 1e30 }"));
    EXPECT_NE(big.find("beyond the 1e+20 units Flexfit computes with"), std::string::npos) << big;
    EXPECT_NE(big.find("scene.toml:"), std::string::npos) << big;
    const std::string small = errorOf(withMouthGenerator("generator = { type = \"box\", half_extents = [1e-30, 1e-30, 1e-30] }"));
    EXPECT_NE(small.find("below the 1e-20 units"), std::string::npos) << small;
    EXPECT_EQ(errorOf(withMouthGenerator("generator = { type = \"sphere\", radius = 1e15 }")), "");
}

TEST(SceneFile, AGrabsDampingGivenMustNotBeNegative) {
    // Left out it is critical (GrabSettings' -1); a negative one given had silently meant the same.
    const auto grabOf = [](const Scene& scene) {
        for (const SceneAction& a : scene.actions)
            if (a.kind == SceneAction::Kind::Grab) return a.grab;
        ADD_FAILURE() << "no grab";
        return GrabSettings{};
    };
    EXPECT_EQ(grabOf(parseScene(kBall, "scene.toml", ".")).damping, -1.0);
    for (const char* key : {"damping", "angular_damping"}) {
        const std::string e = errorOf(withLine("type = \"grab\"", std::string(key) + " = -1e6"));
        EXPECT_NE(e.find("key '" + std::string(key) + "': must be >= 0"), std::string::npos) << e;
    }
    EXPECT_EQ(grabOf(parseScene(withLine("type = \"grab\"", "damping = 0"), "scene.toml", ".")).damping, 0.0);
}

TEST(SceneFile, BoxAndPlateGeneratorsGiveTheShapesTheyState) {
    const std::string text = replaced(withMouthGenerator("generator = { type = \"plate\", half_extents = [3, 0.5, 4], hole_x = 1, hole_z = 2 }"),
                                      kSphere, "generator = { type = \"box\", half_extents = [0.5, 1, 2], divisions = 3 }");
    const Scene s = parseScene(text, "scene.toml", ".");
    const TriMesh& plate = s.parts[0].model->mesh;
    EXPECT_EQ(plate.vertices.size(), 16u);
    EXPECT_EQ(plate.faces.size(), 32u);
    EXPECT_EQ(boundsOf(plate).max(), Vec3(3, 0.5, 4));
    EXPECT_EQ(boundsOf(plate).min(), Vec3(-3, -0.5, -4));
    // The hole's corners: (+-1, +-0.5, +-2).
    std::size_t holeCorners = 0;
    for (const Vec3& v : plate.vertices) holeCorners += std::abs(v.x()) == 1.0 && std::abs(v.z()) == 2.0;
    EXPECT_EQ(holeCorners, 8u);
    const TriMesh& ball = s.parts[1].model->mesh;
    EXPECT_EQ(ball.vertices.size(), 6u * 3u * 3u + 2u);  // 6 d^2 + 2
    EXPECT_EQ(boundsOf(ball).max(), Vec3(0.5, 1, 2));
    EXPECT_EQ(boundsOf(ball).min(), Vec3(-0.5, -1, -2));
    // Defaults: a unit box of one quad per face; a 4 x 1 x 4 plate with a hole half its size.
    const Scene d = parseScene(withBallGenerator("generator = { type = \"box\" }"), "scene.toml", ".");
    EXPECT_EQ(d.parts[1].model->mesh.vertices.size(), 8u);
    EXPECT_EQ(boundsOf(d.parts[1].model->mesh).max(), Vec3(1, 1, 1));
    const Scene p = parseScene(withMouthGenerator("generator = { type = \"plate\" }"), "scene.toml", ".");
    EXPECT_EQ(boundsOf(p.parts[0].model->mesh).max(), Vec3(2, 0.5, 2));
    holeCorners = 0;
    for (const Vec3& v : p.parts[0].model->mesh.vertices) holeCorners += std::abs(v.x()) == 1.0 && std::abs(v.z()) == 1.0;
    EXPECT_EQ(holeCorners, 8u);
}

TEST(SceneFile, BadBoxHalfExtentsAreReported) {
    const std::string zero = errorOf(withBallGenerator("generator = { type = \"box\", half_extents = [1, 0, 1] }"));
    EXPECT_NE(zero.find("scene.toml:18: part 2.generator, key 'half_extents': must be > 0"), std::string::npos) << zero;
    const std::string negative = errorOf(withBallGenerator("generator = { type = \"box\", half_extents = [1, 1, -2] }"));
    EXPECT_NE(negative.find(":18: part 2.generator, key 'half_extents': must be > 0"), std::string::npos) << negative;
    const std::string two = errorOf(withBallGenerator("generator = { type = \"box\", half_extents = [1, 1] }"));
    EXPECT_NE(two.find(":18: part 2.generator, key 'half_extents': expected an array of 3 numbers"), std::string::npos) << two;
    const std::string divisions = errorOf(withBallGenerator("generator = { type = \"box\", divisions = 0 }"));
    EXPECT_NE(divisions.find(":18: part 2.generator, key 'divisions': must be in [1, 256]"), std::string::npos) << divisions;
    const std::string unknown = errorOf(withBallGenerator("generator = { type = \"box\", half_extent = [1, 1, 1] }"));
    EXPECT_NE(unknown.find(":18: part 2.generator, key 'half_extent': unknown key"), std::string::npos) << unknown;
}

TEST(SceneFile, PlateHoleLargerThanThePlateIsReported) {
    const std::string x = errorOf(withMouthGenerator("generator = { type = \"plate\", half_extents = [2, 0.5, 2], hole_x = 2.5 }"));
    EXPECT_NE(x.find("scene.toml:9: part 1.generator, key 'hole_x': must be smaller than the plate's half extent along x"),
              std::string::npos)
        << x;
    // As wide as the plate leaves no wall: refused too.
    const std::string z = errorOf(withMouthGenerator("generator = { type = \"plate\", half_extents = [2, 0.5, 2], hole_z = 2 }"));
    EXPECT_NE(z.find("scene.toml:9: part 1.generator, key 'hole_z': must be smaller than the plate's half extent along z"),
              std::string::npos)
        << z;
    const std::string half = errorOf(withMouthGenerator("generator = { type = \"plate\", half_extents = [2, 0, 2] }"));
    EXPECT_NE(half.find("scene.toml:9: part 1.generator, key 'half_extents': must be > 0"), std::string::npos) << half;
    const std::string hole = errorOf(withMouthGenerator("generator = { type = \"plate\", hole_x = -1 }"));
    EXPECT_NE(hole.find("scene.toml:9: part 1.generator, key 'hole_x': must be > 0"), std::string::npos) << hole;
}

TEST(SceneFile, CoherentCollisionIsAFlag) {
    EXPECT_TRUE(parseScene(kBall, "scene.toml", ".").world.collision.coherent);  // default
    EXPECT_FALSE(parseScene(withLine("duration = 2.5", "coherent_collision = false"), "scene.toml", ".").world.collision.coherent);
    const std::string e = errorOf(withLine("duration = 2.5", "coherent_collision = \"no\""));
    EXPECT_NE(e.find(":6: scene.world, key 'coherent_collision': expected true or false"), std::string::npos) << e;
}

// A part's mesh file with a duplicate face: repaired with a warning at the mesh key's line,
// refused with the mesh file's line by `repair = false` or SceneReadOptions::strictMeshes.
TEST(SceneFile, MeshDefectsAreRepairedWithAWarningOrRefused) {
    flexfit::testing::TempDir dir;
    // A tetrahedron and a copy of its face 0 (line 7) on line 11.
    dir.write("tet.tri", "tet\n4 5\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 2 1\n0 1 3\n0 3 2\n1 2 3\n1 0 2\n");
    const std::string part = "[[part]]\nname = \"tet\"\nmesh = \"tet.tri\"\n";
    const Scene repaired = parseScene(part, "scene.toml", dir.path());
    ASSERT_EQ(repaired.warnings.size(), 1u);
    EXPECT_EQ(repaired.warnings[0].line, 3u);
    EXPECT_NE(repaired.warnings[0].message.find("part 1, key 'mesh': "), std::string::npos) << repaired.warnings[0].message;
    EXPECT_NE(repaired.warnings[0].message.find("1 duplicate face"), std::string::npos) << repaired.warnings[0].message;
    EXPECT_EQ(repaired.parts[0].model->faceCount(), 4u);

    for (const auto& [text, options] : {std::pair{part + "repair = false\n", SceneReadOptions{}}, std::pair{part, SceneReadOptions{true, std::nullopt}}}) {
        try {
            parseScene(text, "scene.toml", dir.path(), options);
            ADD_FAILURE() << "accepted a duplicate face: " << text;
        } catch (const InputError& e) {
            EXPECT_EQ(e.line(), 3u);
            EXPECT_NE(std::string(e.what()).find("tet.tri:11: face 4 (1 0 2) duplicates face 0 (line 7)"), std::string::npos) << e.what();
        }
    }
}

TEST(SceneFile, RepairAppliesOnlyToMeshFiles) {
    const std::string e = errorOf(withLine("name = \"ball\"", "repair = false"));
    EXPECT_NE(e.find("key 'repair': applies only to a part read from a 'mesh' file"), std::string::npos) << e;
}

// `remesh` on a part read from a file: the model is the remeshed surface (CGAL, remesh.hpp).
TEST(SceneFile, RemeshGivesTheModelNearUniformEdges) {
    flexfit::testing::TempDir dir;
    dir.write("tet.tri", "tet\n4 4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 2 1\n0 1 3\n0 3 2\n1 2 3\n");
    const std::string part = "[[part]]\nname = \"tet\"\nmesh = \"tet.tri\"\n";
    const Scene plain = parseScene(part, "scene.toml", dir.path());
    EXPECT_EQ(plain.parts[0].model->faceCount(), 4u);
    for (const std::string& remesh : {std::string("remesh = 0.1\n"), std::string("remesh = { edge = 0.1, iterations = 3, feature_angle = 30 }\n")}) {
        const Scene scene = parseScene(part + remesh, "scene.toml", dir.path());
        const PartModel& model = *scene.parts[0].model;
        EXPECT_GT(model.faceCount(), 300u) << remesh;
        const double meanLength = std::accumulate(model.restLength.begin(), model.restLength.end(), 0.0) / double(model.springCount());
        EXPECT_NEAR(meanLength, 0.1, 0.03) << remesh;
        // Drawn as the file's tetrahedron (draw = "original" is the default).
        ASSERT_TRUE(model.drawn) << remesh;
        EXPECT_EQ(model.drawnMesh().vertices, plain.parts[0].model->mesh.vertices) << remesh;
        EXPECT_EQ(model.drawnMesh().faces, plain.parts[0].model->mesh.faces) << remesh;
    }
    const Scene simulationDrawn = parseScene(part + "remesh = 0.1\ndraw = \"simulation\"\n", "scene.toml", dir.path());
    EXPECT_FALSE(simulationDrawn.parts[0].model->drawn);
    const Scene drawnOnly = parseScene(part + "draw = \"original\"\n", "scene.toml", dir.path());
    ASSERT_EQ(drawnOnly.warnings.size(), 1u);
    EXPECT_NE(drawnOnly.warnings[0].message.find("key 'draw': has no effect without 'remesh'"), std::string::npos);
    EXPECT_GT(simulationDrawn.parts[0].model->drawnMesh().faces.size(), 300u);
    auto error = [&](const std::string& extra) { return errorOf(part + extra, dir.path()); };
    EXPECT_NE(error("remesh = 0.1\ndraw = \"both\"\n").find("scene.toml:5: part 1, key 'draw': unknown value 'both'"), std::string::npos)
        << error("remesh = 0.1\ndraw = \"both\"\n");
    EXPECT_NE(errorOf(withLine("name = \"ball\"", "draw = \"original\"")).find("key 'draw': applies only to a part read from a 'mesh' file"),
              std::string::npos);
    EXPECT_NE(error("remesh = -0.1\n").find("scene.toml:4: part 1, key 'remesh': must be > 0"), std::string::npos) << error("remesh = -0.1\n");
    EXPECT_NE(error("remesh = { iterations = 3 }\n").find("needs 'edge'"), std::string::npos) << error("remesh = { iterations = 3 }\n");
    EXPECT_NE(error("remesh = { edge = 0.1, angle = 3 }\n").find("key 'angle': unknown key"), std::string::npos)
        << error("remesh = { edge = 0.1, angle = 3 }\n");
    EXPECT_NE(error("remesh = 1e-6\n").find("key 'remesh': remesh: the target edge length 1e-06 is below 1e-4"), std::string::npos)
        << error("remesh = 1e-6\n");
    EXPECT_NE(errorOf(withLine("name = \"ball\"", "remesh = 0.5")).find("key 'remesh': applies only to a part read from a 'mesh' file"),
              std::string::npos);
}

// A remeshed part's surface goes through the remesh cache (remesh_cache.hpp): the second load
// reads the file the first wrote (the file is not written again: same inode) and builds the
// same model; `cache = false` and an empty directory write nothing; a directory that cannot be
// written is a warning at the remesh key's line, and the part is still remeshed.
TEST(SceneFile, RemeshedPartsGoThroughTheRemeshCache) {
    flexfit::testing::TempDir dir;
    dir.write("tet.tri", "tet\n4 4\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n0 2 1\n0 1 3\n0 3 2\n1 2 3\n");
    const std::string part = "[[part]]\nname = \"tet\"\nmesh = \"tet.tri\"\n";
    SceneReadOptions options;
    options.remeshCache = dir.path() / "cache";
    const auto cacheFiles = [&] {
        std::vector<std::filesystem::path> files;
        if (std::filesystem::exists(*options.remeshCache))
            for (const auto& entry : std::filesystem::directory_iterator(*options.remeshCache)) files.push_back(entry.path());
        return files;
    };
    const Scene first = parseScene(part + "remesh = 0.2\n", "scene.toml", dir.path(), options);
    ASSERT_EQ(cacheFiles().size(), 1u);
    struct stat before {};
    ASSERT_EQ(::stat(cacheFiles()[0].c_str(), &before), 0);
    const Scene second = parseScene(part + "remesh = 0.2\n", "scene.toml", dir.path(), options);
    struct stat after {};
    ASSERT_EQ(::stat(cacheFiles()[0].c_str(), &after), 0);
    EXPECT_EQ(before.st_ino, after.st_ino);
    EXPECT_TRUE(first.warnings.empty() && second.warnings.empty());
    EXPECT_EQ(second.parts[0].model->mesh.vertices, first.parts[0].model->mesh.vertices);
    EXPECT_EQ(second.parts[0].model->mesh.faces, first.parts[0].model->mesh.faces);
    const Scene uncached = parseScene(part + "remesh = { edge = 0.25, cache = false }\n", "scene.toml", dir.path(), options);
    EXPECT_EQ(cacheFiles().size(), 1u);
    options.remeshCache = std::filesystem::path();
    const Scene off = parseScene(part + "remesh = 0.25\n", "scene.toml", dir.path(), options);
    EXPECT_EQ(off.parts[0].model->mesh.vertices, uncached.parts[0].model->mesh.vertices);
    options.remeshCache = dir.path() / "tet.tri" / "cache";
    const Scene unwritable = parseScene(part + "remesh = 0.2\n", "scene.toml", dir.path(), options);
    ASSERT_EQ(unwritable.warnings.size(), 1u);
    EXPECT_EQ(unwritable.warnings[0].line, 4u);
    EXPECT_NE(unwritable.warnings[0].message.find("part 1, key 'remesh': could not create the remesh cache directory"), std::string::npos)
        << unwritable.warnings[0].message;
    EXPECT_EQ(unwritable.parts[0].model->mesh.vertices, first.parts[0].model->mesh.vertices);
}

// `thin_features` in the remesh table: the part's model is the surface remeshForSimulation makes
// with that choice (a chamfer narrower than half the edge: kept, or rounded).
TEST(SceneFile, RemeshThinFeaturesChoosesTheSurface) {
    const std::filesystem::path data = FLEXFIT_TEST_DATA_DIR;  // chamfered_box.obj: the CLI tests' box
    const TriMesh file = readMesh(data / "chamfered_box.obj").mesh;
    const std::string part = "[[part]]\nname = \"box\"\nmesh = \"chamfered_box.obj\"\n";
    std::vector<std::size_t> faces;
    for (const auto& [key, choice] : {std::pair{"keep", ThinFeatures::Keep}, std::pair{"round", ThinFeatures::Round}}) {
        const Scene scene = parseScene(part + "remesh = { edge = 0.25, thin_features = \"" + key + "\" }\n", "scene.toml", data);
        const TriMesh expected = remeshForSimulation(file, {.targetEdge = 0.25, .thinFeatures = choice}, "chamfered_box.obj").mesh;
        // The model renumbers the vertices for locality: the same surface, compared by its counts.
        EXPECT_EQ(scene.parts[0].model->mesh.faces.size(), expected.faces.size()) << key;
        EXPECT_EQ(scene.parts[0].model->mesh.vertices.size(), expected.vertices.size()) << key;
        faces.push_back(expected.faces.size());
    }
    EXPECT_NE(faces[0], faces[1]);  // the two surfaces differ
    const std::string bad = errorOf(part + "remesh = { edge = 0.25, thin_features = \"never\" }\n", data);
    EXPECT_NE(bad.find("scene.toml:4: part 1.remesh, key 'thin_features': unknown value 'never' (expected 'auto', 'keep' or 'round')"), std::string::npos) << bad;
}

TEST(SceneFile, ImplicitIntegratorAndItsSolve) {
    const Scene s = parseScene(withLine("name = \"mouth\"", "integrator = \"implicit\"\nimplicit_iterations = 12\nimplicit_tolerance = 0"),
                               "scene.toml", ".");
    const SimulationSettings& sim = s.parts[0].part.simulation;
    EXPECT_EQ(sim.integrator, Integrator::ImplicitEuler);
    EXPECT_EQ(sim.implicit.maxIterations, 12);
    EXPECT_EQ(sim.implicit.tolerance, 0.0);
    const std::string zero = errorOf(withLine("name = \"mouth\"", "implicit_iterations = 0"));
    EXPECT_NE(zero.find(":9: part 1, key 'implicit_iterations': must be in [1, 100000]"), std::string::npos) << zero;
    const std::string one = errorOf(withLine("name = \"mouth\"", "implicit_tolerance = 1.5"));
    EXPECT_NE(one.find(":9: part 1, key 'implicit_tolerance': must be in [0, 1)"), std::string::npos) << one;
}

TEST(SceneFile, ConstraintRateReplacesTheFraction) {
    const Scene s = parseScene(withLine("name = \"ball\"", "restoration = \"constraint\"\nconstraint_rate = 2.5"), "scene.toml", ".");
    EXPECT_EQ(s.parts[1].part.simulation.restoration.constraintRate, 2.5);
    const std::string both = errorOf(withLine("name = \"ball\"", "constraint_fraction = 0.01\nconstraint_rate = 2.5"));
    EXPECT_NE(both.find(":19: part 2, key 'constraint_rate': give either constraint_rate or constraint_fraction, not both"),
              std::string::npos)
        << both;
    const std::string negative = errorOf(withLine("name = \"ball\"", "constraint_rate = -1"));
    EXPECT_NE(negative.find(":18: part 2, key 'constraint_rate': must be > 0"), std::string::npos) << negative;
}

TEST(SceneFile, PhysicalMaterialGivesTheMassesAndTheSprings) {
    const Scene s = parseScene(withLine("name = \"ball\"", "material = { youngs_modulus = 2e9, thickness = 0.001, density = 1200, "
                                                          "poisson_ratio = 0.4, damping_ratio = 0.2, bending_springs = true }"),
                               "scene.toml", ".");
    const PartModel& model = *s.parts[1].model;
    double area = 0.0, mass = 0.0;
    for (const Face& f : model.mesh.faces)
        area += 0.5 * (model.mesh.vertices[f[1]] - model.mesh.vertices[f[0]]).cross(model.mesh.vertices[f[2]] - model.mesh.vertices[f[0]]).norm();
    for (double m : model.mass) mass += m;
    EXPECT_NEAR(mass, 1200 * 0.001 * area, 1e-9 * mass);  // density x thickness x area
    EXPECT_GT(model.bendingSpringCount, 0u);
    EXPECT_EQ(model.springCount(), model.topology.edgeCount() + model.bendingSpringCount);
}

TEST(SceneFile, PhysicalMaterialErrorsNameTheKey) {
    auto error = [](const std::string& material) { return errorOf(withLine("name = \"ball\"", "material = " + material)); };
    const std::string missing = error("{ youngs_modulus = 2e9, thickness = 0.001 }");
    EXPECT_NE(missing.find(":18: part 2.material: needs 'density' beside 'youngs_modulus'"), std::string::npos) << missing;
    const std::string both = error("{ youngs_modulus = 2e9, thickness = 0.001, density = 1200, stiffness = 3 }");
    EXPECT_NE(both.find(":18: part 2.material, key 'stiffness': give either spring constants"), std::string::npos) << both;
    const std::string poisson = error("{ youngs_modulus = 2e9, thickness = 0.001, density = 1200, poisson_ratio = 0.5 }");
    EXPECT_NE(poisson.find(":18: part 2.material, key 'poisson_ratio': must be in [0, 0.5)"), std::string::npos) << poisson;
    const std::string stray = error("{ stiffness = 3, thickness = 0.001 }");
    EXPECT_NE(stray.find(":18: part 2.material, key 'thickness': belongs to a physical material"), std::string::npos) << stray;
    const std::string mass = errorOf(withLine("name = \"ball\"", "vertex_mass = 2\nmaterial = { youngs_modulus = 2e9, thickness = 0.001, density = 1200 }"));
    EXPECT_NE(mass.find(":18: part 2, key 'vertex_mass': a physical material gives the masses"), std::string::npos) << mass;
}

TEST(SceneFile, KickActionNeedsMassesAndAVelocity) {
    const Scene s = parseScene(std::string(kBall) + "\n[[action]]\ntime = 0.2\ntype = \"kick\"\npart = \"mouth\"\nmasses = [1, 5]\nvelocity = [0.5, 0, 0]\n",
                               "scene.toml", ".");
    const auto found = std::find_if(s.actions.begin(), s.actions.end(), [](const SceneAction& a) { return a.kind == SceneAction::Kind::Kick; });
    ASSERT_NE(found, s.actions.end());
    const SceneAction& kick = *found;
    EXPECT_EQ(kick.masses, (std::vector<Index>{1, 5}));
    EXPECT_EQ(kick.linear, Vec3(0.5, 0, 0));
    const std::string noVelocity = errorOf(std::string(kBall) + "\n[[action]]\ntime = 0.2\ntype = \"kick\"\npart = \"mouth\"\nmasses = [1]\n");
    EXPECT_NE(noVelocity.find("missing key 'velocity'"), std::string::npos) << noVelocity;
    const std::string range = errorOf(std::string(kBall) + "\n[[action]]\ntime = 0.2\ntype = \"kick\"\npart = \"mouth\"\nmasses = [99999]\nvelocity = [1, 0, 0]\n");
    EXPECT_NE(range.find("key 'masses': index 99999 out of range"), std::string::npos) << range;
}

// Mutated example scenes: each one is refused with an InputError naming a problem, or builds a
// world that steps (10 steps) with finite poses and positions, or stops with a DivergenceError.
// Nothing else may escape. The edits are TOML-aware (a number or a value replaced by an edge
// case, a line deleted or repeated elsewhere), so most cases get past the TOML parser into the
// scene reader's checks; seeded, so every run tests the same scenes. Only the cheaply built
// examples are seeds, and scenes with steps over 0.1 s are left out (each step then spans
// many contact slops: rigid_motion.hpp). A scratch fuzzer of the same kind ran 3,000 cases.
TEST(SceneFileFuzz, MutationsOfTheExampleScenesAreRefusedOrStepFinitely) {
    const std::filesystem::path examples = FLEXFIT_EXAMPLES_DIR;
    std::vector<std::string> seeds;
    for (const char* name : {"contact", "incline", "peg_in_hole", "restoration", "snap_vector", "stack", "stiff_clip",
                             "ball_torus_rigid", "zones"}) {
        std::ifstream in(examples / (std::string(name) + ".toml"), std::ios::binary);
        seeds.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        ASSERT_FALSE(seeds.back().empty()) << name;
    }
    const std::vector<std::string> tokens = {"-1", "0", "1e300", "nan", "inf", "-inf", "1e-300", "2", "0.5", "-0.0",
                                             "true", "\"\"", "[]", "{}", "[0, 0]", "[1e300, 0, 0]", "[nan, 0, 0]", "\"x\"",
                                             "\"ball\"", "\"mouth\""};
    std::mt19937 rng(20261206u);
    const auto pick = [&](std::size_t n) { return std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
    const auto lineAt = [](const std::string& s, std::size_t at) {
        const std::size_t start = at == 0 ? 0 : s.rfind('\n', at - 1) == std::string::npos ? 0 : s.rfind('\n', at - 1) + 1;
        const std::size_t end = s.find('\n', start);
        return std::pair{start, end == std::string::npos ? s.size() : end + 1};
    };
    const auto mutate = [&](std::string s) {
        for (std::size_t m = 0, count = 1 + pick(3); m < count && !s.empty(); ++m) {
            const std::size_t at = pick(s.size());
            switch (pick(4)) {
            case 0: {  // a number replaced
                std::size_t a = s.find_first_of("0123456789", at);
                if (a == std::string::npos) break;
                std::size_t b = a;
                while (b < s.size() && std::string_view("0123456789.-e").find(s[b]) != std::string_view::npos) ++b;
                s.replace(a, b - a, tokens[pick(tokens.size())]);
                break;
            }
            case 1: {  // a line deleted
                const auto [start, end] = lineAt(s, at);
                s.erase(start, end - start);
                break;
            }
            case 2: {  // a line repeated at another line's start
                const auto [start, end] = lineAt(s, at);
                const std::string line = s.substr(start, end - start);
                s.insert(lineAt(s, pick(s.size())).first, line.empty() || line.back() != '\n' ? line + "\n" : line);
                break;
            }
            default: {  // the value after a '= ' replaced
                const std::size_t a = s.find("= ", at);
                if (a == std::string::npos) break;
                const std::size_t end = s.find('\n', a);
                s.replace(a + 2, (end == std::string::npos ? s.size() : end) - a - 2, tokens[pick(tokens.size())]);
                break;
            }
            }
        }
        return s;
    };
    SceneReadOptions options;
    options.remeshCache = std::filesystem::path();
    int stepped = 0, diverged = 0, refused = 0;
    for (int i = 0; i < 600; ++i) {
        const std::string text = mutate(seeds[std::size_t(i) % seeds.size()]);
        const std::string label = "case " + std::to_string(i) + ":\n" + text;
        std::optional<Scene> scene;
        refused += 1 - flexfit::testing::readOrRefused([&] { scene.emplace(parseScene(text, "fuzz.toml", examples, options)); }, label);
        if (::testing::Test::HasFailure()) return;
        if (!scene || !(scene->world.timeStep <= 0.1)) continue;
        try {
            SceneRun run(*scene);
            for (int k = 0; k < 10; ++k) run.step();
            for (BodyId b = 0; b < run.world().bodyCount(); ++b) {
                const Part& part = run.world().part(b);
                ASSERT_TRUE(part.pose().translation.allFinite() && part.pose().rotation.coeffs().allFinite()) << label;
                for (const Vec3& p : part.state().positions) ASSERT_TRUE(p.allFinite()) << label;
            }
            ++stepped;
        } catch (const DivergenceError&) {
            ++diverged;
        } catch (const std::exception& e) {
            FAIL() << label << "\nescaped: " << e.what();
        }
    }
    // Most edits are refused; some leave a valid scene (a comment, an equal value) that steps.
    EXPECT_GT(stepped, 60);
    EXPECT_GT(refused, 200);
    std::cout << "stepped " << stepped << ", diverged " << diverged << ", refused " << refused << "\n";
}
