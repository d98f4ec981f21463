#include "cli_common.hpp"

#include "perturbation_run.hpp"

#include <fmt/core.h>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace flexfit::cli {

namespace {

// A validator of numbers for which accepts(value) holds, `what` naming them in its message.
CLI::Validator numberCheck(bool (*accepts)(double), const std::string& what, const std::string& description) {
    return CLI::Validator(
        [accepts, what](std::string& text) {
            double value = 0.0;
            if (CLI::detail::lexical_cast(text, value) && std::isfinite(value) && accepts(value)) return std::string();
            return text + " is not a finite number " + what;
        },
        description);
}

}  // namespace

const CLI::Validator positiveNumber = numberCheck([](double v) { return v > 0.0; }, "> 0", "POSITIVE");
const CLI::Validator nonNegativeNumber = numberCheck([](double v) { return v >= 0.0; }, ">= 0", "NONNEGATIVE");
const CLI::Validator openAngleDegrees = numberCheck([](double v) { return v > 0.0 && v < 180.0; }, "strictly between 0 and 180", "(0, 180)");

void warn(const std::string& text) { fmt::print(stderr, "warning: {}\n", text); }

void printWarnings(const Scene& scene) { printWarnings(scene.linesFile.empty() ? scene.source : scene.linesFile, scene.warnings); }

void printWarnings(const std::string& file, std::span<const SceneWarning> warnings) {
    for (const SceneWarning& w : warnings) warn(fmt::format("{}:{}: {}", file, w.line, w.message));
}
namespace {

double parseNumber(std::string_view token, const std::string& option, const std::string& whole) {
    double value = 0.0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || end != token.data() + token.size() || !std::isfinite(value))
        throw InputError("option " + option, 0, "'" + whole + "' is not a finite number list (x,y,z)");
    return value;
}

std::filesystem::path toolsDirectory() {
    for (const std::filesystem::path dir : {FLEXFIT_TOOLS_DIR, FLEXFIT_INSTALLED_TOOLS_DIR})
        if (std::filesystem::exists(dir)) return dir;
    return FLEXFIT_TOOLS_DIR;
}

std::string shellQuote(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

}  // namespace

Vec3 parseVec3(const std::string& text, const std::string& option) {
    const std::size_t c1 = text.find(','), c2 = c1 == std::string::npos ? c1 : text.find(',', c1 + 1);
    if (c1 == std::string::npos || c2 == std::string::npos || text.find(',', c2 + 1) != std::string::npos)
        throw InputError("option " + option, 0, "'" + text + "' is not three comma-separated numbers (x,y,z)");
    std::string_view view(text);
    return {parseNumber(view.substr(0, c1), option, text), parseNumber(view.substr(c1 + 1, c2 - c1 - 1), option, text),
            parseNumber(view.substr(c2 + 1), option, text)};
}

PointLoad parseLoad(const std::string& text, const std::string& option) {
    const std::size_t colon = text.find(':');
    if (colon == std::string::npos) throw InputError("option " + option, 0, "'" + text + "' is not MASS:FX,FY,FZ");
    unsigned long mass = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + colon, mass);
    if (ec != std::errc() || end != text.data() + colon)
        throw InputError("option " + option, 0, "'" + text + "': mass index is not a non-negative integer");
    return {Index(mass), parseVec3(text.substr(colon + 1), option)};
}

ZoneRequest parseZone(const std::string& text, const std::string& option) {
    const std::size_t at = text.find('@');
    const bool face = text.rfind("face:", 0) == 0;
    const std::size_t begin = face ? 5 : 0;
    unsigned long index = 0, level = 0;
    const char* end = text.data() + text.size();
    const auto parsedIndex = std::from_chars(text.data() + begin, text.data() + (at == std::string::npos ? text.size() : at), index);
    const bool ok = at != std::string::npos && parsedIndex.ec == std::errc() && parsedIndex.ptr == text.data() + at &&
                    std::from_chars(text.data() + at + 1, end, level).ptr == end && at + 1 < text.size();
    if (!ok || level > 255)
        throw InputError("option " + option, 0, "'" + text + "' is not MASS@LEVEL or face:F@LEVEL (level 0-255)");
    return {face ? ZoneSeed::face(Index(index)) : ZoneSeed::mass(Index(index)), int(level)};
}

MeshReadOptions MeshOptions::read() const {
    MeshReadOptions options;
    if (weldOption != nullptr && weldOption->count() > 0) options.weldTolerance = weld;
    options.repair = !strict;
    return options;
}

