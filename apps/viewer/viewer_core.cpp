#include "viewer_core.hpp"

#include "flexfit/surface_embedding.hpp"

#include <algorithm>
#include <cmath>

namespace flexfit::viewer {

// --- Camera ---

Vec3 Camera::eye() const {
    const Vec3 back(std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw));
    return target + distance * back;
}

Mat4 Camera::view() const {
    const Vec3 e = eye();
    const Vec3 f = (target - e).normalized();
    const Vec3 s = f.cross(Vec3::UnitY()).normalized();
    const Vec3 u = s.cross(f);
    Mat4 m = Mat4::Identity();
    m.block<1, 3>(0, 0) = s.transpose();
    m.block<1, 3>(1, 0) = u.transpose();
    m.block<1, 3>(2, 0) = -f.transpose();
    m(0, 3) = -s.dot(e);
    m(1, 3) = -u.dot(e);
    m(2, 3) = f.dot(e);
    return m;
}

Mat4 Camera::projection() const {
    const double nearPlane = std::max(1e-3, distance * 0.01), farPlane = distance * 100.0 + 100.0;
    const double t = 1.0 / std::tan(fovY / 2.0), aspect = double(width) / double(std::max(height, 1));
    Mat4 p = Mat4::Zero();
    p(0, 0) = t / aspect;
    p(1, 1) = t;
    p(2, 2) = (farPlane + nearPlane) / (nearPlane - farPlane);
    p(2, 3) = 2.0 * farPlane * nearPlane / (nearPlane - farPlane);
    p(3, 2) = -1.0;
    return p;
}

std::optional<Eigen::Vector3d> Camera::project(const Vec3& world) const {
    const Eigen::Vector4d clip = projection() * view() * world.homogeneous();
    if (clip.w() <= 0.0) return std::nullopt;
    const Vec3 ndc = clip.head<3>() / clip.w();
    return Eigen::Vector3d((ndc.x() + 1.0) * 0.5 * width, (1.0 - ndc.y()) * 0.5 * height, (ndc.z() + 1.0) * 0.5);
}

Camera::Ray Camera::rayThrough(double px, double py) const {
    const Mat4 inverse = (projection() * view()).inverse();
    const double x = 2.0 * px / width - 1.0, y = 1.0 - 2.0 * py / height;
    const Eigen::Vector4d nearPoint = inverse * Eigen::Vector4d(x, y, -1.0, 1.0);
    const Eigen::Vector4d farPoint = inverse * Eigen::Vector4d(x, y, 1.0, 1.0);
    const Vec3 a = nearPoint.head<3>() / nearPoint.w(), b = farPoint.head<3>() / farPoint.w();
    return {eye(), (b - a).normalized()};
}

void Camera::orbit(double dx, double dy) {
    yaw -= dx * 0.008;
    pitch = std::clamp(pitch + dy * 0.008, -1.5, 1.5);
}

void Camera::pan(double dx, double dy) { target = dragInViewPlane(target, -dx, -dy); }

void Camera::zoom(double factor) { distance = std::clamp(distance * factor, 1e-3, 1e6); }

void Camera::frame(const Vec3& centre, double radius) {
    target = centre;
    const double halfAngle = 0.5 * std::min(fovY, fovY * double(width) / double(std::max(height, 1)));
    distance = std::max(radius, 1e-3) / std::sin(halfAngle) * 1.05;
}

Vec3 Camera::dragInViewPlane(const Vec3& anchor, double dx, double dy) const {
    const Mat4 v = view();
    const Vec3 right = v.block<1, 3>(0, 0).transpose(), up = v.block<1, 3>(1, 0).transpose();
    const double depth = (anchor - eye()).dot((target - eye()).normalized());
    const double worldPerPixel = 2.0 * depth * std::tan(fovY / 2.0) / double(std::max(height, 1));
    return anchor + worldPerPixel * (dx * right - dy * up);
}

Camera initialCamera(const World& world, int width, int height) {
    Camera camera;
    camera.width = width;
    camera.height = height;
    camera.yaw = 0.5;
    camera.pitch = 0.52;
    Eigen::AlignedBox3d box;
    std::vector<Vec3> positions;
    for (BodyId id = 0; id < world.bodyCount(); ++id) {
        world.part(id).worldPositions(positions);
        for (const Vec3& p : positions) box.extend(p);
    }
    if (box.isEmpty()) return camera;
    camera.frame(box.center(), 0.5 * box.diagonal().norm() * 0.8);
    return camera;
}

