// The remesher's fingerprint (remesh_samples.hpp), on its own so that a new source hash
// recompiles this file only. FLEXFIT_REMESHER_HASH comes from src/CMakeLists.txt.
#include "geometry/remesh_samples.hpp"

#include <CGAL/version.h>

namespace flexfit::detail {

std::string_view remesherFingerprint() { return "CGAL " CGAL_VERSION_STR ", sources " FLEXFIT_REMESHER_HASH; }

}  // namespace flexfit::detail
