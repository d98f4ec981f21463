// Small text helpers the tests share.
#pragma once

#include <string>

namespace flexfit::testing {

inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace flexfit::testing
