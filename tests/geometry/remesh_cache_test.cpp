// Tests remeshCached against remeshForSimulation called directly (the independent reference):
// a hit gives the same surface and report bit for bit; a changed vertex or option misses; a
// damaged file is remeshed and written again; a directory that cannot be written is reported
// and the surface still made; concurrent writers leave one whole file; bad options throw and
// write nothing; the default directory follows the environment. Trimming, against ages and
// sizes set by hand: the least recently used surfaces go first, others' files stay.
#include "flexfit/generators.hpp"
#include "flexfit/core.hpp"
#include "flexfit/remesh_cache.hpp"
#include "temp_dir.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace flexfit {
namespace {

using flexfit::testing::TempDir;

TriMesh cacheInput() { return makeBox(Vec3(1.0, 0.6, 0.4), 2); }

RemeshOptions cacheOptions() {
    RemeshOptions o;
    o.targetEdge = 0.3;
    return o;
}

void expectSameQuality(const MeshQuality& a, const MeshQuality& b) {
    EXPECT_EQ(a.faces, b.faces);
    EXPECT_EQ(a.minAngle, b.minAngle);
    EXPECT_EQ(a.slivers, b.slivers);
    EXPECT_EQ(a.minEdge, b.minEdge);
    EXPECT_EQ(a.meanEdge, b.meanEdge);
    EXPECT_EQ(a.maxEdge, b.maxEdge);
    EXPECT_EQ(a.edgeSpread, b.edgeSpread);
}

void expectSameRemesh(const RemeshResult& a, const RemeshResult& b) {
    EXPECT_EQ(a.mesh.name, b.mesh.name);
    EXPECT_EQ(a.mesh.vertices, b.mesh.vertices);
    EXPECT_EQ(a.mesh.faces, b.mesh.faces);
    expectSameQuality(a.before, b.before);
    expectSameQuality(a.after, b.after);
    EXPECT_EQ(a.featureEdges, b.featureEdges);
    EXPECT_EQ(a.droppedFaces, b.droppedFaces);
    EXPECT_EQ(a.seamVertices, b.seamVertices);
    EXPECT_EQ(a.releasedEdges, b.releasedEdges);
    EXPECT_EQ(a.roundedHausdorff, b.roundedHausdorff);
    EXPECT_EQ(a.rounded, b.rounded);
    EXPECT_EQ(a.hausdorff, b.hausdorff);
    EXPECT_EQ(a.diagonal, b.diagonal);
}

std::vector<std::filesystem::path> filesIn(const std::filesystem::path& directory) {
    std::vector<std::filesystem::path> out;
    if (std::filesystem::exists(directory))
        for (const auto& entry : std::filesystem::directory_iterator(directory)) out.push_back(entry.path());
    return out;
}

std::string contentOf(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void overwrite(const std::filesystem::path& file, const std::string& content) {
    std::ofstream(file, std::ios::binary | std::ios::trunc) << content;
}

TEST(RemeshCache, AHitGivesWhatRemeshingGives) {
    TempDir dir;
    const TriMesh input = cacheInput();
    const RemeshResult reference = remeshForSimulation(input, cacheOptions(), "box");
    const CachedRemesh first = remeshCached(input, cacheOptions(), "box", dir.path() / "cache");
    EXPECT_FALSE(first.hit);
    EXPECT_EQ(first.problem, "");
    expectSameRemesh(first.result, reference);
    ASSERT_EQ(filesIn(dir.path() / "cache").size(), 1u);
    const CachedRemesh second = remeshCached(input, cacheOptions(), "box", dir.path() / "cache");
    EXPECT_TRUE(second.hit);
    EXPECT_EQ(second.problem, "");
    expectSameRemesh(second.result, reference);
    // The result takes the input's name, which is not part of the key.
    TriMesh renamed = input;
    renamed.name = "another name";
    const CachedRemesh third = remeshCached(renamed, cacheOptions(), "box", dir.path() / "cache");
    EXPECT_TRUE(third.hit);
    EXPECT_EQ(third.result.mesh.name, "another name");
}

TEST(RemeshCache, AChangedVertexOrOptionMisses) {
    TempDir dir;
    const TriMesh input = cacheInput();
    ASSERT_FALSE(remeshCached(input, cacheOptions(), "box", dir.path()).hit);
    TriMesh nudged = input;
    nudged.vertices[3].x() = std::nextafter(nudged.vertices[3].x(), 2.0);
    const CachedRemesh moved = remeshCached(nudged, cacheOptions(), "box", dir.path());
    EXPECT_FALSE(moved.hit);
    expectSameRemesh(moved.result, remeshForSimulation(nudged, cacheOptions(), "box"));
    RemeshOptions fewer = cacheOptions();
    fewer.iterations = 2;
    EXPECT_FALSE(remeshCached(input, fewer, "box", dir.path()).hit);
    RemeshOptions kept = cacheOptions();
    kept.thinFeatures = ThinFeatures::Keep;
    EXPECT_FALSE(remeshCached(input, kept, "box", dir.path()).hit);
    RemeshOptions flatter = cacheOptions();
    flatter.featureAngle = 41.0;
    EXPECT_FALSE(remeshCached(input, flatter, "box", dir.path()).hit);
    EXPECT_EQ(filesIn(dir.path()).size(), 5u);
    EXPECT_TRUE(remeshCached(nudged, cacheOptions(), "box", dir.path()).hit);
    EXPECT_TRUE(remeshCached(input, fewer, "box", dir.path()).hit);
}

TEST(RemeshCache, ADamagedFileIsRemeshedAndWrittenAgain) {
    TempDir dir;
    const TriMesh input = cacheInput();
    const RemeshResult reference = remeshForSimulation(input, cacheOptions(), "box");
    remeshCached(input, cacheOptions(), "box", dir.path());
    const std::filesystem::path file = filesIn(dir.path()).at(0);
    const std::string whole = contentOf(file);
    std::string flipped = whole;
    flipped[whole.size() / 2] = char(flipped[whole.size() / 2] ^ 0x10);
    std::string otherFormat = whole;
    otherFormat[7] = '9';
    for (const std::string& damaged : {whole.substr(0, whole.size() / 2), whole.substr(0, 5), std::string(), flipped, otherFormat,
                                       whole + "x"}) {
        overwrite(file, damaged);
        const CachedRemesh again = remeshCached(input, cacheOptions(), "box", dir.path());
        EXPECT_FALSE(again.hit) << damaged.size();
        EXPECT_EQ(again.problem, "");
        expectSameRemesh(again.result, reference);
        EXPECT_TRUE(contentOf(file) == whole) << damaged.size();
    }
    EXPECT_EQ(filesIn(dir.path()).size(), 1u);
}

TEST(RemeshCache, ADirectoryThatCannotBeWrittenIsReportedAndTheSurfaceStillMade) {
    TempDir dir;
    const std::filesystem::path notADirectory = dir.write("file", "x");
    const TriMesh input = cacheInput();
    const CachedRemesh r = remeshCached(input, cacheOptions(), "box", notADirectory / "cache");
    EXPECT_FALSE(r.hit);
    EXPECT_FALSE(r.stored);
    EXPECT_NE(r.problem.find("could not create the remesh cache directory " + (notADirectory / "cache").string()), std::string::npos)
        << r.problem;
    expectSameRemesh(r.result, remeshForSimulation(input, cacheOptions(), "box"));
    // No directory: no cache, nothing reported.
    const CachedRemesh off = remeshCached(input, cacheOptions(), "box", {});
    EXPECT_FALSE(off.hit);
    EXPECT_EQ(off.problem, "");
}

TEST(RemeshCache, ConcurrentWritersLeaveOneWholeFile) {
    TempDir dir;
    const TriMesh input = cacheInput();
    std::optional<CachedRemesh> results[2];
    {
        std::jthread a([&] { results[0] = remeshCached(input, cacheOptions(), "box", dir.path()); });
        std::jthread b([&] { results[1] = remeshCached(input, cacheOptions(), "box", dir.path()); });
    }
    const RemeshResult reference = remeshForSimulation(input, cacheOptions(), "box");
    for (const auto& r : results) {
        ASSERT_TRUE(r.has_value());
        EXPECT_EQ(r->problem, "");
        expectSameRemesh(r->result, reference);
    }
    EXPECT_EQ(filesIn(dir.path()).size(), 1u);  // no temporary left behind
    EXPECT_TRUE(remeshCached(input, cacheOptions(), "box", dir.path()).hit);
}

TEST(RemeshCache, BadOptionsThrowAndWriteNothing) {
    TempDir dir;
    RemeshOptions none = cacheOptions();
    none.targetEdge = 0.0;
    EXPECT_THROW(remeshCached(cacheInput(), none, "box", dir.path() / "cache"), InputError);
    EXPECT_TRUE(filesIn(dir.path() / "cache").empty());
}

// Sets an environment variable for the scope, restoring it (or its absence) after.
class ScopedVariable {
public:
    ScopedVariable(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        if (value) ::setenv(name, value, 1);
        else ::unsetenv(name);
    }
    ~ScopedVariable() {
        if (old_) ::setenv(name_, old_->c_str(), 1);
        else ::unsetenv(name_);
    }
    ScopedVariable(const ScopedVariable&) = delete;
    ScopedVariable& operator=(const ScopedVariable&) = delete;

private:
    const char* name_;
    std::optional<std::string> old_;
};

TEST(RemeshCache, DefaultDirectoryFollowsTheEnvironment) {
    ScopedVariable home("HOME", "/home/user");
    {
        ScopedVariable chosen("FLEXFIT_CACHE_DIR", "/chosen");
        EXPECT_EQ(defaultRemeshCacheDirectory(), std::filesystem::path("/chosen/remesh"));
    }
    {
        ScopedVariable off("FLEXFIT_CACHE_DIR", "");
        EXPECT_EQ(defaultRemeshCacheDirectory(), std::filesystem::path());
    }
    ScopedVariable unset("FLEXFIT_CACHE_DIR", nullptr);
    {
        ScopedVariable xdg("XDG_CACHE_HOME", "/xdg");
        EXPECT_EQ(defaultRemeshCacheDirectory(), std::filesystem::path("/xdg/flexfit/remesh"));
    }
    ScopedVariable noXdg("XDG_CACHE_HOME", nullptr);
    EXPECT_EQ(defaultRemeshCacheDirectory(), std::filesystem::path("/home/user/.cache/flexfit/remesh"));
    ScopedVariable noHome("HOME", nullptr);
    EXPECT_EQ(defaultRemeshCacheDirectory(), std::filesystem::path());
}

// Files of given sizes and ages (seconds before now) in `dir`.
void writeAged(const std::filesystem::path& file, std::size_t bytes, int secondsOld) {
    overwrite(file, std::string(bytes, 'x'));
    std::filesystem::last_write_time(file, std::filesystem::file_time_type::clock::now() - std::chrono::seconds(secondsOld));
}

TEST(RemeshCache, TrimmingRemovesTheLeastRecentlyUsedSurfacesFirst) {
    TempDir dir;
    const std::filesystem::path a = dir.path() / "a.remesh", b = dir.path() / "b.remesh", c = dir.path() / "c.remesh";
    writeAged(a, 100, 300);
    writeAged(b, 100, 200);
    writeAged(c, 100, 100);
    writeAged(dir.path() / "notes.txt", 1000, 400);                    // not a surface
    writeAged(dir.path() / "d.remesh.tmp.12.34.0", 1000, 400);         // another writer's, unfinished
    // 300 bytes of surfaces: at most 250 removes the oldest only.
    EXPECT_EQ(trimRemeshCache(dir.path(), 250), 1u);
    EXPECT_FALSE(std::filesystem::exists(a));
    EXPECT_TRUE(std::filesystem::exists(b) && std::filesystem::exists(c));
    EXPECT_EQ(trimRemeshCache(dir.path(), 200), 0u);  // within the limit: nothing
    // Below one file: all but the kept one go, oldest first, and the kept one stays above it.
    EXPECT_EQ(trimRemeshCache(dir.path(), 50, b), 1u);
    EXPECT_TRUE(std::filesystem::exists(b));
    EXPECT_FALSE(std::filesystem::exists(c));
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "notes.txt") && std::filesystem::exists(dir.path() / "d.remesh.tmp.12.34.0"));
    EXPECT_EQ(trimRemeshCache(dir.path() / "absent", 0), 0u);
}

