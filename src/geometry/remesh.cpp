// Simulation remeshing (remesh.hpp) with CGAL's Polygon Mesh Processing. Compiled apart from
// the rest of the library (src/CMakeLists.txt): CGAL's usage requirements (-frounding-math)
// stay in this file and do not reach the step kernels.
#include "flexfit/remesh.hpp"
#include "flexfit/mesh_repair.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace flexfit {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;

// Smallest interior angle of a triangle, degrees (0 for a degenerate one).
double smallestAngle(const Vec3& a, const Vec3& b, const Vec3& c) {
    auto angle = [](const Vec3& at, const Vec3& u, const Vec3& v) {
        return std::atan2((u - at).cross(v - at).norm(), (u - at).dot(v - at)) * 180.0 / M_PI;
    };
    return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

SurfaceMesh toSurfaceMesh(const TriMesh& mesh, const std::string& source) {
    std::vector<Point> points;
    points.reserve(mesh.vertices.size());
    for (const Vec3& v : mesh.vertices) points.emplace_back(v.x(), v.y(), v.z());
    std::vector<std::array<std::size_t, 3>> polygons;
    polygons.reserve(mesh.faces.size());
    for (const Face& f : mesh.faces) polygons.push_back({f[0], f[1], f[2]});
    // Non-manifold edges or vertices: CGAL's orientation splits them so the soup is a surface.
    if (!PMP::is_polygon_soup_a_polygon_mesh(polygons)) PMP::orient_polygon_soup(points, polygons);
    SurfaceMesh out;
    PMP::polygon_soup_to_polygon_mesh(points, polygons, out);
    if (out.is_empty() || !CGAL::is_triangle_mesh(out) || !out.is_valid(false))
        throw InputError(source, 0, "remesh: the mesh cannot be made a manifold surface");
    return out;
}

TriMesh toTriMesh(const SurfaceMesh& mesh, const std::string& name) {
    TriMesh out;
    out.name = name;
    std::vector<Index> index(mesh.number_of_vertices() + mesh.number_of_removed_vertices(), Index(-1));
    for (SurfaceMesh::Vertex_index v : mesh.vertices()) {
        index[std::size_t(v)] = Index(out.vertices.size());
        const Point& p = mesh.point(v);
        out.vertices.emplace_back(p.x(), p.y(), p.z());
    }
    for (SurfaceMesh::Face_index f : mesh.faces()) {
        Face face{};
        std::size_t k = 0;
        for (SurfaceMesh::Vertex_index v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) face[k++] = index[std::size_t(v)];
        out.faces.push_back(face);
    }
    return out;
}

// Feature and border edges of `mesh`, marked in its "e:constrained" map; returns their number.
std::size_t markConstrainedEdges(SurfaceMesh& mesh, double featureAngle,
                                 SurfaceMesh::Property_map<SurfaceMesh::Edge_index, bool>& constrained) {
    PMP::detect_sharp_edges(mesh, featureAngle, constrained);
    std::size_t count = 0;
    for (SurfaceMesh::Edge_index e : mesh.edges()) {
        if (mesh.is_border(e)) constrained[e] = true;
        count += constrained[e] ? 1 : 0;
    }
    return count;
}

// Faces removed after remeshing: caps (an angle above kCapAngle degrees) and needles (longest
// over shortest edge above kNeedleRatio, the short one below kNeedleEdge of the target).
constexpr double kCapAngle = 160.0;
constexpr double kNeedleRatio = 4.0;
constexpr double kNeedleEdge = 0.2;

// The Hausdorff distance's samples: vertices, and points on a grid over every edge and face
// at this share of the target edge (deterministic, unlike random sampling).
constexpr double kSampleShare = 0.25;

// Farthest distance from `from`'s samples to `to`.
double farthestSample(const SurfaceMesh& from, const SurfaceMesh& to, double spacing) {
    std::vector<Point> samples;
    PMP::sample_triangle_mesh(from, std::back_inserter(samples), CGAL::parameters::use_grid_sampling(true).grid_spacing(spacing));
    return PMP::max_distance_to_triangle_mesh<CGAL::Sequential_tag>(samples, to);
}

// The symmetric Hausdorff distance, from samples `spacing` apart: a lower bound of the true one,
// short of it by at most about the spacing.
double sampledHausdorff(const SurfaceMesh& a, const SurfaceMesh& b, double spacing) {
    return std::max(farthestSample(a, b, spacing), farthestSample(b, a, spacing));
}

}  // namespace

MeshQuality measureQuality(const TriMesh& mesh) {
    MeshQuality q;
    q.faces = mesh.faces.size();
    q.minAngle = 180.0;
    std::size_t slivers = 0;
    for (const Face& f : mesh.faces) {
        const double angle = smallestAngle(mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]);
        q.minAngle = std::min(q.minAngle, angle);
        slivers += angle < 20.0 ? 1 : 0;
    }
    q.slivers = mesh.faces.empty() ? 0.0 : double(slivers) / double(mesh.faces.size());
    // Each edge once: the faces' edges, keyed by their vertices.
    std::vector<std::uint64_t> keys;
    keys.reserve(3 * mesh.faces.size());
    for (const Face& f : mesh.faces)
        for (int k = 0; k < 3; ++k) keys.push_back(std::uint64_t(std::min(f[k], f[(k + 1) % 3])) << 32 | std::max(f[k], f[(k + 1) % 3]));
    std::sort(keys.begin(), keys.end());
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
    double sum = 0.0, sum2 = 0.0;
    q.minEdge = std::numeric_limits<double>::infinity();
    for (std::uint64_t key : keys) {
        const double length = (mesh.vertices[key >> 32] - mesh.vertices[key & 0xffffffffu]).norm();
        q.minEdge = std::min(q.minEdge, length);
        q.maxEdge = std::max(q.maxEdge, length);
        sum += length;
        sum2 += length * length;
    }
    if (keys.empty()) return q;
    const double n = double(keys.size());
    q.meanEdge = sum / n;
    q.edgeSpread = q.meanEdge > 0.0 ? std::sqrt(std::max(0.0, sum2 / n - q.meanEdge * q.meanEdge)) / q.meanEdge : 0.0;
    return q;
}

