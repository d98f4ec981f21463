// Random edits of a file's text for the readers' fuzz tests (tri_io_test.cpp, mesh_io_test.cpp):
// 1 to 4 of flipping a bit, deleting a run of bytes, inserting a byte (random or from
// `interesting`, the format's own characters), replacing a byte with an interesting one, and
// duplicating a whole line. Seeded by the caller, so every run tests the same texts. And the
// tests' one rule for a mutated file: it reads, or it is refused with an InputError.
#pragma once

#include "flexfit/core.hpp"

#include <gtest/gtest.h>

#include <exception>
#include <random>
#include <string>
#include <string_view>

namespace flexfit::testing {

inline std::string mutated(std::string text, std::mt19937& rng, std::string_view interesting) {
    std::uniform_int_distribution<int> byte(0, 255);
    std::uniform_int_distribution<int> operation(0, 4);
    std::uniform_int_distribution<int> mutationCount(1, 4);
    const int mutations = mutationCount(rng);
    for (int m = 0; m < mutations; ++m) {
        std::uniform_int_distribution<std::size_t> position(0, text.empty() ? 0 : text.size() - 1);
        switch (operation(rng)) {
        case 0:  // flip a bit
            if (!text.empty()) text[position(rng)] ^= char(1 << (byte(rng) % 8));
            break;
        case 1:  // delete a run of bytes
            if (!text.empty()) text.erase(position(rng), std::size_t(1 + byte(rng) % 4));
            break;
        case 2:  // insert a byte, random or from the format's alphabet
            text.insert(text.begin() + std::ptrdiff_t(text.empty() ? 0 : position(rng)),
                        byte(rng) % 2 ? char(byte(rng)) : interesting[std::size_t(byte(rng)) % interesting.size()]);
            break;
        case 3:  // replace a byte
            if (!text.empty()) text[position(rng)] = interesting[std::size_t(byte(rng)) % interesting.size()];
            break;
        default: {  // duplicate a whole line
            if (text.empty()) break;
            std::size_t start = text.rfind('\n', position(rng));
            start = start == std::string::npos ? 0 : start + 1;
            std::size_t end = text.find('\n', start);
            end = end == std::string::npos ? text.size() : end + 1;
            const std::string line = text.substr(start, end - start);
            text.insert(end, line.back() == '\n' ? line : line + "\n");
            break;
        }
        }
    }
    return text;
}

// 1 when `read()` returns (it checks what it read), 0 when it throws InputError with a problem;
// any other exception fails the test.
template <class Read>
int readOrRefused(Read&& read, const std::string& label) {
    try {
        read();
        return 1;
    } catch (const InputError& e) {
        EXPECT_FALSE(e.problem().empty()) << label;
        return 0;
    } catch (const std::exception& e) {
        ADD_FAILURE() << label << ": std::exception escaped: " << e.what();
    } catch (...) {
        ADD_FAILURE() << label << ": unknown exception escaped";
    }
    return 0;
}

}  // namespace flexfit::testing
