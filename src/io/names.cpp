// The vocabulary's tables (names.hpp), and every enum's toString.
#include "flexfit/names.hpp"

#include "flexfit/scene.hpp"

namespace flexfit {
namespace {

template <class Enum, std::size_t N>
std::span<const EnumName<Enum>> table(const EnumName<Enum> (&entries)[N]) {
    return {entries, N};
}

}  // namespace

template <>
std::span<const EnumName<PartMode>> enumNames() {
    static constexpr EnumName<PartMode> names[] = {
        {PartMode::Rigid, "rigid", "rigid"},
        {PartMode::RigidDeformable, "rigid-deformable", "rigid-deformable (zones)"},
        {PartMode::FullDeformable, "full-deformable", "full-deformable"},
    };
    return table(names);
}

template <>
std::span<const DeprecatedName<PartMode>> deprecatedNames() {
    static constexpr DeprecatedName<PartMode> names[] = {{"zones", PartMode::RigidDeformable}, {"full", PartMode::FullDeformable}};
    return names;
}

template <>
std::span<const EnumName<MotionType>> enumNames() {
    static constexpr EnumName<MotionType> names[] = {
        {MotionType::Static, "static", "static"},
        {MotionType::Kinematic, "kinematic", "kinematic"},
        {MotionType::Dynamic, "dynamic", "dynamic"},
    };
    return table(names);
}

template <>
std::span<const EnumName<Integrator>> enumNames() {
    static constexpr EnumName<Integrator> names[] = {
        {Integrator::SemiImplicitEuler, "semi-implicit", "semi-implicit (symplectic) Euler"},
        {Integrator::ExplicitEuler, "explicit", "explicit Euler"},
    };
    return table(names);
}

template <>
std::span<const EnumName<RestorationMethod>> enumNames() {
    static constexpr EnumName<RestorationMethod> names[] = {
        {RestorationMethod::None, "none", "none"},
        {RestorationMethod::AnchorSprings, "anchors", "anchor springs"},
        {RestorationMethod::Constraint, "constraint", "restoration constraint"},
    };
    return table(names);
}

template <>
std::span<const DeprecatedName<RestorationMethod>> deprecatedNames() {
    static constexpr DeprecatedName<RestorationMethod> names[] = {{"anchor", RestorationMethod::AnchorSprings}};
    return names;
}

template <>
std::span<const EnumName<ExactTest>> enumNames() {
    static constexpr EnumName<ExactTest> names[] = {
        {ExactTest::SphereTriangle, "sphere", "face sphere against triangle"},
        {ExactTest::TriangleTriangle, "triangle", "triangle against triangle"},
    };
    return table(names);
}

template <>
std::span<const EnumName<BoundingVolumeKind>> enumNames() {
    static constexpr EnumName<BoundingVolumeKind> names[] = {
        {BoundingVolumeKind::Sphere, "sphere", "spheres"},
        {BoundingVolumeKind::Aabb, "aabb", "axis-aligned boxes"},
    };
    return table(names);
}

template <>
std::span<const EnumName<BroadPhaseUpdate>> enumNames() {
    static constexpr EnumName<BroadPhaseUpdate> names[] = {
        {BroadPhaseUpdate::Refit, "refit", "refit"},
        {BroadPhaseUpdate::Rebuild, "rebuild", "rebuild"},
    };
    return table(names);
}

template <>
std::span<const EnumName<RigidDeformableQuery>> enumNames() {
    static constexpr EnumName<RigidDeformableQuery> names[] = {
        {RigidDeformableQuery::Faces, "faces", "face hierarchies"},
        {RigidDeformableQuery::PointShell, "point-shell", "point shell"},
    };
    return table(names);
}

template <>
std::span<const EnumName<SnapTechnique>> enumNames() {
    static constexpr EnumName<SnapTechnique> names[] = {
        {SnapTechnique::CollisionSnap, "collision", "collision snapping"},
        {SnapTechnique::ProximitySnap, "proximity", "proximity snapping"},
        {SnapTechnique::VectorSnap, "vector", "improved snap-fitting"},
        {SnapTechnique::ZoneSnap, "zone", "zone snap-fitting"},
    };
    return table(names);
}

template <>
std::span<const EnumName<AssemblyArea::Shape>> enumNames() {
    static constexpr EnumName<AssemblyArea::Shape> names[] = {
        {AssemblyArea::Shape::Box, "box", "box"},
        {AssemblyArea::Shape::Sphere, "sphere", "sphere"},
        {AssemblyArea::Shape::Cylinder, "cylinder", "cylinder"},
    };
    return table(names);
}

template <>
std::span<const EnumName<SceneAction::Kind>> enumNames() {
    using Kind = SceneAction::Kind;
    static constexpr EnumName<Kind> names[] = {
        {Kind::Grab, "grab", "grab"},     {Kind::Move, "move", "move"},    {Kind::Release, "release", "release"},
        {Kind::Push, "push", "push"},     {Kind::Force, "force", "force"}, {Kind::Velocity, "velocity", "velocity"},
    };
    return table(names);
}

template <>
std::span<const EnumName<Stage>> enumNames() {
    static constexpr EnumName<Stage> names[] = {
        {Stage::OperatorInput, "operator_input", "operator input"},
        {Stage::RigidMotion, "rigid_motion", "rigid motion"},
        {Stage::BroadPhase, "broad_phase", "broad phase"},
        {Stage::NarrowPhase, "narrow_phase", "narrow phase"},
        {Stage::ContactResponse, "contact_response", "contact response"},
        {Stage::ZoneDynamics, "zone_dynamics", "zone dynamics"},
        {Stage::ZoneRetirement, "zone_retirement", "zone retirement"},
        {Stage::Assembly, "assembly", "assembly"},
    };
    static_assert(std::size(names) == kStageCount);
    return table(names);
}

std::string deprecationWarning(std::string_view oldName, std::string_view replacement) {
    return "'" + std::string(oldName) + "' is deprecated: write '" + std::string(replacement) + "'";
}

const char* toString(PartMode v) { return nameOf(v); }
const char* toString(MotionType v) { return nameOf(v); }
const char* toString(Integrator v) { return nameOf(v); }
const char* toString(RestorationMethod v) { return nameOf(v); }
const char* toString(ExactTest v) { return nameOf(v); }
const char* toString(BoundingVolumeKind v) { return nameOf(v); }
const char* toString(BroadPhaseUpdate v) { return nameOf(v); }
const char* toString(RigidDeformableQuery v) { return nameOf(v); }
const char* toString(SnapTechnique v) { return nameOf(v); }
const char* toString(AssemblyArea::Shape v) { return nameOf(v); }
const char* toString(SceneAction::Kind v) { return nameOf(v); }
const char* toString(Stage v) { return nameOf(v); }

}  // namespace flexfit
