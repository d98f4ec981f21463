#include "progress.hpp"

#include <algorithm>
#include <cstdio>
#include <unistd.h>

namespace flexfit::cli {

ProgressBar::ProgressBar(std::string label, bool enabled)
    : label_(std::move(label)), enabled_(enabled && isatty(STDERR_FILENO) != 0) {}

// Left unfinished (an error stopped the run): end the line where the bar stands, not at 100%.
ProgressBar::~ProgressBar() {
    if (!enabled_ || finished_) return;
    std::fprintf(stderr, "\n");
    finished_ = true;
}

void ProgressBar::update(double fraction) {
    if (!enabled_ || finished_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - lastDraw_ < std::chrono::milliseconds(100) && fraction < 1.0) return;
    lastDraw_ = now;
    constexpr int kWidth = 40;
    const int filled = int(std::clamp(fraction, 0.0, 1.0) * kWidth);
    std::fprintf(stderr, "\r%s [%.*s%*s] %5.1f%%", label_.c_str(), filled, "########################################",
                 kWidth - filled, "", 100.0 * std::clamp(fraction, 0.0, 1.0));
    std::fflush(stderr);
}

void ProgressBar::finish() {
    if (!enabled_ || finished_) return;
    update(1.0);
    std::fprintf(stderr, "\n");
    finished_ = true;
}

}  // namespace flexfit::cli
