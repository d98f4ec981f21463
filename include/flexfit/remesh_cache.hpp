// Remeshed surfaces kept on disk, so that a scene loaded again (the next `flexfit run`, a
// sweep's next variant, a Dask worker's next task) reads its parts' surfaces instead of
// remeshing them: a CAD part remeshed finely takes seconds to minutes (regr01 at 0.5 % of its
// size: 34 s), its file reads in milliseconds.
//
// One file per (input mesh, options), named by a 64-bit FNV-1a hash of the input's vertices
// and faces (their bytes), the options, and the remesher's fingerprint: CGAL's version and a
// hash of Flexfit's remeshing sources taken when the build is configured. A changed mesh,
// option, CGAL or remesher misses and remeshes. The file repeats the input's counts and the
// options and is checked against them, so a hash collision (about n^2 / 2^65 for n files)
// would also need equal counts to be taken. The remesher is deterministic (the same bits on any
// number of cores, remesh.hpp), so a hit is what remeshing again would give, quality report
// included.
//
// Files are written under a temporary name and renamed into place (atomic on POSIX), so
// processes sharing the directory never read one half-written. A file that does not read back
// whole (truncated, another format, a checksum that does not match) is a miss and is written
// again. The cache never makes a load fail: a directory that cannot be created or written is
// reported (CachedRemesh::problem, a scene warning) and the surface is remeshed.
//
// The cache holds at most FLEXFIT_CACHE_MAX bytes of surfaces (2 GiB by default; a file takes
// about 24 bytes a vertex and 12 a face): after each write the least recently used files go
// (by modification time, which a hit renews), never the one just written.
//
// Known limits: files are in the machine's byte order (another byte order
// misses, by the format tag); the input's name is not part of the key (the result takes the
// input's name); builds of the same sources that round differently (another compiler, other
// floating-point flags) share files as if they did not.
#pragma once

#include "flexfit/remesh.hpp"

#include <cstdint>
#include <filesystem>
#include <string>

namespace flexfit {

// FLEXFIT_CACHE_DIR when set (an empty value turns the cache off), else $XDG_CACHE_HOME/flexfit,
// else $HOME/.cache/flexfit, each with "remesh" appended; empty when none is set.
std::filesystem::path defaultRemeshCacheDirectory();

// The most bytes of surfaces a cache directory keeps: FLEXFIT_CACHE_MAX when set (bytes, or
// with a K, M or G suffix for powers of 1024; 0: no limit), else 2 GiB. A value that is not a
// size is named in `problem` and the default is used.
struct RemeshCacheLimit {
    std::uintmax_t bytes = 0;  // 0: no limit
    std::string problem;
};
RemeshCacheLimit defaultRemeshCacheLimit();

// Removes the least recently used surfaces (*.remesh files, oldest modification time first)
// from `directory` until those left take at most maxBytes; `keep` is never removed, even alone
// above the limit. Other files are left alone, and a file another process removed first is
// skipped. Returns how many it removed.
std::size_t trimRemeshCache(const std::filesystem::path& directory, std::uintmax_t maxBytes, const std::filesystem::path& keep = {});

struct CachedRemesh {
    RemeshResult result;
    bool hit = false;     // read from the cache
    bool stored = false;  // remeshed now and written to the cache
    std::string problem;  // why the cache could not be read or written, or its size limit not read (empty: none, or it is off)
};

// remeshForSimulation(mesh, options, source) through the cache in `directory` (created when
// missing, trimmed to defaultRemeshCacheLimit() after a write); an empty directory remeshes
// without it. Errors in the mesh or the options throw
// as remeshForSimulation does, and nothing is written for them.
CachedRemesh remeshCached(const TriMesh& mesh, const RemeshOptions& options, const std::string& source,
                          const std::filesystem::path& directory);

}  // namespace flexfit
