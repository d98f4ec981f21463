// VTK and glTF frames (src/io/frame_export.cpp). The pytest suite reads them with VTK's own
// reader; here: the fields hold the part's state (read back by a small independent parser),
// the glTF loads back with assimp, and a file that cannot be written is an error.
#include "flexfit/frame_export.hpp"
#include "flexfit/generators.hpp"
#include "flexfit/mesh_io.hpp"
#include "temp_dir.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <regex>
#include <sstream>

namespace flexfit {
namespace {

using testing::TempDir;

std::string readText(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// The numbers of the named DataArray.
std::vector<double> dataArray(const std::string& xml, const std::string& name) {
    const auto start = xml.find("Name=\"" + name + "\"");
    EXPECT_NE(start, std::string::npos) << name;
    const auto open = xml.find('>', start) + 1, close = xml.find("</DataArray>", open);
    std::istringstream in(xml.substr(open, close - open));
    std::vector<double> values;
    for (double v; in >> v;) values.push_back(v);
    return values;
}

Part pressedTorus() {
    Part part(buildPartModel(makeTorus(2.0, 0.5, 12, 8)));
    part.setPose(Pose{Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Vec3::UnitZ())), Vec3(1, 2, 3)});
    part.openZone(ZoneSeed::mass(5), 2);
    part.applyForce(5, Vec3(0, 0.3, 0));
    for (int i = 0; i < 20; ++i) part.step();
    return part;
}

TEST(FrameExport, VtkFieldsHoldThePartsState) {
    TempDir dir;
    const Part part = pressedTorus();
    writeVtkFrame(dir.path() / "f.vtp", {{"torus", &part}});
    const std::string xml = readText(dir.path() / "f.vtp");
    const std::size_t n = part.model().massCount();
    const auto depth = dataArray(xml, "zone_depth"), disp = dataArray(xml, "displacement"), vel = dataArray(xml, "velocity");
    ASSERT_EQ(depth.size(), n);
    ASSERT_EQ(disp.size(), 3 * n);
    ASSERT_EQ(vel.size(), 3 * n);
    std::vector<int> expected;
    part.zoneDepths(expected);
    std::size_t moving = 0;
    for (std::size_t m = 0; m < n; ++m) {
        EXPECT_EQ(int(depth[m]), expected[m]);
        const Vec3 d = part.pose().rotation * (part.state().positions[m] - part.model().restPositions[m]);
        for (int k = 0; k < 3; ++k) EXPECT_EQ(disp[3 * m + std::size_t(k)], d[k]);  // %.17g: bit for bit
        moving += expected[m] >= 0;
    }
    EXPECT_GT(moving, 0u);
    EXPECT_NE(xml.find("NumberOfPolys=\"" + std::to_string(part.model().mesh.faces.size()) + "\""), std::string::npos);
}

TEST(FrameExport, CollectionListsEveryFrameWithItsTime) {
    TempDir dir;
    const Part part = pressedTorus();
    VtkSeries series(dir.path(), "run");
    series.write(0.5, {{"a", &part}});
    series.write(1.25, {{"a", &part}});
    const std::string pvd = readText(series.collection());
    EXPECT_NE(pvd.find("timestep=\"0.5\" part=\"0\" file=\"run_000000.vtp\""), std::string::npos) << pvd;
    EXPECT_NE(pvd.find("timestep=\"1.25\" part=\"0\" file=\"run_000001.vtp\""), std::string::npos) << pvd;
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "run_000001.vtp"));
}

TEST(FrameExport, GlbLoadsBackWithAssimp) {
    TempDir dir;
    const Part a = pressedTorus();
    const Part b(buildPartModel(makeIcoSphere(1.0, 1)));
    writeGlbFrame(dir.path() / "f.glb", {{"torus", &a}, {"ball", &b}});
    const MeshReadResult back = readMesh(dir.path() / "f.glb");  // assimp's glTF importer
    EXPECT_EQ(back.mesh.faces.size(), a.model().mesh.faces.size() + b.model().mesh.faces.size());
    // The pressed torus's first world position is among the read vertices (float precision).
    std::vector<Vec3> world;
    a.worldPositions(world);
    bool found = false;
    for (const Vec3& v : back.mesh.vertices) found = found || (v - world[5]).norm() < 1e-5;
    EXPECT_TRUE(found);
}

TEST(FrameExport, UnwritablePathIsAnErrorNamingIt) {
    const Part part = pressedTorus();
    for (const std::string file : {"/nonexistent/dir/f.vtp", "/nonexistent/dir/f.glb"}) {
        try {
            if (file.ends_with(".vtp")) writeVtkFrame(file, {{"a", &part}});
            else writeGlbFrame(file, {{"a", &part}});
            ADD_FAILURE() << "no error for " << file;
        } catch (const InputError& e) {
            EXPECT_EQ(e.source(), file);
            EXPECT_NE(std::string(e.what()).find("cannot write"), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(writeVtkFrame("/tmp/none.vtp", {}), InputError);
}

// Nothing but the finished files is left in the directory, whether a write succeeds or fails
// (here: the target is a directory, so the rename into place fails).
TEST(FrameExport, TemporariesAreUniqueAndNeverLeftBehind) {
    const TempDir temp;
    const std::filesystem::path dir = temp.path();
    std::filesystem::create_directories(dir / "taken.vtp");
    const std::filesystem::path a = temporaryBeside(dir / "f.vtp"), b = temporaryBeside(dir / "f.vtp");
    EXPECT_NE(a, b);
    EXPECT_EQ(a.parent_path(), dir);
    EXPECT_TRUE(a.string().ends_with(".partial")) << a;
    const Part part = pressedTorus();
    writeVtkFrame(dir / "f.vtp", {{"a", &part}});
    writeGlbFrame(dir / "f.glb", {{"a", &part}});
    EXPECT_THROW(writeVtkFrame(dir / "taken.vtp", {{"a", &part}}), InputError);
    std::vector<std::string> names;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"f.glb", "f.vtp", "taken.vtp"}));
}

}  // namespace
}  // namespace flexfit
