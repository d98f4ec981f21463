// The scene reader on a parsed TOML document (scene_file.cpp), for callers that build or edit
// the document first: the sweeps (sweep.cpp) set their parameters' values in a copy of the
// base scene's document. A value without a source region (one set by a sweep) is reported at
// line 0; the sweep names its own line instead.
#pragma once

#include "flexfit/scene_file.hpp"

#include <toml++/toml.h>

namespace flexfit::detail {

// The line a TOML node starts on, for messages (0 when it has no source region).
inline std::size_t lineOf(const toml::node& node) { return node.source().begin.line; }

Scene readSceneDocument(const toml::table& document, const std::string& source, const std::filesystem::path& baseDirectory,
                        const SceneReadOptions& options);

// One [[assembly]] table read as the scene reader reads it, its `primary` and `secondary`
// looked up in `partNames` (a body's id is its index there): for callers that build a rule from
// the scene file's keys (the Python World.add_assembly). Errors name `source`; warnings (old
// spellings) are added to `warnings`.
AssemblyRule readAssemblyTable(const toml::table& table, const std::string& source, const std::vector<std::string>& partNames,
                               std::vector<SceneWarning>& warnings);

}  // namespace flexfit::detail
