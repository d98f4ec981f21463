// Virtual assembly by snapping (SPEC 7, thesis 3.2 and 4.4).
//
// A rule joins a primary part (the one the operator brings) to a secondary part (the one that
// receives it). It holds the primary's final pose relative to the secondary and one trigger:
//   CollisionSnap  assemble as soon as the two parts touch;
//   ProximitySnap  assemble when the primary's pose is within a distance (and angle) of its
//                  final pose;
//   VectorSnap     improved snap-fitting: each part carries an assembly vector (origin, end in
//                  its own frame); assemble when both ends of the primary's vector are within a
//                  tolerance of the secondary's (so a wrong orientation is refused);
//   ZoneSnap       the thesis's zone snap-fitting: the secondary carries an assembly area (box,
//                  sphere or cylinder in its frame); assemble when the primary's assembly vector
//                  lies entirely inside it (both ends: the areas are convex).
// Assembling moves the primary to its final pose over `snapDuration` seconds (position
// interpolated linearly, rotation by slerp), not in one jump, and reports an event.
#pragma once

#include "flexfit/names.hpp"
#include "flexfit/pose.hpp"

#include <optional>
#include <string>

namespace flexfit {

enum class SnapTechnique { CollisionSnap, ProximitySnap, VectorSnap, ZoneSnap };
// Its names (names.hpp).
inline constexpr EnumName<SnapTechnique> kSnapTechniqueNames[] = {
    {SnapTechnique::CollisionSnap, "collision", "collision snapping"}, {SnapTechnique::ProximitySnap, "proximity", "proximity snapping"},
    {SnapTechnique::VectorSnap, "vector", "improved snap-fitting"}, {SnapTechnique::ZoneSnap, "zone", "zone snap-fitting"},
};
template <> inline constexpr std::span<const EnumName<SnapTechnique>> kEnumNames<SnapTechnique> = kSnapTechniqueNames;

struct AssemblyVector {
    Vec3 origin = Vec3::Zero();  // part frame
    Vec3 end = Vec3::UnitY();
};

struct AssemblyArea {
    enum class Shape { Box, Sphere, Cylinder } shape = Shape::Box;
    Pose frame;                  // the area's frame in the secondary part's frame
    Vec3 halfExtents = Vec3::Ones();  // box
    double radius = 1.0;              // sphere, cylinder (around the frame's y axis)
    double halfHeight = 1.0;          // cylinder, along y
    bool contains(const Vec3& pointInPart) const;
};
// Its names (names.hpp).
inline constexpr EnumName<AssemblyArea::Shape> kAreaShapeNames[] = {
    {AssemblyArea::Shape::Box, "box", "box"},
    {AssemblyArea::Shape::Sphere, "sphere", "sphere"},
    {AssemblyArea::Shape::Cylinder, "cylinder", "cylinder"},
};
template <> inline constexpr std::span<const EnumName<AssemblyArea::Shape>> kEnumNames<AssemblyArea::Shape> = kAreaShapeNames;

struct AssemblyRule {
    std::string name;
    std::uint32_t primary = 0, secondary = 0;  // body ids
    SnapTechnique technique = SnapTechnique::ZoneSnap;
    Pose finalRelativePose;            // primary's pose in the secondary's frame once assembled
    double snapDuration = 0.1;         // s
    // ProximitySnap
    double distanceTolerance = 0.5;
    double angleTolerance = 0.26;      // rad (about 15 degrees)
    // VectorSnap and ZoneSnap
    AssemblyVector primaryVector;
    AssemblyVector secondaryVector;    // VectorSnap
    double vectorTolerance = 0.5;      // VectorSnap
    AssemblyArea area;                 // ZoneSnap
};

// Whether the rule's geometric condition holds for these poses (CollisionSnap needs contacts
// and is decided by the caller: pass `touching`).
bool snapConditionHolds(const AssemblyRule& rule, const Pose& primary, const Pose& secondary, bool touching);

// Final world pose of the primary for the secondary's current pose.
Pose finalPose(const AssemblyRule& rule, const Pose& secondary);

// Pose between `from` and `to` at fraction s in [0, 1].
Pose interpolate(const Pose& from, const Pose& to, double s);

struct AssemblyEvent {
    std::string rule;
    SnapTechnique technique;
    double time = 0.0;         // s, when the snap started
    Pose primaryPoseBefore;    // where the primary was
    Pose primaryPoseAfter;     // the final pose it is brought to
};

}  // namespace flexfit
