#include "core/child_process.hpp"

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

namespace flexfit::detail {
namespace {

// The child's message: one tag byte, then the bytes the work returned or its exception's text.
constexpr char kReturned = 'R', kThrew = 'T';

void writeAll(int fd, const char* data, std::size_t size) {
    while (size > 0) {
        const ssize_t n = ::write(fd, data, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) ::_exit(3);  // the parent is gone or the pipe broke: nobody to tell
        data += n;
        size -= std::size_t(n);
    }
}

[[noreturn]] void runChild(const std::function<std::string()>& work, int fd) {
    std::string message;
    try {
        message = kReturned + work();
    } catch (const std::exception& e) {
        message = std::string(1, kThrew) + e.what();
    } catch (...) {
        message = std::string(1, kThrew) + "an exception that is not a std::exception";
    }
    writeAll(fd, message.data(), message.size());
    ::close(fd);
    ::_exit(0);
}

// Reads the pipe until its end or the deadline; false when the deadline passed first.
bool readUntilClosed(int fd, std::chrono::steady_clock::time_point deadline, std::string& out) {
    char buffer[1 << 16];
    for (;;) {
        const auto now = std::chrono::steady_clock::now();
        if (now >= deadline) return false;
        const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - now).count();
        pollfd p{fd, POLLIN, 0};
        const int ready = ::poll(&p, 1, int(std::min<long long>(left, 1 << 30)));
        if (ready < 0 && errno == EINTR) continue;
        if (ready < 0) throw ChildFailure(ChildFailure::Kind::Failed, std::string("poll failed: ") + std::strerror(errno));
        if (ready == 0) continue;  // the deadline is checked above
        const ssize_t n = ::read(fd, buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw ChildFailure(ChildFailure::Kind::Failed, std::string("read failed: ") + std::strerror(errno));
        if (n == 0) return true;
        out.append(buffer, std::size_t(n));
    }
}

int reap(pid_t pid) {
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
}

std::string signalText(int signal) {
    const char* name = ::strsignal(signal);
    return "killed by signal " + std::to_string(signal) + (name ? std::string(" (") + name + ")" : std::string());
}

}  // namespace

std::string runInChild(const std::function<std::string()>& work, double seconds) {
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) throw ChildFailure(ChildFailure::Kind::Failed, std::string("pipe failed: ") + std::strerror(errno));
    const pid_t pid = ::fork();
    if (pid < 0) {
        const int error = errno;
        ::close(fds[0]);
        ::close(fds[1]);
        throw ChildFailure(ChildFailure::Kind::Failed, std::string("fork failed: ") + std::strerror(error));
    }
    if (pid == 0) {
        ::close(fds[0]);
        runChild(work, fds[1]);
    }
    ::close(fds[1]);
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                                  std::chrono::duration<double>(std::max(seconds, 0.0)));
    std::string message;
    bool finished = false;
    try {
        finished = readUntilClosed(fds[0], deadline, message);
    } catch (...) {
        ::close(fds[0]);
        ::kill(pid, SIGKILL);
        reap(pid);
        throw;
    }
    ::close(fds[0]);
    if (!finished) ::kill(pid, SIGKILL);
    const int status = reap(pid);
    if (!finished) throw ChildFailure(ChildFailure::Kind::TimedOut, "did not finish within " + std::to_string(int(seconds)) + " s");
    if (WIFSIGNALED(status)) throw ChildFailure(ChildFailure::Kind::Crashed, signalText(WTERMSIG(status)));
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || message.empty())
        throw ChildFailure(ChildFailure::Kind::Failed, "ended with exit status " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1));
    if (message[0] == kThrew) throw ChildFailure(ChildFailure::Kind::Threw, message.substr(1));
    return message.substr(1);
}

}  // namespace flexfit::detail
