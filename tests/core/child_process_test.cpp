// Tests runInChild against what each kind of work must give: its bytes back whole (binary, and
// more than a pipe holds at once), its exception's message, a crash and a hang reported as such,
// and nothing the child writes to memory reaching the parent.
#include "core/child_process.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <string>
#include <unistd.h>

namespace flexfit::detail {
namespace {

// The kind of ChildFailure `work` ends in, with its message.
ChildFailure failureOf(const std::function<std::string()>& work, double seconds = 30.0) {
    try {
        runInChild(work, seconds);
    } catch (const ChildFailure& e) {
        return e;
    }
    ADD_FAILURE() << "the work ended normally";
    return ChildFailure(ChildFailure::Kind::Failed, "none");
}

TEST(ChildProcess, ReturnsTheWorksBytesWhole) {
    EXPECT_EQ(runInChild([] { return std::string("mesh"); }, 30.0), "mesh");
    EXPECT_EQ(runInChild([] { return std::string(); }, 30.0), "");
    const std::string binary("a\0b\xff\n", 5);
    EXPECT_EQ(runInChild([&] { return binary; }, 30.0), binary);
    // 10 MB: far more than a pipe's buffer, so the parent must read while the child writes.
    std::string large(10'000'000, '\0');
    for (std::size_t i = 0; i < large.size(); ++i) large[i] = char(i * 2654435761u >> 24);
    EXPECT_EQ(runInChild([&] { return large; }, 60.0), large);
}

TEST(ChildProcess, TheChildsWritesStayInTheChild) {
    int value = 1;
    runInChild([&] {
        value = 2;
        return std::string();
    }, 30.0);
    EXPECT_EQ(value, 1);
}

TEST(ChildProcess, AnExceptionComesBackWithItsMessage) {
    const ChildFailure e = failureOf([]() -> std::string { throw std::runtime_error("face 3 has 2 vertices"); });
    EXPECT_EQ(e.kind(), ChildFailure::Kind::Threw);
    EXPECT_STREQ(e.what(), "face 3 has 2 vertices");
    EXPECT_EQ(failureOf([]() -> std::string { throw 42; }).kind(), ChildFailure::Kind::Threw);
}

TEST(ChildProcess, ACrashIsReportedWithItsSignal) {
    const ChildFailure aborted = failureOf([]() -> std::string { std::abort(); });
    EXPECT_EQ(aborted.kind(), ChildFailure::Kind::Crashed);
    EXPECT_NE(std::string(aborted.what()).find("signal " + std::to_string(SIGABRT)), std::string::npos) << aborted.what();
    const ChildFailure killed = failureOf([]() -> std::string {
        ::kill(::getpid(), SIGKILL);
        return "unreachable";
    });
    EXPECT_EQ(killed.kind(), ChildFailure::Kind::Crashed);
    EXPECT_NE(std::string(killed.what()).find("signal " + std::to_string(SIGKILL)), std::string::npos) << killed.what();
    // An exit without an answer (a library calling exit) is a failure too, not an empty answer.
    EXPECT_EQ(failureOf([]() -> std::string { ::_exit(7); }).kind(), ChildFailure::Kind::Failed);
}

TEST(ChildProcess, AHangIsKilledAtTheTimeLimit) {
    const auto start = std::chrono::steady_clock::now();
    const ChildFailure e = failureOf([]() -> std::string {
        for (;;) ::pause();
    }, 0.5);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(e.kind(), ChildFailure::Kind::TimedOut);
    EXPECT_GE(seconds, 0.5);
    EXPECT_LT(seconds, 20.0);  // killed, not waited for
}

}  // namespace
}  // namespace flexfit::detail
