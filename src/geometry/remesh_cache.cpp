#include "flexfit/remesh_cache.hpp"

#include "core/fnv1a.hpp"
#include "geometry/remesh_samples.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <sstream>
#include <string_view>
#include <type_traits>
#include <unistd.h>
#include <vector>

namespace flexfit {
namespace {

// The format's tag: its version and this machine's byte order (the 8 bytes of a known integer).
constexpr char kFormat[8] = {'F', 'F', 'R', 'M', 'S', 'H', '0', '1'};
constexpr std::uint64_t kByteOrder = 0x0102030405060708ull;

// Everything a cached surface depends on, besides the remesher's fingerprint in `hash`.
struct CacheKey {
    std::uint64_t hash = 0;
    std::uint64_t vertices = 0, faces = 0;
    double targetEdge = 0.0, featureAngle = 0.0;
    std::int64_t iterations = 0, thinFeatures = 0;
    bool operator==(const CacheKey&) const = default;
};

// Calls io(field) for each key field but the hash: what the hash mixes in after the mesh.
template <class Io, class Key>
void visitCounts(Io& io, Key& key) {
    io(key.vertices), io(key.faces), io(key.targetEdge), io(key.featureAngle), io(key.iterations), io(key.thinFeatures);
}

// Calls io(field) for each key field, then each report field of r, in the file's order: the
// writer and the reader share this list.
template <class Io, class Key, class Result>
void visitFields(Io& io, Key& key, Result& r) {
    io(key.hash);
    visitCounts(io, key);
    for (auto* q : {&r.before, &r.after})
        io(q->faces), io(q->minAngle), io(q->slivers), io(q->minEdge), io(q->meanEdge), io(q->maxEdge), io(q->edgeSpread);
    io(r.featureEdges), io(r.droppedFaces), io(r.seamVertices), io(r.releasedEdges), io(r.roundedHausdorff), io(r.rounded),
        io(r.hausdorff), io(r.diagonal);
}

template <class T>
void mixValue(detail::Fnv1a& h, const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    h.mix(&value, sizeof value);
}

CacheKey keyOf(const TriMesh& mesh, const RemeshOptions& options) {
    CacheKey key;
    key.vertices = mesh.vertices.size();
    key.faces = mesh.faces.size();
    key.targetEdge = options.targetEdge;
    key.featureAngle = options.featureAngle;
    key.iterations = options.iterations;
    key.thinFeatures = std::int64_t(options.thinFeatures);
    detail::Fnv1a h;
    const std::string_view fingerprint = detail::remesherFingerprint();
    h.mix(fingerprint.data(), fingerprint.size());
    for (const Vec3& p : mesh.vertices) h.mix(p.data(), 3 * sizeof(double));
    h.mix(mesh.faces.data(), mesh.faces.size() * sizeof(Face));
    auto mix = [&h](const auto& value) { mixValue(h, value); };
    visitCounts(mix, key);
    key.hash = h.value();
    return key;
}

std::filesystem::path fileOf(const std::filesystem::path& directory, const CacheKey& key) {
    std::ostringstream name;
    name << std::hex;
    name.width(16);
    name.fill('0');
    name << key.hash << ".remesh";
    return directory / name.str();
}

struct Writer {
    std::vector<char> bytes;
    void raw(const void* data, std::size_t size) {
        const char* p = static_cast<const char*>(data);
        bytes.insert(bytes.end(), p, p + size);
    }
    template <class T>
    void operator()(const T& value) {
        static_assert(std::is_trivially_copyable_v<T>);
        raw(&value, sizeof value);
    }
};

// Reads `bytes` in order; `ok` turns false at the first read past their end.
struct Reader {
    std::span<const char> bytes;
    std::size_t at = 0;
    bool ok = true;
    bool raw(void* data, std::size_t size) {
        ok = ok && size <= bytes.size() - at;
        if (ok) std::memcpy(data, bytes.data() + at, size), at += size;
        return ok;
    }
    template <class T>
    void operator()(T& value) {
        static_assert(std::is_trivially_copyable_v<T>);
        raw(&value, sizeof value);
    }
};

std::uint64_t checksumOf(const char* data, std::size_t size) {
    detail::Fnv1a h;
    h.mix(data, size);
    return h.value();
}

std::vector<char> serialise(const CacheKey& key, const RemeshResult& r) {
    Writer w;
    w.raw(kFormat, sizeof kFormat);
    w(kByteOrder);
    visitFields(w, key, r);
    w(std::uint64_t(r.mesh.vertices.size()));
    w(std::uint64_t(r.mesh.faces.size()));
    for (const Vec3& p : r.mesh.vertices) w.raw(p.data(), 3 * sizeof(double));
    w.raw(r.mesh.faces.data(), r.mesh.faces.size() * sizeof(Face));
    w(checksumOf(w.bytes.data(), w.bytes.size()));
    return std::move(w.bytes);
}

// The surface in `bytes` when they are a whole file of this format for `key`.
std::optional<RemeshResult> deserialise(const std::vector<char>& bytes, const CacheKey& key) {
    constexpr std::size_t kChecksum = sizeof(std::uint64_t);
    if (bytes.size() < sizeof kFormat + kChecksum) return std::nullopt;
    std::uint64_t stored = 0;
    std::memcpy(&stored, bytes.data() + bytes.size() - kChecksum, kChecksum);
    if (stored != checksumOf(bytes.data(), bytes.size() - kChecksum)) return std::nullopt;
    Reader in{std::span<const char>(bytes).first(bytes.size() - kChecksum)};
    char format[sizeof kFormat];
    std::uint64_t byteOrder = 0, vertices = 0, faces = 0;
    CacheKey found;
    RemeshResult r;
    in.raw(format, sizeof format);
    in(byteOrder);
    visitFields(in, found, r);
    in(vertices), in(faces);
    const std::size_t payload = in.bytes.size() - in.at;
    if (!in.ok || std::memcmp(format, kFormat, sizeof kFormat) != 0 || byteOrder != kByteOrder || !(found == key) ||
        vertices > payload / (3 * sizeof(double)) || faces > payload / sizeof(Face) ||
        vertices * 3 * sizeof(double) + faces * sizeof(Face) != payload)
        return std::nullopt;
    r.mesh.vertices.resize(vertices);
    r.mesh.faces.resize(faces);
    for (Vec3& p : r.mesh.vertices) in.raw(p.data(), 3 * sizeof(double));
    in.raw(r.mesh.faces.data(), faces * sizeof(Face));
    for (const Vec3& p : r.mesh.vertices)
        if (!p.allFinite()) return std::nullopt;
    for (const Face& f : r.mesh.faces)
        for (Index v : f)
            if (v >= vertices) return std::nullopt;
    return r;
}

std::optional<std::vector<char>> readWhole(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return std::nullopt;
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) return std::nullopt;
    return bytes;
}

// Written beside `file` under a name of this writer's and renamed over it; the problem, or "".
// The name has the process id and a random number: processes on machines sharing the directory
// can have the same id.
std::string writeAtomically(const std::filesystem::path& file, const std::vector<char>& bytes) {
    static std::atomic<unsigned> counter{0};
    std::filesystem::path temporary = file;
    temporary += ".tmp." + std::to_string(::getpid()) + "." + std::to_string(std::random_device{}()) + "." +
                 std::to_string(counter++);
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        out.write(bytes.data(), std::streamsize(bytes.size()));
        out.close();
        if (!out) {
            std::error_code ignored;
            std::filesystem::remove(temporary, ignored);
            return "could not write " + temporary.string();
        }
    }
    std::error_code error;
    std::filesystem::rename(temporary, file, error);
    if (!error) return {};
    std::filesystem::remove(temporary, error);
    return "could not rename " + temporary.string() + " to " + file.string();
}

