// Simulation remeshing (remesh.hpp) with CGAL's Polygon Mesh Processing. Compiled apart from
// the rest of the library (src/CMakeLists.txt): CGAL's usage requirements (-frounding-math)
// stay in this file and do not reach the step kernels.
#include "flexfit/remesh.hpp"
#include "flexfit/mesh_repair.hpp"
#include "core/parallel.hpp"
#include "geometry/remesh_samples.hpp"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/distance.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/tangential_relaxation.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <vector>

namespace flexfit {
namespace {

using detail::forChunks;

namespace PMP = CGAL::Polygon_mesh_processing;

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using VertexIndex = SurfaceMesh::Vertex_index;
using EdgeIndex = SurfaceMesh::Edge_index;
using FaceIndex = SurfaceMesh::Face_index;
using HalfedgeIndex = SurfaceMesh::Halfedge_index;
using EdgeFlags = SurfaceMesh::Property_map<EdgeIndex, bool>;
using VertexFlags = SurfaceMesh::Property_map<VertexIndex, bool>;
using FacePatches = SurfaceMesh::Property_map<FaceIndex, std::size_t>;
using FaceTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CGAL::AABB_face_graph_triangle_primitive<SurfaceMesh>>>;

// Builds a face tree's hierarchy and its distance-query search tree now (CGAL builds both at
// the first query), so that threads then only read it.
void buildForQueries(FaceTree& tree) {
    tree.build();
    tree.accelerate_distance_queries();
    if (!tree.empty()) tree.closest_point(CGAL::ORIGIN);  // the search tree is built at its first search
}

Vec3 toVec3(const Point& p) { return {p.x(), p.y(), p.z()}; }

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
        out.vertices.push_back(toVec3(mesh.point(v)));
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
std::size_t markConstrainedEdges(SurfaceMesh& mesh, double featureAngle, EdgeFlags& constrained) {
    PMP::detect_sharp_edges(mesh, featureAngle, constrained);
    std::size_t count = 0;
    for (EdgeIndex e : mesh.edges()) {
        if (mesh.is_border(e)) constrained[e] = true;
        count += constrained[e] ? 1 : 0;
    }
    return count;
}

// Faces removed after remeshing: caps (an angle above kCapAngle degrees) and needles (longest
// over shortest edge above kNeedleRatio, the short one below kNeedleEdge of the target). A
// triangle with an angle below 20 degrees is one or the other at these bounds (a cap of two
// 20-degree angles has a 140-degree one; a needle's sides are 2.9 times its base).
constexpr double kCapAngle = 120.0;
constexpr double kNeedleRatio = 2.5;
constexpr double kNeedleEdge = 0.6;

// Sharp polylines closer than this share of the target edge cannot be meshed between without
// slivers: a triangle spanning them is at most this high against sides of about the target.
constexpr double kThinFeature = 0.5;
// Rounds of releasing thin features and remeshing again: a round's remeshing can leave new thin
// slivers beside the edges it released (on regr01 the third round still found a few).
constexpr int kReleaseRounds = 3;
// A sliver: a triangle with an angle below this many degrees (MeshQuality::slivers).
constexpr double kSliverAngle = 20.0;
// ThinFeatures::Auto tries rounding when the surface keeping every sharp edge has this share of
// slivers, and keeps the rounded surface when it has fewer, lies within the target edge of the
// input (or no farther than the other) and is closed if the other is.
constexpr double kRoundingShare = 0.01;

// The input surface, split into patches (its faces between sharp edges): every remeshing
// iteration puts each vertex back on the input faces of its own patch, as CGAL's remesher
// does, so a vertex beside a sharp edge stays on its side of it. Once thin features are
// released, a patch of the remeshed surface covers the input patches it merged.
class PatchProjection {
public:
    static constexpr std::size_t kProjectionChunk = 1024;

    PatchProjection(const SurfaceMesh& input, const FacePatches& patch, std::size_t patches) : input_(input), faces_(patches), sources_(patches) {
        for (FaceIndex f : input.faces()) faces_[patch[f]].push_back(f);
        for (std::size_t p = 0; p < patches; ++p) sources_[p] = {p};
        buildTrees();
    }

