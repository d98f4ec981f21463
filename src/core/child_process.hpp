// Internal: work that may crash or hang, run in a child process so that it cannot take the
// caller's process with it.
//
// Why: assimp's importers crash (segmentation fault, abort, failed assertion) or spin forever on
// some damaged files. Measured with the Debian assimp 5.2.5: 13 of 512 damaged copies of the
// assimp-testmodels files crashed the importing process and one never returned. A library that
// reads its users' files must answer those with an error, not die with them, so readMesh runs
// assimp's import here (io/assimp_io.cpp).
//
// How: fork(); the child runs the work, writes the bytes it returns (or the error it threw) to a
// pipe and leaves with _exit, so none of the parent's exit handlers run in it. The parent reads
// the pipe until the child closes it or the time limit passes (then the child is killed), and
// reaps the child. Copy-on-write makes the fork cheap: the child touches little of the parent's
// memory.
//
// Known limits: POSIX only (Linux, the target). In a process with other threads, the child has
// only the forking thread: glibc makes malloc safe after fork, but a lock another thread held at
// that instant (a logger's, iostreams') stays held in the child, which then waits until the time
// limit kills it; the caller then gets a ChildFailure naming the time limit. Nothing the work
// writes to memory reaches the parent except the returned bytes.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

namespace flexfit::detail {

// What went wrong in the child: a crash (killed by a signal), the time limit, or an exception
// the work threw (its what()).
class ChildFailure : public std::runtime_error {
public:
    enum class Kind { Crashed, TimedOut, Threw, Failed };
    ChildFailure(Kind kind, const std::string& what) : std::runtime_error(what), kind_(kind) {}
    Kind kind() const { return kind_; }

private:
    Kind kind_;
};

// Runs `work` in a child process and returns the bytes it returned. Throws ChildFailure when the
// work throws (Threw, with the exception's message), the child is killed by a signal (Crashed:
// "killed by signal N (name)"), does not finish within `seconds` (TimedOut; the child is killed),
// or cannot be started (Failed).
std::string runInChild(const std::function<std::string()>& work, double seconds);

}  // namespace flexfit::detail