Vec3 partColour(const Part& part, MotionType motion) {
    if (part.deforms()) return {0.55, 0.66, 0.86};          // deformable: blue
    return motion == MotionType::Static ? Vec3(0.62, 0.62, 0.64) : Vec3(0.90, 0.58, 0.30);  // grey / orange
}

Vec3 zoneColour(int depth, int deepest) {
    const double s = deepest > 0 ? double(depth) / double(deepest) : 0.0;
    return Vec3(0.05, 0.92, 0.12) * (1.0 - s) + Vec3(0.30, 0.70, 0.28) * s;
}

// --- Picking ---

std::optional<double> intersectRayTriangle(const Camera::Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 e1 = b - a, e2 = c - a;
    const Vec3 p = ray.direction.cross(e2);
    const double det = e1.dot(p);
    if (std::abs(det) < 1e-14 * e1.norm() * e2.norm()) return std::nullopt;
    const Vec3 s = ray.origin - a;
    // A hair of tolerance: a ray through a shared vertex or edge must not slip between faces.
    constexpr double kSlack = 1e-9;
    const double u = s.dot(p) / det;
    if (u < -kSlack || u > 1.0 + kSlack) return std::nullopt;
    const Vec3 q = s.cross(e1);
    const double v = ray.direction.dot(q) / det;
    if (v < -kSlack || u + v > 1.0 + kSlack) return std::nullopt;
    const double t = e2.dot(q) / det;
    return t > 0.0 ? std::optional<double>(t) : std::nullopt;
}

std::optional<Pick> pick(const World& world, const Camera::Ray& ray) {
    std::optional<Pick> best;
    std::vector<Vec3> positions;
    for (BodyId id = 0; id < world.bodyCount(); ++id) {
        const Part& part = world.part(id);
        part.worldPositions(positions);
        const auto& faces = part.model().mesh.faces;
        for (Index f = 0; f < faces.size(); ++f) {
            const auto t = intersectRayTriangle(ray, positions[faces[f][0]], positions[faces[f][1]], positions[faces[f][2]]);
            if (!t || (best && *t >= best->distance)) continue;
            Pick hit;
            hit.body = id;
            hit.face = f;
            hit.distance = *t;
            hit.point = ray.origin + *t * ray.direction;
            hit.mass = *std::min_element(faces[f].begin(), faces[f].end(), [&](Index x, Index y) {
                return (positions[x] - hit.point).squaredNorm() < (positions[y] - hit.point).squaredNorm();
            });
            best = hit;
        }
    }
    return best;
}

// --- Normals ---

namespace {
Vec3 faceNormalTimesTwoArea(std::span<const Vec3> x, const Face& f) { return (x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]); }
}  // namespace

std::vector<Vec3> vertexNormals(std::span<const Face> faces, std::span<const Vec3> x) {
    std::vector<Vec3> n(x.size(), Vec3::Zero());
    for (const Face& f : faces) {
        const Vec3 fn = faceNormalTimesTwoArea(x, f);
        for (Index v : f) n[v] += fn;
    }
    for (Vec3& v : n) v = v.norm() > 0.0 ? Vec3(v.normalized()) : Vec3(Vec3::UnitY());
    return n;
}

std::vector<Vec3> SurfaceNormals::computeAll(const Part& part) {
    return vertexNormals(part.model().mesh.faces, part.state().positions);
}

void showPart(const Part& part, const std::vector<Vec3>& massNormals, const std::vector<Vec3>& massColours, ShownSurface& out) {
    const PartModel& model = part.model();
    const auto& drawn = model.drawn;
    if (!drawn) {  // the masses, in the user's vertex order (drawnMesh()'s faces)
        part.drawnPositions(out.positions);
        inVertexOrder<Vec3>(model, massNormals, out.normals, [](Index) { return Vec3(Vec3::UnitY()); });
        inVertexOrder<Vec3>(model, massColours, out.colours);  // a removed file vertex: black, in no face
        return;
    }
    part.drawnPositions(out.positions);
    out.normals = vertexNormals(drawn->mesh.faces, out.positions);
    out.colours.resize(out.positions.size());
    for (std::size_t v = 0; v < out.colours.size(); ++v) out.colours[v] = massColours[drawn->nearestMass[v]];
}