    // `work`'s patches were relabelled (`before[f]` their old labels, now `patch`): each new
    // patch covers the input patches of the old ones it holds.
    void relabel(const SurfaceMesh& work, const std::vector<std::size_t>& before, const FacePatches& patch, std::size_t patches) {
        std::vector<std::vector<std::size_t>> sources(patches);
        for (FaceIndex f : work.faces()) {
            const std::vector<std::size_t>& old = sources_[before[std::size_t(f)]];
            sources[patch[f]].insert(sources[patch[f]].end(), old.begin(), old.end());
        }
        for (std::vector<std::size_t>& s : sources) {
            std::sort(s.begin(), s.end());
            s.erase(std::unique(s.begin(), s.end()), s.end());
        }
        sources_ = std::move(sources);
        buildTrees();
    }

    // Each vertex on its own (queries of built trees, one point written each): in parallel.
    void project(SurfaceMesh& work, const FacePatches& patch, const VertexFlags& held) const {
        forChunks(work.num_vertices(), kProjectionChunk, [&](std::size_t begin, std::size_t end) {
            for (std::size_t i = begin; i < end; ++i) {
                const VertexIndex v(static_cast<SurfaceMesh::size_type>(i));
                if (work.is_removed(v) || held[v]) continue;
                for (HalfedgeIndex h : CGAL::halfedges_around_target(v, work)) {
                    if (work.is_border(h)) continue;
                    work.point(v) = trees_[patch[work.face(h)]]->closest_point(work.point(v));
                    break;
                }
            }
        });
    }

private:
    void buildTrees() {
        trees_.clear();
        for (const std::vector<std::size_t>& source : sources_) {
            std::vector<FaceIndex> faces;
            for (std::size_t p : source) faces.insert(faces.end(), faces_[p].begin(), faces_[p].end());
            trees_.push_back(std::make_unique<FaceTree>(faces.begin(), faces.end(), input_));
            buildForQueries(*trees_.back());
        }
    }

    const SurfaceMesh& input_;
    std::vector<std::vector<FaceIndex>> faces_;      // per input patch
    std::vector<std::vector<std::size_t>> sources_;  // per patch of the remeshed surface: its input patches
    std::vector<std::unique_ptr<FaceTree>> trees_;   // per patch of the remeshed surface
};

// The surface being remeshed, with its kept edges (sharp or border: CGAL's constrained edges),
// its held vertices (seams, below: not moved at all) and its faces' patch labels, which CGAL
// carries through splits and flips.
struct WorkSurface {
    SurfaceMesh mesh;
    EdgeFlags kept;
    VertexFlags held;
    FacePatches patch;

