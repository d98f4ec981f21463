// Scene files: a scene (scene.hpp) written in TOML.
//
// Why TOML (toml++ from Debian's libtomlplusplus-dev): a scene is a handful of flat tables
// ([world], [[part]], [[assembly]], [[action]], [output]) that engineers write by hand. TOML
// has no indentation rules to get wrong and no implicit typing surprises (YAML's "no" is a
// boolean), and toml++ keeps the line of every key, so each error names file, line and key.
// Every key is checked: an unknown key is an error, as is a value of the wrong type or out of
// range. Old spellings of names (names.hpp) are read, with a warning in Scene::warnings.
#pragma once

#include "flexfit/scene.hpp"

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace flexfit {

struct SceneReadOptions {
    // Refuse mesh files with geometric defects (mesh_repair.hpp) instead of repairing them, for
    // every part (a part's own `repair = false` does it for that part alone).
    bool strictMeshes = false;
    // Where remeshed parts' surfaces are kept between loads (remesh_cache.hpp): unset, the
    // default directory (defaultRemeshCacheDirectory()); an empty path, nowhere. A part's own
    // `remesh = { ..., cache = false }` skips it for that part.
    std::optional<std::filesystem::path> remeshCache;
};

// Throws InputError naming the file, the line and the key for every problem. A part's mesh
// file is repaired unless the part says `repair = false`; what was repaired is in the
// scene's warnings, at the line of the part's `mesh` key.
Scene loadScene(const std::filesystem::path& file, const SceneReadOptions& options = {});
// The same from text; mesh paths are resolved against `baseDirectory`.
Scene parseScene(std::string_view text, const std::string& source, const std::filesystem::path& baseDirectory,
                 const SceneReadOptions& options = {});

}  // namespace flexfit