TEST(RemeshCache, AHitRenewsItsFileAndAWriteTrimsTheOthersToTheLimit) {
    TempDir dir;
    const std::filesystem::path cache = dir.path() / "cache";
    ScopedVariable unlimited("FLEXFIT_CACHE_MAX", "0");
    ASSERT_TRUE(remeshCached(cacheInput(), cacheOptions(), "box", cache).problem.empty());
    const std::vector<std::filesystem::path> first = filesIn(cache);
    ASSERT_EQ(first.size(), 1u);
    const auto old = std::filesystem::file_time_type::clock::now() - std::chrono::hours(24);
    std::filesystem::last_write_time(first[0], old);
    ASSERT_TRUE(remeshCached(cacheInput(), cacheOptions(), "box", cache).hit);
    EXPECT_GT(std::filesystem::last_write_time(first[0]), old);
    // Another surface under a one-byte limit: the first goes, the new one stays.
    ScopedVariable tiny("FLEXFIT_CACHE_MAX", "1");
    RemeshOptions other = cacheOptions();
    other.targetEdge = 0.35;
    const CachedRemesh second = remeshCached(cacheInput(), other, "box", cache);
    EXPECT_FALSE(second.hit);
    EXPECT_TRUE(second.problem.empty()) << second.problem;
    const std::vector<std::filesystem::path> left = filesIn(cache);
    ASSERT_EQ(left.size(), 1u);
    EXPECT_NE(left[0], first[0]);
    EXPECT_TRUE(remeshCached(cacheInput(), other, "box", cache).hit);
}