    explicit WorkSurface(const SurfaceMesh& from)
        : mesh(from), kept(mesh.add_property_map<EdgeIndex, bool>("e:constrained", false).first),
          held(mesh.add_property_map<VertexIndex, bool>("v:held", false).first),
          patch(mesh.add_property_map<FaceIndex, std::size_t>("f:patch", 0).first) {}
    WorkSurface(const WorkSurface& other)
        : mesh(other.mesh), kept(mesh.property_map<EdgeIndex, bool>("e:constrained").first),
          held(mesh.property_map<VertexIndex, bool>("v:held").first), patch(mesh.property_map<FaceIndex, std::size_t>("f:patch").first) {}
};

using Position = std::array<double, 3>;

Position positionOf(const SurfaceMesh& mesh, VertexIndex v) {
    const Point& p = mesh.point(v);
    return {p.x(), p.y(), p.z()};
}

// Positions held by more than one vertex.
std::set<Position> sharedPositions(const SurfaceMesh& mesh) {
    std::map<Position, int> count;
    for (VertexIndex v : mesh.vertices()) ++count[positionOf(mesh, v)];
    std::set<Position> shared;
    for (const auto& [position, n] : count)
        if (n > 1) shared.insert(position);
    return shared;
}

// Seams: where the input had non-manifold edges or vertices (or windings no orientation could
// reconcile), CGAL's polygon-soup orientation split it into sheets, a copy of the vertices on
// each. Remeshed apart, the copies drift (collapsed, slid along their polylines) and the junction
// opens into cracks. So every edge both of whose end positions another edge also joins is cut
// at its midpoints (the same points on every sheet) until no longer than the longest edge the
// remeshing keeps (4/3 L), kept as a sharp edge, and every vertex at a shared position held
// where it is: the copies stay bit-identical, and repairMesh welds them back into the input's
// junction. Returns the vertices held.
std::size_t holdSeams(WorkSurface& s, double targetEdge) {
    const std::set<Position> shared = sharedPositions(s.mesh);
    if (shared.empty()) return 0;
    using Join = std::pair<Position, Position>;
    std::map<Join, int> joins;
    auto key = [&s](EdgeIndex e) {
        const Position a = positionOf(s.mesh, s.mesh.vertex(e, 0)), b = positionOf(s.mesh, s.mesh.vertex(e, 1));
        return a < b ? Join{a, b} : Join{b, a};  // by value: std::minmax would return references to these
    };
    for (EdgeIndex e : s.mesh.edges())
        if (shared.count(positionOf(s.mesh, s.mesh.vertex(e, 0))) && shared.count(positionOf(s.mesh, s.mesh.vertex(e, 1)))) ++joins[key(e)];
    std::vector<EdgeIndex> seam;
    for (EdgeIndex e : s.mesh.edges()) {
        const auto found = joins.find(key(e));
        if (found == joins.end() || found->second < 2) continue;
        seam.push_back(e);
        s.kept[e] = true;
    }
    PMP::split_long_edges(seam, 4.0 / 3.0 * targetEdge, s.mesh, CGAL::parameters::edge_is_constrained_map(s.kept));
    const std::set<Position> held = sharedPositions(s.mesh);
    std::size_t count = 0;
    for (VertexIndex v : s.mesh.vertices()) {
        s.held[v] = held.count(positionOf(s.mesh, v)) > 0;
        count += s.held[v] ? 1 : 0;
    }
    return count;
}

// Labels the faces by patch (connected across edges not kept); returns their number.
std::size_t labelPatches(WorkSurface& s) {
    return PMP::connected_components(s.mesh, s.patch, CGAL::parameters::edge_is_constrained_map(s.kept));
}

// One iteration of isotropic remeshing at a time: CGAL's split, collapse and flip, then our
// own call of its tangential relaxation and projection. CGAL 5.5.1's relaxation inside
// isotropic_remeshing reads its constraint map at an invalid edge for a vertex whose faces are
// all degenerate (a read far past a property array: a segfault on regr01 when a remeshed
// surface was remeshed again); given a map that answers such an edge, the same relaxation is safe.
void remeshIterations(WorkSurface& s, const RemeshOptions& options, const PatchProjection& projection) {
    SurfaceMesh& work = s.mesh;
    auto notMoved = [&work](VertexIndex v) { return work.point(v); };  // never called: do_project(false)
    auto keptEdge = [&s](EdgeIndex e) { return std::size_t(e) < s.mesh.num_edges() && (s.kept[e] || s.mesh.is_border(e)); };
    for (int i = 0; i < options.iterations; ++i) {
        PMP::isotropic_remeshing(faces(work), options.targetEdge, work,
                                 CGAL::parameters::number_of_iterations(1)
                                     .number_of_relaxation_steps(0)
                                     .do_project(false)
                                     .projection_functor(notMoved)
                                     .edge_is_constrained_map(s.kept)
                                     .vertex_is_constrained_map(s.held)
                                     .face_patch_map(s.patch)
                                     .relax_constraints(true));
        PMP::tangential_relaxation(vertices(work), work,
                                   CGAL::parameters::number_of_iterations(1)
                                       .edge_is_constrained_map(boost::make_function_property_map<EdgeIndex>(keptEdge))
                                       .vertex_is_constrained_map(s.held)
                                       .relax_constraints(true));
        projection.project(work, s.patch, s.held);
    }
}

// Where sharp polylines meet, needles and caps can remain: collapsed or flipped away (CGAL's
// cap/needle removal, kept edges kept).
void removeCapsAndNeedles(WorkSurface& s, double targetEdge) {
    PMP::experimental::remove_almost_degenerate_faces(s.mesh, std::cos(kCapAngle * M_PI / 180.0), kNeedleRatio, kNeedleEdge * targetEdge,
                                                      CGAL::parameters::edge_is_constrained_map(s.kept).vertex_is_constrained_map(s.held));
    s.mesh.collect_garbage();
}

double smallestAngle(const SurfaceMesh& mesh, HalfedgeIndex h) {
    return smallestAngle(toVec3(mesh.point(mesh.source(h))), toVec3(mesh.point(mesh.target(h))), toVec3(mesh.point(mesh.target(mesh.next(h)))));
}

// A sliver whose three vertices lie on sharp polylines, lower than kThinFeature of the target
// edge: two polylines (or one folded back) closer than the triangles can span. The sharp edges
// at its vertices stop being kept; returns how many.
std::size_t releaseThinFeatures(WorkSurface& s, double targetEdge) {
    SurfaceMesh& work = s.mesh;
    EdgeFlags& constrained = s.kept;
    std::vector<char> onPolyline(work.num_vertices(), 0);
    for (EdgeIndex e : work.edges())
        if (constrained[e]) onPolyline[std::size_t(work.vertex(e, 0))] = onPolyline[std::size_t(work.vertex(e, 1))] = 1;
    std::vector<VertexIndex> corners;
    for (FaceIndex f : work.faces()) {
        const HalfedgeIndex h = work.halfedge(f);
        if (smallestAngle(work, h) >= kSliverAngle) continue;
        double longest = 0.0;
        bool allOnPolylines = true;
        for (HalfedgeIndex k : CGAL::halfedges_around_face(h, work)) {
            longest = std::max(longest, std::sqrt(CGAL::squared_distance(work.point(work.source(k)), work.point(work.target(k)))));
            allOnPolylines = allOnPolylines && onPolyline[std::size_t(work.target(k))];
        }
        const Point& a = work.point(work.source(h));
        const double height = std::sqrt(CGAL::cross_product(work.point(work.target(h)) - a, work.point(work.target(work.next(h))) - a).squared_length()) / longest;
        if (!allOnPolylines || height >= kThinFeature * targetEdge) continue;
        for (VertexIndex v : CGAL::vertices_around_face(h, work)) corners.push_back(v);
    }
    std::size_t released = 0;
    for (VertexIndex v : corners)
        for (HalfedgeIndex h : CGAL::halfedges_around_target(v, work))
            if (constrained[work.edge(h)] && !work.is_border(work.edge(h))) {
                constrained[work.edge(h)] = false;
                ++released;
            }
    return released;
}

// Rounds of releasing thin features and remeshing again; returns the edges released.
std::size_t roundThinFeatures(WorkSurface& s, const RemeshOptions& options, PatchProjection& projection) {
    std::size_t total = 0;
    for (int round = 0; round < kReleaseRounds; ++round) {
        const std::size_t released = releaseThinFeatures(s, options.targetEdge);
        if (released == 0) break;
        total += released;
        std::vector<std::size_t> before(s.mesh.num_faces());
        for (FaceIndex f : s.mesh.faces()) before[std::size_t(f)] = s.patch[f];
        projection.relabel(s.mesh, before, s.patch, labelPatches(s));
        remeshIterations(s, options, projection);
    }
    removeCapsAndNeedles(s, options.targetEdge);
    return total;
}

// A remeshed surface as returned: what is still of zero area by validateMesh's test (three
// vertices of one kept polyline, nearly collinear) dropped and counted, which can open it.
// `slivers` is the remeshed surface's share of slivers before that (what Auto compares).
struct FinishedSurface {
    TriMesh mesh;
    double slivers = 0.0;
    std::size_t dropped = 0;
    bool closed = false;
};

FinishedSurface finish(const WorkSurface& s, const std::string& name, const std::string& source) {
    FinishedSurface f{toTriMesh(s.mesh, name)};
    f.slivers = measureQuality(f.mesh).slivers;
    const MeshRepairs repairs = repairMesh(f.mesh, 0.0, source);
    f.dropped = repairs.degenerateFaces + repairs.duplicateFaces;
    f.closed = validateMesh(f.mesh, source).closed();
    return f;
}

// The Hausdorff distance's samples: vertices, and points at most this share of the target edge
// apart along every edge and across every face (deterministic, unlike random sampling), and at
// most kSampleShare of kCoarseRemeshEdgeShare (remesh.hpp) of the diagonal: a target edge far beyond the part's size
// (1e6 on a torus of diagonal 36) spaced them so far apart that the distance read 5.8 where
// a target of 50 read 7.7 on the same output.
constexpr double kSampleShare = 0.25;

// Points of segment ab strictly between its ends, at most `spacing` apart.
void sampleBetween(const Point& a, const Point& b, double spacing, std::vector<Point>& out) {
    const std::size_t pieces = std::size_t(std::ceil(std::sqrt(CGAL::squared_distance(a, b)) / spacing));
    for (std::size_t k = 1; k < pieces; ++k) out.push_back(a + (b - a) * (double(k) / double(pieces)));
}

// Points of the triangle's interior in rows parallel to its longest edge ab (apex c), rows and
// points at most `spacing` apart: about area / spacing^2 points. (CGAL's grid sampling lays
// its grid along two edges of a face: a needle of length l got about (l / spacing)^2 / 2
// points whatever its area, 5.9 million for regr01's input at 1 % of its size.)
void sampleInterior(const Point& a, const Point& b, const Point& c, double spacing, std::vector<Point>& out) {
    const double base = std::sqrt(CGAL::squared_distance(a, b));
    if (!(base > 0.0)) return;
    const double height = std::sqrt(CGAL::cross_product(b - a, c - a).squared_length()) / base;
    const std::size_t rows = std::size_t(std::ceil(height / spacing));
    for (std::size_t k = 1; k < rows; ++k) {
        const double t = double(k) / double(rows);
        sampleBetween(a + (c - a) * t, b + (c - b) * t, spacing, out);
    }
}

// detail::hausdorffSamples (remesh_samples.hpp), on CGAL's surface.
std::vector<Point> surfaceSamples(const SurfaceMesh& mesh, double spacing) {
    std::vector<Point> out;
    for (VertexIndex v : mesh.vertices()) out.push_back(mesh.point(v));
    for (EdgeIndex e : mesh.edges()) sampleBetween(mesh.point(mesh.vertex(e, 0)), mesh.point(mesh.vertex(e, 1)), spacing, out);
    for (FaceIndex f : mesh.faces()) {
        std::array<Point, 3> p;
        std::size_t i = 0;
        for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) p[i++] = mesh.point(v);
        std::size_t longest = 0;  // the edge p[longest] -> p[longest + 1]
        for (std::size_t k = 1; k < 3; ++k)
            if (CGAL::squared_distance(p[k], p[(k + 1) % 3]) > CGAL::squared_distance(p[longest], p[(longest + 1) % 3])) longest = k;
        sampleInterior(p[longest], p[(longest + 1) % 3], p[(longest + 2) % 3], spacing, out);
    }
    return out;
}

// A face tree of `mesh`, ready for queries from several threads.
std::unique_ptr<FaceTree> faceTreeOf(const SurfaceMesh& mesh) {
    auto tree = std::make_unique<FaceTree>(faces(mesh).first, faces(mesh).second, mesh);
    buildForQueries(*tree);
    return tree;
}

// Farthest distance from `samples` to the tree's faces, in parallel: each chunk of samples
// searches from its first sample's closest point on, as CGAL's max_distance_to_triangle_mesh
// does from the last one (the same distances: a hint only starts the search).
double farthestSample(const std::vector<Point>& samples, const FaceTree& to) {
    constexpr std::size_t kChunk = 4096;
    if (samples.empty()) return 0.0;
    if (to.empty()) return std::numeric_limits<double>::infinity();
    std::vector<double> farthest((samples.size() + kChunk - 1) / kChunk, 0.0);  // squared, per chunk
    forChunks(samples.size(), kChunk, [&](std::size_t begin, std::size_t end) {
        Point hint = to.closest_point(samples[begin]);
        for (std::size_t i = begin; i < end; ++i) {
            hint = to.closest_point(samples[i], hint);
            farthest[begin / kChunk] = std::max(farthest[begin / kChunk], CGAL::squared_distance(hint, samples[i]));
        }
    });
    return std::sqrt(*std::max_element(farthest.begin(), farthest.end()));
}

// The input surface's side of the symmetric Hausdorff distance, from samples `spacing` apart
// (a lower bound of the true distance, short of it by at most about the spacing): its samples
// and face tree, made once for every surface measured against it.
class HausdorffFrom {
public:
    HausdorffFrom(const SurfaceMesh& input, double spacing)
        : spacing_(spacing), samples_(surfaceSamples(input, spacing)), tree_(faceTreeOf(input)) {}

