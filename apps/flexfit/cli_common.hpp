// Helpers shared by the subcommands: parsing of vector and load arguments, loading meshes with
// their warnings printed, writing text files, and running the plot scripts.
#pragma once

#include "flexfit/flexfit.hpp"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace flexfit::cli {

// Checks of a number option with plain messages ("--edge: -1 is not a finite number > 0"):
// CLI11 2.1's PositiveNumber and NonNegativeNumber let NaN through and print their range's end,
// the largest double, in 309 digits.
extern const CLI::Validator positiveNumber;     // finite, > 0
extern const CLI::Validator openAngleDegrees;   // finite, strictly between 0 and 180
extern const CLI::Validator nonNegativeNumber;  // finite, >= 0

// "x,y,z" -> Vec3; throws InputError naming `option`.
Vec3 parseVec3(const std::string& text, const std::string& option);
// "MASS:FX,FY,FZ" -> PointLoad; throws InputError naming `option`.
PointLoad parseLoad(const std::string& text, const std::string& option);

// "MASS@LEVEL" or "face:F@LEVEL" -> zone request; throws InputError naming `option`.
struct ZoneRequest;
ZoneRequest parseZone(const std::string& text, const std::string& option);

// "warning: <text>" on stderr.
void warn(const std::string& text);
// Prints a scene's warnings (old spellings, mesh repairs) on stderr, with the file and line
// (a sweep run's: the base scene's file).
void printWarnings(const Scene& scene);
void printWarnings(const std::string& file, std::span<const SceneWarning> warnings);

// The value of an option that names an enum (names.hpp). Old spellings are accepted with a
// warning on stderr that names the new one; anything else throws InputError naming `option`.
template <class Enum>
Enum enumOption(const std::string& text, const std::string& option) {
    std::string replacement;
    const std::optional<Enum> value = parseName<Enum>(text, &replacement);
    if (!value) throw InputError(option, 0, "unknown value '" + text + "' (expected one of " + nameList<Enum>() + ")");
    if (!replacement.empty()) warn(option + ": " + deprecationWarning(text, replacement));
    return *value;
}
// The names an enum option accepts (old spellings included), for CLI11's IsMember check.
template <class Enum>
std::vector<std::string> enumChoices() {
    return allNames<Enum>(true);
}

// How a command reads mesh files: --weld TOLERANCE (asked-for welding) and --strict (refuse
// geometric defects instead of repairing them, mesh_repair.hpp).
struct MeshOptions {
    double weld = 0.0;
    bool strict = false;
    CLI::Option* weldOption = nullptr;
    MeshReadOptions read() const;
};
void addMeshOptions(CLI::App* cmd, MeshOptions& options, bool weld = true);

// How a command reads scene files: --strict (every part's mesh file) and --remesh-cache DIR
// (SceneReadOptions, scene_file.hpp).
struct SceneOptions {
    bool strict = false;
    std::optional<std::string> remeshCache;
    SceneReadOptions read() const;
};
void addSceneOptions(CLI::App* cmd, SceneOptions& options);

// Reads any supported mesh and prints its warnings (repairs first) to stderr.
MeshReadResult loadMesh(const std::filesystem::path& path, const MeshReadOptions& options = {});

// One object of a multi-part OBJ frame.
struct NamedPart {
    std::string name;
    const Part* part = nullptr;
};
// Writes the parts, in world coordinates, as one OBJ file with an "o NAME" object each and a
// "# header" first line (for Blender or ParaView); throws InputError when it cannot.
void writePartsObj(const std::filesystem::path& path, const std::string& header, const std::vector<NamedPart>& parts);
// Creates the directory (and parents); throws InputError when it cannot.
void makeDirectory(const std::filesystem::path& dir);

// The files of one run, all or none: each is written under a temporary name beside it
// (temporaryBeside, frame_export.hpp), commit() renames them all once the run has finished, and the destructor
// removes whatever was not committed. So a run that fails (a divergence, a write error) leaves
// no half-written output; files of an earlier run under the same names stay until commit().
class PendingFiles {
public:
    PendingFiles() = default;
    PendingFiles(const PendingFiles&) = delete;
    PendingFiles& operator=(const PendingFiles&) = delete;
    ~PendingFiles();
    // The temporary path to write `path` to (`path` itself when it exists and is not a regular
    // file: a device or a pipe, which cannot be replaced).
    std::filesystem::path add(const std::filesystem::path& path);
    // makeDirectory, remembering the directories it created: a run that fails before commit
    // leaves none of them behind (only where they are still empty).
    void makeDirectory(const std::filesystem::path& dir);
    // Renames every temporary to its path (close streams first); throws InputError when one
    // cannot be renamed (the rest are then removed).
    void commit();

private:
    struct File {
        std::filesystem::path temporary, path;
    };
    std::vector<File> files_;
    std::vector<std::filesystem::path> createdDirectories_;  // outermost first
};

// Runs tools/<script> with Debian's /usr/bin/python3 (matplotlib); returns false (after a
// warning) when Python or matplotlib is missing, so the CSV results still stand.
bool runPlotScript(const std::string& script, const std::vector<std::string>& args);

}  // namespace flexfit::cli