// "123", "64K", "100M", "2G" (powers of 1024), or nullopt.
std::optional<std::uintmax_t> parseSize(std::string_view text) {
    std::size_t digits = 0;
    while (digits < text.size() && text[digits] >= '0' && text[digits] <= '9') ++digits;
    if (digits == 0 || digits > 15 || text.size() > digits + 1) return std::nullopt;
    std::uintmax_t value = std::stoull(std::string(text.substr(0, digits)));
    if (digits == text.size()) return value;
    const char suffix = char(std::toupper(static_cast<unsigned char>(text[digits])));
    const int shift = suffix == 'K' ? 10 : suffix == 'M' ? 20 : suffix == 'G' ? 30 : -1;
    if (shift < 0 || value > (std::numeric_limits<std::uintmax_t>::max() >> shift)) return std::nullopt;
    return value << shift;
}

void markUsed(const std::filesystem::path& file) {
    std::error_code ignored;  // a read-only directory still serves hits
    std::filesystem::last_write_time(file, std::filesystem::file_time_type::clock::now(), ignored);
}

}  // namespace

RemeshCacheLimit defaultRemeshCacheLimit() {
    constexpr std::uintmax_t kDefault = std::uintmax_t(2) << 30;
    const char* text = std::getenv("FLEXFIT_CACHE_MAX");
    if (text == nullptr) return {kDefault, {}};
    if (const std::optional<std::uintmax_t> bytes = parseSize(text)) return {*bytes, {}};
    return {kDefault, std::string("FLEXFIT_CACHE_MAX: '") + text + "' is not a size (bytes, or a number with K, M or G); the cache keeps 2G"};
}

