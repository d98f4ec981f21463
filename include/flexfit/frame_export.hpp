// Frames for ParaView and Blender: VTK XML PolyData with per-vertex fields, and glTF 2 binary.
//
// VTK (.vtp, one <Piece> per part, world coordinates, the simulation mesh, whose masses carry
// the fields): point data
//   zone_depth     Int32    depth of the mass in the zones covering it (0 = seed), -1 at rest
//   displacement   Float64  the mass's offset from its rest position, world axes
//   velocity       Float64  the mass's deformation velocity, world axes (the body's own
//                           motion not included)
// A VtkSeries writes each frame and keeps a .pvd collection beside them (time of every frame)
// that ParaView opens as one time series; the .pvd is rewritten after each frame, so it is
// valid while a run is still going. Written as ASCII XML by our code: the VTK library itself
// (Debian's libvtk9-dev) would add ~250 packages (Qt, MPI, HDF5) to the build for a format
// that is a page of XML; the tests read our files with VTK's own reader (python3-vtk9).
//
// glTF 2 (.glb, through assimp's exporter): one mesh per part in world coordinates, the drawn
// mesh (the user's own when the part simulates on a remeshed surface), for Blender and the web.
//
// Both throw InputError naming the file when it cannot be written, and write nothing then.
#pragma once

#include "flexfit/part.hpp"

#include <filesystem>
#include <string_view>
#include <string>
#include <utility>
#include <vector>

namespace flexfit {

struct FramePart {
    std::string name;
    const Part* part = nullptr;
};

void writeVtkFrame(const std::filesystem::path& file, const std::vector<FramePart>& parts);
void writeGlbFrame(const std::filesystem::path& file, const std::vector<FramePart>& parts);

// A .pvd collection: (time in s, frame file relative to the .pvd) per frame.
void writeVtkCollection(const std::filesystem::path& file, const std::vector<std::pair<double, std::string>>& frames);

// The temporary that `file` is written under before it is renamed into place (the exports
// here, and the runs' outputs): beside it, named by this process and a per-process count
// (`<file>.<pid>-<n>.partial`), so two writers of the same file (a command and a Python sweep,
// a retried task) never write into each other's temporary.
std::filesystem::path temporaryBeside(const std::filesystem::path& file);

// Writes `text` as the whole of `file`: under temporaryBeside(file), closed (the last buffer
// flushed), checked and renamed into place, so a write that fails (a full disk, a file-size
// limit) leaves no file, or the earlier one, and throws InputError naming the file. A file that
// exists and is not a regular file (a device, a pipe) is written in place, and checked alike.
// The mesh writers (mesh_io.hpp), the frames here and the command's outputs use it.
void writeWholeFile(const std::filesystem::path& file, std::string_view text);

// Frames <directory>/<stem>_<NNNNNN>.vtp and the collection <directory>/<stem>.pvd.
class VtkSeries {
public:
    VtkSeries(std::filesystem::path directory, std::string stem);
    // Writes the frame for time `time` (s); returns its path.
    std::filesystem::path write(double time, const std::vector<FramePart>& parts);
    const std::filesystem::path& collection() const { return collection_; }

private:
    std::filesystem::path directory_, collection_;
    std::string stem_;
    std::vector<std::pair<double, std::string>> frames_;
};

}  // namespace flexfit
