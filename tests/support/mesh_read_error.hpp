// Helpers of the mesh readers' tests: the error a reader gives for a file's text (written to a
// temporary file of the given name, whose extension picks the reader; a test failure when the
// text is accepted), lists of such cases, and a mesh as OFF / PLY body lines.
#pragma once

#include "flexfit/mesh_io.hpp"
#include "strings.hpp"
#include "temp_dir.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include <string>
#include <vector>

namespace flexfit::testing {

inline InputError meshReadError(const std::string& fileName, const std::string& text, const MeshReadOptions& options = {}) {
    TempDir dir;
    try {
        readMesh(dir.write(fileName, text), options);
    } catch (const InputError& e) {
        return e;
    }
    ADD_FAILURE() << fileName << " accepted:\n" << text;
    return InputError("", 0, "");
}

// The body of OFF and ASCII PLY files: `x y z` lines (17 digits: every bit), then `3 a b c`.
inline std::string vertexAndFaceLines(const TriMesh& mesh) {
    std::string text;
    char buffer[96];
    for (const Vec3& v : mesh.vertices) {
        std::snprintf(buffer, sizeof buffer, "%.17g %.17g %.17g\n", v.x(), v.y(), v.z());
        text += buffer;
    }
    for (const Face& f : mesh.faces) text += "3 " + std::to_string(f[0]) + " " + std::to_string(f[1]) + " " + std::to_string(f[2]) + "\n";
    return text;
}

// A file's text, the line its error must name and a part of its problem.
struct ReadErrorCase {
    std::string text;
    std::size_t line;
    std::string problem;
};

// Each case refused by the reader `fileName`'s extension picks, at its line, for its problem.
inline void expectReadErrors(const std::string& fileName, const std::vector<ReadErrorCase>& cases) {
    for (const ReadErrorCase& c : cases) {
        const InputError e = meshReadError(fileName, c.text);
        EXPECT_EQ(e.line(), c.line) << c.text << "\n" << e.what();
        EXPECT_TRUE(contains(e.problem(), c.problem)) << c.text << "\n" << e.what();
    }
}

}  // namespace flexfit::testing