TEST(RemeshCache, TheLimitFollowsTheEnvironment) {
    {
        ScopedVariable unset("FLEXFIT_CACHE_MAX", nullptr);
        EXPECT_EQ(defaultRemeshCacheLimit().bytes, std::uintmax_t(2) << 30);
    }
    for (const auto& [text, bytes] : {std::pair{"12345", std::uintmax_t(12345)}, std::pair{"64k", std::uintmax_t(65536)},
                                      std::pair{"100M", std::uintmax_t(100) << 20}, std::pair{"3G", std::uintmax_t(3) << 30},
                                      std::pair{"0", std::uintmax_t(0)}, std::pair{"999999999999999", std::uintmax_t(999999999999999)}}) {
        ScopedVariable limit("FLEXFIT_CACHE_MAX", text);
        EXPECT_EQ(defaultRemeshCacheLimit().bytes, bytes) << text;
        EXPECT_TRUE(defaultRemeshCacheLimit().problem.empty()) << text;
    }
    for (const char* bad : {"", "12x", "1.5G", "-1", "G", "10 M", "9999999999999999", "999999999999999G"}) {
        ScopedVariable limit("FLEXFIT_CACHE_MAX", bad);
        const RemeshCacheLimit read = defaultRemeshCacheLimit();
        EXPECT_EQ(read.bytes, std::uintmax_t(2) << 30) << bad;
        EXPECT_EQ(read.problem, std::string("FLEXFIT_CACHE_MAX: '") + bad + "' is not a size (bytes, or a number with K, M or G); the cache keeps 2G");
    }
    // A write under a bad limit says so (a scene shows it as a warning) and still caches.
    TempDir dir;
    ScopedVariable limit("FLEXFIT_CACHE_MAX", "lots");
    const CachedRemesh written = remeshCached(cacheInput(), cacheOptions(), "box", dir.path());
    EXPECT_NE(written.problem.find("FLEXFIT_CACHE_MAX: 'lots' is not a size"), std::string::npos) << written.problem;
    EXPECT_TRUE(written.stored);  // so a scene does not say the part is remeshed at every load
    EXPECT_EQ(filesIn(dir.path()).size(), 1u);
}

}  // namespace
}  // namespace flexfit
