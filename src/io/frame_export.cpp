// VTK XML PolyData, .pvd collections and glTF binary frames (frame_export.hpp).
#include "flexfit/frame_export.hpp"

#include <assimp/Exporter.hpp>
#include <assimp/scene.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <unistd.h>
#include <fstream>
#include <sstream>

namespace flexfit {
namespace {

// Renames `temporary` to `file` once whole (or removes it and throws).
void moveIntoPlace(const std::filesystem::path& temporary, const std::filesystem::path& file, bool written,
                   const std::string& problem = "cannot write the file") {
    std::error_code ec;
    if (written) std::filesystem::rename(temporary, file, ec);
    if (!written || ec) {
        std::filesystem::remove(temporary, ec);
        throw InputError(file.string(), 0, problem);
    }
}

void checkParts(const std::vector<FramePart>& parts, const std::filesystem::path& file) {
    if (parts.empty()) throw InputError(file.string(), 0, "no parts to write");
    for (const FramePart& p : parts)
        if (!p.part) throw InputError(file.string(), 0, "part '" + p.name + "' is null");
}

std::string xmlEscaped(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
        case '&': out += "&amp;"; break;
        case '<': out += "&lt;"; break;
        case '>': out += "&gt;"; break;
        case '"': out += "&quot;"; break;
        default: out += static_cast<unsigned char>(c) < 0x20 ? '?' : c;  // XML 1.0 allows no control characters
        }
    }
    return out;
}

// %.17g: doubles written so they read back bit for bit.
void appendVectors(std::ostringstream& out, const std::vector<Vec3>& values) {
    char buffer[96];
    for (const Vec3& v : values) {
        std::snprintf(buffer, sizeof buffer, "%.17g %.17g %.17g\n", v.x(), v.y(), v.z());
        out << buffer;
    }
}

void appendPiece(std::ostringstream& out, const FramePart& named) {
    const Part& part = *named.part;
    const PartModel& model = part.model();
    const std::size_t n = model.massCount();
    // The simulation surface in the user's vertex order (PartModel::userMesh()); a file vertex
    // the repair removed is carried rigidly, undisplaced, outside every zone.
    const auto& faces = model.userMesh().faces;
    std::vector<Vec3> perMass(n), points, displacement, velocity;
    part.vertexWorldPositions(points);
    for (std::size_t m = 0; m < n; ++m) perMass[m] = part.pose().rotate(part.state().positions[m] - model.restPositions[m]);
    inVertexOrder<Vec3>(model, perMass, displacement);
    for (std::size_t m = 0; m < n; ++m) perMass[m] = part.pose().rotate(part.state().velocities[m]);
    inVertexOrder<Vec3>(model, perMass, velocity);
    std::vector<int> depthPerMass, depth;
    part.zoneDepths(depthPerMass);
    inVertexOrder<int>(model, depthPerMass, depth, [](Index) { return -1; });
    out << "<Piece Name=\"" << xmlEscaped(named.name) << "\" NumberOfPoints=\"" << points.size() << "\" NumberOfPolys=\"" << faces.size() << "\">\n";
    out << "<PointData Scalars=\"zone_depth\" Vectors=\"displacement\">\n";
    out << "<DataArray type=\"Int32\" Name=\"zone_depth\" format=\"ascii\">\n";
    for (int d : depth) out << d << "\n";
    out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"displacement\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    appendVectors(out, displacement);
    out << "</DataArray>\n<DataArray type=\"Float64\" Name=\"velocity\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    appendVectors(out, velocity);
    out << "</DataArray>\n</PointData>\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    appendVectors(out, points);
    out << "</DataArray>\n</Points>\n<Polys>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const Face& f : faces) out << f[0] << " " << f[1] << " " << f[2] << "\n";
    out << "</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 1; i <= faces.size(); ++i) out << 3 * i << "\n";
    out << "</DataArray>\n</Polys>\n</Piece>\n";
}

}  // namespace

std::filesystem::path temporaryBeside(const std::filesystem::path& file) {
    static std::atomic<std::uint64_t> count{0};
    return file.string() + "." + std::to_string(::getpid()) + "-" + std::to_string(count++) + ".partial";
}