namespace {

// The most triangles a remesh may make: about a minute and a few GB with CGAL here (the heart at
// 917,000 took 58 s); more is a unit mistaken, not a simulation surface.
constexpr double kMaxRemeshTriangles = 2e6;

// Refuses a target edge that would make more than kMaxRemeshTriangles (the surface's area over
// an equilateral triangle's), or that the coordinates barely resolve (below 10^4 units in the
// last place of the largest one: splitting edges of 1e-10 at x = 1e6, where a unit in the last
// place is 1.2e-10, made CGAL take memory without end).
void checkRemeshSize(const TriMesh& mesh, double edge, const std::string& source) {
    double area = 0.0, largest = 0.0;
    for (const Face& f : mesh.faces) area += faceArea(mesh.vertices, f);
    for (const Vec3& p : mesh.vertices) largest = std::max(largest, p.cwiseAbs().maxCoeff());
    const double triangles = area / (std::sqrt(3.0) / 4.0 * edge * edge);
    std::ostringstream text;
    if (edge < 1e4 * std::numeric_limits<double>::epsilon() * largest)
        text << "remesh: the target edge length " << edge << " is below 10^4 units in the last place of the largest coordinate ("
             << largest << "): the coordinates cannot resolve it";
    else if (!(triangles <= kMaxRemeshTriangles))
        text << "remesh: the target edge length " << edge << " would make about " << std::llround(std::min(triangles, 1e18))
             << " triangles (the surface's area " << area << " over equilateral triangles of that edge), more than "
             << kMaxRemeshTriangles << ": use a longer edge";
    else
        return;
    throw InputError(source, 0, text.str());
}

RemeshResult remeshChecked(const TriMesh& mesh, const RemeshOptions& options, const std::string& source) {
    RemeshResult r;
    r.diagonal = boundingBox(mesh).diagonal().norm();
    if (!(options.targetEdge > 0.0) || !std::isfinite(options.targetEdge))
        throw InputError(source, 0, "remesh: the target edge length must be a finite number > 0");
    if (options.targetEdge < 1e-4 * r.diagonal) {
        std::ostringstream text;
        text << "remesh: the target edge length " << options.targetEdge << " is below 1e-4 of the part's size (" << r.diagonal
             << "): more than ~10^8 triangles";
        throw InputError(source, 0, text.str());
    }
    checkRemeshSize(mesh, options.targetEdge, source);
    if (options.iterations < 1 || options.iterations > 100) throw InputError(source, 0, "remesh: iterations must be 1 to 100");
    if (!(options.featureAngle > 0.0 && options.featureAngle < 180.0))
        throw InputError(source, 0, "remesh: the feature angle must be between 0 and 180 degrees");
    r.before = measureQuality(mesh);
    const SurfaceMesh input = toSurfaceMesh(mesh, source);
    SurfaceMesh work = input;
    auto constrained = work.add_property_map<SurfaceMesh::Edge_index, bool>("e:constrained", false).first;
    r.featureEdges = markConstrainedEdges(work, options.featureAngle, constrained);
    PMP::isotropic_remeshing(faces(work), options.targetEdge, work,
                             CGAL::parameters::number_of_iterations(unsigned(options.iterations))
                                 .edge_is_constrained_map(constrained)
                                 .relax_constraints(true));
    // Where constrained polylines meet, a few needles and caps can remain: collapsed or
    // flipped away (CGAL's cap/needle removal, features kept).
    PMP::experimental::remove_almost_degenerate_faces(work, std::cos(kCapAngle * M_PI / 180.0), kNeedleRatio, kNeedleEdge * options.targetEdge,
                                                      CGAL::parameters::edge_is_constrained_map(constrained));
    work.collect_garbage();
    r.mesh = toTriMesh(work, mesh.name);
    // What is still degenerate by validateMesh's test (three vertices of one constrained
    // polyline, nearly collinear) is dropped and counted.
    const MeshRepairs repairs = repairMesh(r.mesh, 0.0, source);
    r.droppedFaces = repairs.degenerateFaces + repairs.duplicateFaces;
    r.after = measureQuality(r.mesh);
    r.hausdorff = sampledHausdorff(input, work, kSampleShare * options.targetEdge);
    validateMesh(r.mesh, source);
    return r;
}

}  // namespace

RemeshResult remeshForSimulation(const TriMesh& mesh, const RemeshOptions& options, const std::string& source) {
    // CGAL reports a violated precondition by throwing (CGAL::Failure_exception): it becomes the
    // user's error, naming the file, never an abort.
    try {
        return remeshChecked(mesh, options, source);
    } catch (const CGAL::Failure_exception& e) {
        throw InputError(source, 0, "remesh: CGAL could not remesh this surface (" + e.message() + ")");
    }
}

}  // namespace flexfit
