// A progress bar on stderr for long runs, drawn only when stderr is a terminal (CI logs stay
// clean). Redraws at most ~10 times per second.
#pragma once

#include <chrono>
#include <string>

namespace flexfit::cli {

class ProgressBar {
public:
    explicit ProgressBar(std::string label, bool enabled = true);
    ~ProgressBar();
    void update(double fraction);
    void finish();

private:
    std::string label_;
    bool enabled_;
    bool finished_ = false;
    std::chrono::steady_clock::time_point lastDraw_{};
};

}  // namespace flexfit::cli