void writeWholeFile(const std::filesystem::path& file, std::string_view text) {
    std::error_code ec;
    const std::filesystem::file_status status = std::filesystem::status(file, ec);
    const bool inPlace = std::filesystem::exists(status) && !std::filesystem::is_regular_file(status);
    const std::filesystem::path target = inPlace ? file : temporaryBeside(file);
    std::ofstream out(target, std::ios::binary);
    if (!out) throw InputError(file.string(), 0, "cannot write the file: it cannot be created there");
    out.write(text.data(), std::streamsize(text.size()));
    out.close();  // flushes the last buffer: a full disk shows here
    if (inPlace) {
        if (out.fail()) throw InputError(file.string(), 0, "write failed");
        return;
    }
    moveIntoPlace(target, file, !out.fail(), "write failed");
}

void writeVtkFrame(const std::filesystem::path& file, const std::vector<FramePart>& parts) {
    checkParts(parts, file);
    std::ostringstream out;
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<PolyData>\n";
    for (const FramePart& p : parts) appendPiece(out, p);
    out << "</PolyData>\n</VTKFile>\n";
    writeWholeFile(file, out.str());
}

void writeGlbFrame(const std::filesystem::path& file, const std::vector<FramePart>& parts) {
    checkParts(parts, file);
    aiScene scene;  // owns everything below (its destructor frees meshes, materials and nodes)
    scene.mRootNode = new aiNode("flexfit");
    scene.mNumMaterials = 1;
    scene.mMaterials = new aiMaterial*[1]{new aiMaterial()};
    scene.mNumMeshes = unsigned(parts.size());
    scene.mMeshes = new aiMesh*[parts.size()]{};
    scene.mRootNode->mNumChildren = unsigned(parts.size());
    scene.mRootNode->mChildren = new aiNode*[parts.size()]{};
    std::vector<Vec3> world;
    for (std::size_t i = 0; i < parts.size(); ++i) {
        const Part& part = *parts[i].part;
        part.drawnWorldPositions(world);
        const auto& faces = part.model().drawnMesh().faces;
        auto* mesh = new aiMesh();
        scene.mMeshes[i] = mesh;
        mesh->mName = parts[i].name;
        mesh->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
        mesh->mNumVertices = unsigned(world.size());
        mesh->mVertices = new aiVector3D[world.size()];
        for (std::size_t v = 0; v < world.size(); ++v) mesh->mVertices[v] = aiVector3D(ai_real(world[v].x()), ai_real(world[v].y()), ai_real(world[v].z()));
        mesh->mNumFaces = unsigned(faces.size());
        mesh->mFaces = new aiFace[faces.size()];
        for (std::size_t f = 0; f < faces.size(); ++f) {
            mesh->mFaces[f].mNumIndices = 3;
            mesh->mFaces[f].mIndices = new unsigned[3]{faces[f][0], faces[f][1], faces[f][2]};
        }
        auto* node = new aiNode(parts[i].name);
        node->mParent = scene.mRootNode;
        node->mNumMeshes = 1;
        node->mMeshes = new unsigned[1]{unsigned(i)};
        scene.mRootNode->mChildren[i] = node;
    }
    Assimp::Exporter exporter;
    const std::filesystem::path temporary = temporaryBeside(file);
    const bool written = exporter.Export(&scene, "glb2", temporary.string()) == AI_SUCCESS;
    moveIntoPlace(temporary, file, written, written ? "cannot write the file" : std::string("cannot write the glTF file: ") + exporter.GetErrorString());
}

void writeVtkCollection(const std::filesystem::path& file, const std::vector<std::pair<double, std::string>>& frames) {
    std::ostringstream pvd;
    pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n<Collection>\n";
    char line[64];
    for (const auto& [t, f] : frames) {
        std::snprintf(line, sizeof line, "%.17g", t);
        pvd << "<DataSet timestep=\"" << line << "\" part=\"0\" file=\"" << xmlEscaped(f) << "\"/>\n";
    }
    pvd << "</Collection>\n</VTKFile>\n";
    writeWholeFile(file, pvd.str());
}

VtkSeries::VtkSeries(std::filesystem::path directory, std::string stem)
    : directory_(std::move(directory)), collection_(directory_ / (stem + ".pvd")), stem_(std::move(stem)) {}

std::filesystem::path VtkSeries::write(double time, const std::vector<FramePart>& parts) {
    char name[64];
    std::snprintf(name, sizeof name, "_%06zu.vtp", frames_.size());
    const std::string file = stem_ + name;
    writeVtkFrame(directory_ / file, parts);
    frames_.emplace_back(time, file);
    writeVtkCollection(collection_, frames_);
    return directory_ / file;
}

}  // namespace flexfit