std::shared_ptr<const PartModel> withMaterial(const PartModel& old, const Material& material) {
    PartModelSettings settings;
    settings.material = material;
    inGivenVertexOrder<double>(old, old.mass, settings.vertexMasses);
    settings.vertexOrder = old.renumbered() ? VertexOrder::Locality : VertexOrder::AsGiven;
    if (old.drawn) settings.drawnMesh = old.drawn->mesh;
    if (old.file) settings.fileVertices = old.file->vertices;
    return buildPartModel(old.givenMesh ? *old.givenMesh : old.mesh, settings);
}

std::span<const Index> MovedMasses::update(const Part& part) {
    const auto moving = part.movingMasses();
    moved_.assign(moving.begin(), moving.end());
    moved_.insert(moved_.end(), previous_.begin(), previous_.end());
    previous_.assign(moving.begin(), moving.end());
    return moved_;
}

SurfaceNormals::SurfaceNormals(const Part& part) : normals_(computeAll(part)), ring_(part.model().massCount()) {}

bool SurfaceNormals::update(const Part& part) {
    recomputed_ = 0;
    const std::span<const Index> moved = moved_.update(part);
    if (moved.empty()) return false;
    // A vertex's normal depends on its own position and its neighbours': the 1-ring of the
    // moved masses, each vertex once.
    const Topology& topology = part.model().topology;
    ring_.clear();
    for (Index seed : moved) {
        ring_.insert(seed);
        for (Index n : topology.neighborsOf(seed)) ring_.insert(n);
    }
    const auto& faces = part.model().mesh.faces;
    for (Index mass : ring_) {
        Vec3 sum = Vec3::Zero();
        for (Index f : topology.facesOf(mass)) sum += faceNormalTimesTwoArea(part.state().positions, faces[f]);
        normals_[mass] = sum.norm() > 0.0 ? Vec3(sum.normalized()) : Vec3(Vec3::UnitY());
    }
    recomputed_ = ring_.size();
    return true;
}

// --- Hierarchies for drawing ---

DisplayHierarchy::DisplayHierarchy(const Part& part, const PartCollider& like)
    : collider_(part, like.kind(), like.exactTest()), moved_(part.movingMasses()) {}

void DisplayHierarchy::update(const Part& part) {
    const std::span<const Index> moved = moved_.update(part);
    if (!moved.empty()) collider_.refit(part, moved);
}

// --- Session ---

Session::Session(Scene scene) : scene_(std::move(scene)) { reset(); }

void Session::reset() {
    run_ = std::make_unique<SceneRun>(scene_);
    owed_ = 0.0;
    steps_ = 0;
    massForce_.reset();
}

void Session::singleStep() {
    if (massForce_ && massForce_->onFace) world().applyFaceForce(massForce_->body, massForce_->index, massForce_->force);
    if (massForce_ && !massForce_->onFace) world().applyMassForce(massForce_->body, massForce_->index, massForce_->force);
    run_->step();
    ++steps_;
}

void Session::advance(double wallSeconds) {
    if (paused) return;
    const double h = scene_.world.timeStep;
    owed_ += wallSeconds * speed;
    int taken = 0;
    while (owed_ >= h * (1.0 - 1e-9) && taken < maxStepsPerFrame) {
        singleStep();
        owed_ -= h;
        ++taken;
    }
    if (taken == maxStepsPerFrame) owed_ = 0.0;  // behind real time: drop the debt, do not spiral
}

void Session::grab(BodyId body, const Vec3& worldPoint) {
    World& w = world();
    w.grab(body);
    grabOffset_ = w.part(body).pose().applyInverse(worldPoint);
    w.setGrabTarget(w.part(body).pose());
}

void Session::dragTo(const Vec3& worldPoint) {
    World& w = world();
    if (!w.grabbed()) return;
    Pose target = w.grabTarget();
    target.translation = worldPoint - target.rotation * grabOffset_;
    w.setGrabTarget(target);
}

void Session::rotateGrabbed(const Vec3& axis, double angle) {
    World& w = world();
    if (!w.grabbed()) return;
    Pose target = w.grabTarget();
    const Vec3 pivot = target.apply(grabOffset_);
    target.rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis.normalized())) * target.rotation).normalized();
    target.translation = pivot - target.rotation * grabOffset_;
    w.setGrabTarget(target);
}

void Session::release() { world().release(); }

std::optional<BodyId> Session::grabbed() const { return world().grabbed(); }

void Session::setMassForce(BodyId body, Index vertex, const Vec3& worldForce) { massForce_ = MassForce{body, vertex, false, worldForce}; }
void Session::setFaceForce(BodyId body, Index face, const Vec3& worldForce) { massForce_ = MassForce{body, face, true, worldForce}; }

}  // namespace flexfit::viewer
