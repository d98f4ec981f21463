// The viewer's parts that need no OpenGL, so tests can run them anywhere: the orbit camera and
// its projections, picking by ray casting, and the session that steps a scene on a fixed time
// step decoupled from the frame rate.
//
// Camera: orbits a target (yaw about +y, pitch clamped short of the poles), pans in the view
// plane, zooms by distance. Pixels have their origin at the top left, y down (window
// convention); OpenGL matrices are column-major Eigen 4x4.
//
// Picking: the ray through a pixel against every face of every part (Moller-Trumbore), the
// nearest hit wins; the picked mass is the hit face's corner nearest the hit point. O(faces)
// per click, which is instant for the scenes we ship (15,000 faces) and needs no hierarchy.
//
// Session: advance(wallSeconds) runs as many world steps as the simulated time owed allows
// (at most maxStepsPerFrame, so a slow machine runs slower than real time instead of
// spiralling); the world steps at its own h (1 kHz in the examples) whatever the frame rate.
// The scene's scripted actions run exactly as in `flexfit run` (same SceneRun); the mouse and
// keyboard add operator actions on top (grab and drag, forces on selected masses).
#pragma once

#include "flexfit/scene_file.hpp"
#include "flexfit/scene_run.hpp"

#include <Eigen/Geometry>

#include <optional>

namespace flexfit::viewer {

using Mat4 = Eigen::Matrix4d;

class Camera {
public:
    Vec3 target = Vec3::Zero();
    double distance = 50.0;
    double yaw = 0.6, pitch = 0.5;  // radians
    double fovY = 45.0 * M_PI / 180.0;
    int width = 1280, height = 800;  // viewport, pixels

    Vec3 eye() const;
    Mat4 view() const;
    Mat4 projection() const;
    // World point to pixel (x right, y down) and depth in [0, 1]; nullopt behind the eye.
    std::optional<Eigen::Vector3d> project(const Vec3& world) const;
    struct Ray {
        Vec3 origin, direction;  // unit direction
    };
    Ray rayThrough(double px, double py) const;

