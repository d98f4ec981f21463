// Internal: the 64-bit FNV-1a hash behind the state hashes (part_state.hpp, world.hpp). Bytes
// in, bit for bit: equal hashes mean equal bytes with overwhelming probability. Not for
// security; chosen because it is a few lines, fixed by its definition, and fast enough for a
// hash per run.
#pragma once

#include <cstddef>
#include <cstdint>

namespace flexfit::detail {

class Fnv1a {
public:
    void mix(const void* data, std::size_t size) {
        const auto* bytes = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < size; ++i) value_ = (value_ ^ bytes[i]) * kPrime;
    }
    std::uint64_t value() const { return value_; }

private:
    static constexpr std::uint64_t kOffsetBasis = 14695981039346656037ull;
    static constexpr std::uint64_t kPrime = 1099511628211ull;
    std::uint64_t value_ = kOffsetBasis;
};

}  // namespace flexfit::detail