    double to(const SurfaceMesh& other) const {
        return std::max(farthestSample(samples_, *faceTreeOf(other)), farthestSample(surfaceSamples(other, spacing_), *tree_));
    }

private:
    double spacing_;
    std::vector<Point> samples_;
    std::unique_ptr<FaceTree> tree_;
};

}  // namespace

MeshQuality measureQuality(const TriMesh& mesh) {
    MeshQuality q;
    q.faces = mesh.faces.size();
    q.minAngle = 180.0;
    std::size_t slivers = 0;
    for (const Face& f : mesh.faces) {
        const double angle = smallestAngle(mesh.vertices[f[0]], mesh.vertices[f[1]], mesh.vertices[f[2]]);
        q.minAngle = std::min(q.minAngle, angle);
        slivers += angle < kSliverAngle ? 1 : 0;
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

std::vector<Vec3> detail::hausdorffSamples(const TriMesh& mesh, double spacing) {
    std::vector<Vec3> out;
    for (const Point& p : surfaceSamples(toSurfaceMesh(mesh, mesh.name), spacing)) out.push_back(toVec3(p));
    return out;
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
        throw InputError(source, 0, "remesh: the feature angle must be strictly between 0 and 180 degrees");
    r.before = measureQuality(mesh);
    const SurfaceMesh input = toSurfaceMesh(mesh, source);
    WorkSurface work(input);
    r.featureEdges = markConstrainedEdges(work.mesh, options.featureAngle, work.kept);
    r.seamVertices = holdSeams(work, options.targetEdge);
    // `work`'s faces of `input`'s indices lie within those faces (seams were only cut), so the
    // labels, numbered in face order, are the input faces' too.
    const std::size_t patches = labelPatches(work);
    PatchProjection projection(input, work.patch, patches);
    remeshIterations(work, options, projection);
    removeCapsAndNeedles(work, options.targetEdge);
    const HausdorffFrom fromInput(input, kSampleShare * std::min(options.targetEdge, kCoarseRemeshEdgeShare * r.diagonal));
    r.hausdorff = fromInput.to(work.mesh);
    FinishedSurface result = finish(work, mesh.name, source);
    const bool round = options.thinFeatures == ThinFeatures::Round;
    if (round || (options.thinFeatures == ThinFeatures::Auto && result.slivers >= kRoundingShare)) {
        WorkSurface rounded(work);
        r.releasedEdges = roundThinFeatures(rounded, options, projection);
        r.roundedHausdorff = fromInput.to(rounded.mesh);
        FinishedSurface roundedResult = finish(rounded, mesh.name, source);
        r.rounded = round || (r.roundedHausdorff <= std::max(r.hausdorff, options.targetEdge) && roundedResult.slivers < result.slivers &&
                              (roundedResult.closed || !result.closed));
        if (r.rounded) {
            result = std::move(roundedResult);
            r.hausdorff = r.roundedHausdorff;
        }
    }
    r.mesh = std::move(result.mesh);
    r.droppedFaces = result.dropped;
    r.after = measureQuality(r.mesh);
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
