#include "flexfit/core.hpp"

namespace flexfit {
namespace {
std::string formatInputError(const std::string& source, std::size_t line, const std::string& problem) {
    // Built with append(): GCC 12 warns falsely (-Wrestrict) on chained operator+ at -O3.
    std::string text = source;
    if (line > 0) text.append(":").append(std::to_string(line));
    text.append(": ").append(problem);
    return text;
}
}  // namespace

InputError::InputError(std::string source, std::size_t line, const std::string& problem)
    : std::runtime_error(formatInputError(source, line, problem)),
      source_(std::move(source)),
      line_(line),
      problem_(problem) {}

}  // namespace flexfit