void addMeshOptions(CLI::App* cmd, MeshOptions& options, bool weld) {
    if (weld)
        options.weldOption = cmd->add_option("--weld", options.weld, "Weld vertices closer than this distance (default: near-duplicates, 1e-6 of the diagonal)")
                                 ->check(nonNegativeNumber);
    cmd->add_flag("--strict", options.strict,
                  "Refuse meshes with geometric defects (degenerate or duplicate faces, near-duplicate or unused vertices, "
                  "inconsistent windings) instead of repairing them");
}

SceneReadOptions SceneOptions::read() const {
    SceneReadOptions options;
    options.strictMeshes = strict;
    if (remeshCache) options.remeshCache = std::filesystem::path(*remeshCache);
    return options;
}

void addSceneOptions(CLI::App* cmd, SceneOptions& options) {
    cmd->add_flag("--strict", options.strict, "Refuse mesh files with geometric defects instead of repairing them (every part)");
    cmd->add_option("--remesh-cache", options.remeshCache,
                    "Directory keeping remeshed parts' surfaces between runs (default: $FLEXFIT_CACHE_DIR/remesh, else "
                    "~/.cache/flexfit/remesh; \"\": none)");
}

MeshReadResult loadMesh(const std::filesystem::path& path, const MeshReadOptions& options) {
    MeshReadResult result = readMesh(path, options);
    for (const std::string& warning : result.diagnostics.warnings) fmt::print(stderr, "warning: {}: {}\n", path.string(), warning);
    return result;
}

void writePartsObj(const std::filesystem::path& path, const std::string& header, const std::vector<NamedPart>& parts) {
    std::ostringstream obj;
    obj << "# " << header << "\n";
    std::size_t base = 1;
    std::vector<Vec3> world;
    for (const NamedPart& named : parts) {
        obj << "o " << objObjectName(named.name) << "\n";
        named.part->drawnWorldPositions(world);
        for (const Vec3& v : world) obj << fmt::format("v {:.9g} {:.9g} {:.9g}\n", v.x(), v.y(), v.z());
        for (const Face& f : named.part->model().drawnMesh().faces) obj << "f " << f[0] + base << " " << f[1] + base << " " << f[2] + base << "\n";
        base += world.size();
    }
    writeWholeFile(path, obj.str());
}

void makeDirectory(const std::filesystem::path& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec || !std::filesystem::is_directory(dir)) throw InputError(dir.string(), 0, "cannot create the directory: " + ec.message());
}

PendingFiles::~PendingFiles() {
    for (const File& f : files_) {
        std::error_code ec;
        std::filesystem::remove(f.temporary, ec);  // best effort: nothing to report it to
    }
    for (auto d = createdDirectories_.rbegin(); d != createdDirectories_.rend(); ++d) {
        std::error_code ec;
        std::filesystem::remove(*d, ec);  // removes only an empty directory
    }
}

void PendingFiles::makeDirectory(const std::filesystem::path& dir) {
    std::vector<std::filesystem::path> missing;
    std::error_code ec;
    for (std::filesystem::path d = dir; !d.empty() && !std::filesystem::exists(d, ec); d = d.parent_path()) {
        missing.push_back(d);
        if (d == d.parent_path()) break;
    }
    // Remembered first: if a parent is made and the leaf is not, the parent goes too.
    createdDirectories_.insert(createdDirectories_.end(), missing.rbegin(), missing.rend());
    cli::makeDirectory(dir);
}

std::filesystem::path PendingFiles::add(const std::filesystem::path& path) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(path, ec);
    if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) return path;  // /dev/stdout, a pipe
    const std::filesystem::path temporary = temporaryBeside(path);
    files_.push_back({temporary, path});
    return temporary;
}

void PendingFiles::commit() {
    while (!files_.empty()) {
        const File& f = files_.front();
        std::error_code ec;
        std::filesystem::rename(f.temporary, f.path, ec);
        if (ec) throw InputError(f.path.string(), 0, "cannot move the finished file into place: " + ec.message());
        files_.erase(files_.begin());
    }
    createdDirectories_.clear();
}

bool runPlotScript(const std::string& script, const std::vector<std::string>& args) {
    const char* python = "/usr/bin/python3";
    if (!std::filesystem::exists(python)) {
        fmt::print(stderr, "warning: {} not found: plots skipped (CSV results are complete)\n", python);
        return false;
    }
    std::string command = std::string(python) + " " + shellQuote((toolsDirectory() / script).string());
    for (const std::string& a : args) command += " " + shellQuote(a);
    if (std::system(command.c_str()) != 0) {
        fmt::print(stderr, "warning: {} failed (is python3-matplotlib installed?): plots skipped\n", script);
        return false;
    }
    return true;
}

}  // namespace flexfit::cli
