// The library's errors (core.hpp): bad input, and a simulation that diverged.
#include "flexfit/core.hpp"

#include <cstdio>

namespace flexfit {
namespace {
std::string formatInputError(const std::string& source, std::size_t line, const std::string& problem) {
    // Built with append(): GCC 12 warns falsely (-Wrestrict) on chained operator+ at -O3.
    std::string text = source;
    if (line > 0) text.append(":").append(std::to_string(line));
    text.append(": ").append(problem);
    return text;
}

std::string formatDivergenceError(std::optional<BodyId> body, const std::string& name, double time, const std::string& problem) {
    std::string text = body ? std::string("body ").append(std::to_string(*body)) : std::string("part");
    if (!name.empty()) text.append(" '").append(name).append("'");
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.9g", time);
    text.append(" diverged at t = ").append(seconds).append(" s: ").append(problem);
    return text;
}
}  // namespace

InputError::InputError(std::string source, std::size_t line, const std::string& problem)
    : std::runtime_error(formatInputError(source, line, problem)),
      source_(std::move(source)),
      line_(line),
      problem_(problem) {}

DivergenceError::DivergenceError(std::optional<BodyId> body, double time, const std::string& problem, std::string name)
    : std::runtime_error(formatDivergenceError(body, name, time, problem)),
      body_(body),
      name_(std::move(name)),
      time_(time),
      problem_(problem) {}

}  // namespace flexfit