    void orbit(double dxPixels, double dyPixels);
    void pan(double dxPixels, double dyPixels);
    void zoom(double factor);
    // Centres a bounding sphere and backs off until it fills the view.
    void frame(const Vec3& centre, double radius);
    // Moves in the view plane through `anchor` that a drag of (dx, dy) pixels covers there.
    Vec3 dragInViewPlane(const Vec3& anchor, double dxPixels, double dyPixels) const;
};

// The camera the viewer starts with: every part in view, looking down at 30 degrees, with
// room on the left and right for the panels.
Camera initialCamera(const World& world, int width, int height);

// Colours the viewer paints (linear RGB in [0, 1]); tests look for them in screenshots.
Vec3 partColour(const Part& part, MotionType motion);
Vec3 zoneColour(int depth, int deepest);  // the thesis's green deformation area
inline const Vec3 kBackground(0.13, 0.14, 0.17);

struct Pick {
    BodyId body = 0;
    Index face = 0;
    Index mass = 0;     // the hit face's corner nearest the hit point
    Vec3 point;         // world
    double distance = 0.0;  // along the ray
};

// Nearest hit of the ray with any part's faces (current, deformed positions).
std::optional<Pick> pick(const World& world, const Camera::Ray& ray);

// Ray-triangle intersection (Moller-Trumbore): distance along the ray, nullopt when missed.
std::optional<double> intersectRayTriangle(const Camera::Ray& ray, const Vec3& a, const Vec3& b, const Vec3& c);

// The masses of a part whose positions may have changed since the last update: those moving
// now, and those that moved at the last update (they may have stopped and returned to rest).
// What the viewer's incremental caches (normals, drawn hierarchies) recompute from.
class MovedMasses {
public:
    explicit MovedMasses(std::span<const Index> movingAtStart = {}) : previous_(movingAtStart.begin(), movingAtStart.end()) {}
    // The masses moving now or at the last update (each may appear twice); empty when none.
    std::span<const Index> update(const Part& part);

private:
    std::vector<Index> previous_;
    std::vector<Index> moved_;  // scratch
};

// Per-vertex normals of a part in its own frame (area-weighted face normals), kept up to
// date incrementally: a rigid motion changes nothing (the renderer rotates them), and a
// deformation recomputes only the moving masses, the masses that stopped since the last
// update, and their neighbours. recomputed() counts vertex normals computed by the last update.
class SurfaceNormals {
public:
    explicit SurfaceNormals(const Part& part);
    // Returns true when some normal changed.
    bool update(const Part& part);
    const std::vector<Vec3>& normals() const { return normals_; }
    std::size_t recomputed() const { return recomputed_; }
    // Every normal from scratch (the reference the incremental update must equal).
    static std::vector<Vec3> computeAll(const Part& part);

private:
    std::vector<Vec3> normals_;
    MovedMasses moved_;
    IndexSet ring_;  // (V) scratch: the moved masses and their neighbours
    std::size_t recomputed_ = 0;
};

// Per-vertex unit normals (area-weighted face normals; +y where they cancel).
std::vector<Vec3> vertexNormals(std::span<const Face> faces, std::span<const Vec3> positions);

// What the renderer draws of a part, in its frame: the simulated masses, or the part's own drawn
// mesh (PartModel::drawn, a remeshed part drawn as the user's file) carried by them. Colours
// come per mass; a drawn vertex takes its nearest mass's colour. A drawn mesh is recomputed
// whole (O(its vertices)) each time the part's shape changes.
struct ShownSurface {
    std::vector<Vec3> positions, normals, colours;
};
// `massNormals`: the simulated surface's normals (SurfaceNormals), used when the part has no
// drawn mesh of its own. A model whose masses are renumbered (VertexOrder::Locality) or whose
// file lost vertices to welding or repair shows them in the user's vertex order (the file's),
// the order of drawnMesh()'s faces.
void showPart(const Part& part, const std::vector<Vec3>& massNormals, const std::vector<Vec3>& massColours, ShownSurface& out);

// The model a material change restarts a part with: the same mesh as given, its masses on the
// same vertices, renumbered as before, its drawn mesh kept, so a scene's mass indices keep
// naming the same vertices.
std::shared_ptr<const PartModel> withMaterial(const PartModel& model, const Material& material);

// A part's face hierarchy for drawing, kept in step with the part's shape by the viewer: the
// world refits its own hierarchies only when a face query needs them (never for a part met
// only by point-shell queries, or alone), and drawing must not change the world. Built like the
// world's collider of the part; each update refits the faces around the masses that move or
// have just stopped (O(those masses)).
class DisplayHierarchy {
public:
    DisplayHierarchy(const Part& part, const PartCollider& like);
    void update(const Part& part);
    const PartCollider& collider() const { return collider_; }

private:
    PartCollider collider_;
    MovedMasses moved_;
};

class Session {
public:
    explicit Session(Scene scene);

    void advance(double wallSeconds);  // nothing while paused
    void singleStep();                 // one step, with the selected force (also while paused)
    void reset();                      // the scene from its start, same settings
    bool paused = false;
    int maxStepsPerFrame = 200;
    double speed = 1.0;                // simulated seconds per wall second

    World& world() { return run_->world(); }
    const World& world() const { return run_->world(); }
    const Scene& scene() const { return scene_; }
    Scene& editableScene() { return scene_; }  // changes take effect at the next reset()
    std::uint64_t steps() const { return steps_; }

    // Operator: grab a body at a world point, drag the grab target, release.
    void grab(BodyId body, const Vec3& worldPoint);
    void dragTo(const Vec3& worldPoint);   // the grabbed point goes there
    void rotateGrabbed(const Vec3& axis, double angle);
    void release();
    std::optional<BodyId> grabbed() const;
    // A force on a selected mass (named by the user's vertex, World::applyMassForce) or face
    // (spread over its 3 masses), applied at every step until cleared.
    void setMassForce(BodyId body, Index vertex, const Vec3& worldForce);
    void setFaceForce(BodyId body, Index face, const Vec3& worldForce);
    void clearMassForce() { massForce_.reset(); }

private:
    Scene scene_;
    std::unique_ptr<SceneRun> run_;
    double owed_ = 0.0;
    std::uint64_t steps_ = 0;
    Vec3 grabOffset_ = Vec3::Zero();  // grabbed point in the body's frame
    struct MassForce {
        BodyId body;
        Index index;  // a user's vertex, or a face when onFace
        bool onFace;
        Vec3 force;
    };
    std::optional<MassForce> massForce_;
};

}  // namespace flexfit::viewer