std::size_t trimRemeshCache(const std::filesystem::path& directory, std::uintmax_t maxBytes, const std::filesystem::path& keep) {
    struct Entry {
        std::filesystem::file_time_type used;
        std::uintmax_t bytes;
        std::filesystem::path path;
    };
    std::vector<Entry> entries;
    std::uintmax_t total = 0;
    std::error_code error;
    for (std::filesystem::directory_iterator it(directory, error), end; !error && it != end; it.increment(error)) {
        if (it->path().extension() != ".remesh") continue;
        std::error_code statError;
        const std::uintmax_t bytes = it->file_size(statError);
        const auto used = it->last_write_time(statError);
        if (statError) continue;  // removed meanwhile
        total += bytes;
        if (it->path() != keep) entries.push_back({used, bytes, it->path()});
    }
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.used < b.used || (a.used == b.used && a.path < b.path); });
    std::size_t removed = 0;
    for (const Entry& e : entries) {
        if (total <= maxBytes) break;
        total -= e.bytes;
        std::error_code removeError;
        removed += std::filesystem::remove(e.path, removeError) ? 1 : 0;
    }
    return removed;
}

std::filesystem::path defaultRemeshCacheDirectory() {
    if (const char* chosen = std::getenv("FLEXFIT_CACHE_DIR"))
        return *chosen ? std::filesystem::path(chosen) / "remesh" : std::filesystem::path();
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return std::filesystem::path(xdg) / "flexfit" / "remesh";
    if (const char* home = std::getenv("HOME"); home && *home)
        return std::filesystem::path(home) / ".cache" / "flexfit" / "remesh";
    return {};
}

CachedRemesh remeshCached(const TriMesh& mesh, const RemeshOptions& options, const std::string& source,
                          const std::filesystem::path& directory) {
    CachedRemesh out;
    if (directory.empty()) {
        out.result = remeshForSimulation(mesh, options, source);
        return out;
    }
    const CacheKey key = keyOf(mesh, options);
    const std::filesystem::path file = fileOf(directory, key);
    if (const std::optional<std::vector<char>> bytes = readWhole(file))
        if (std::optional<RemeshResult> cached = deserialise(*bytes, key)) {
            out.result = std::move(*cached);
            out.result.mesh.name = mesh.name;
            out.hit = true;
            markUsed(file);
            return out;
        }
    out.result = remeshForSimulation(mesh, options, source);
    std::error_code error;
    std::filesystem::create_directories(directory, error);
    out.problem = error ? "could not create the remesh cache directory " + directory.string() + " (" + error.message() + ")"
                        : writeAtomically(file, serialise(key, out.result));
    if (!out.problem.empty()) return out;
    out.stored = true;
    const RemeshCacheLimit limit = defaultRemeshCacheLimit();
    out.problem = limit.problem;
    if (limit.bytes > 0) trimRemeshCache(directory, limit.bytes, file);
    return out;
}

}  // namespace flexfit
