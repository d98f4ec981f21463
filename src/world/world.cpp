// The world (world.hpp): its registry calls, the operator's calls, and the step as the list of
// its stages.
#include "flexfit/world.hpp"

#include "core/fnv1a.hpp"
#include "core/reserve.hpp"
#include "divergence_check.hpp"
#include "rigid_motion.hpp"
#include "step_profiler.hpp"
#include "world_data.hpp"
#include "zone_dynamics.hpp"

#include <cmath>
#include <string>

namespace flexfit {
namespace {

const std::string kSource = "world";


// World::warnings(): a deforming part's restoration constraint left at its per-step default
// fraction (no rate) at a world time step other than 1 ms.
void noteDefaultFraction(detail::WorldData& d, BodyId id, const PartSettings& part) {
    if (const std::optional<DefaultFractionElsewhere> e = defaultFractionAt(part, d.settings.timeStep))
        d.warnings.push_back("body " + std::to_string(id) + ": " +
                             describe(*e, {"WorldSettings::timeStep = ", "RestorationSettings::constraintRate = ", " (1/s)",
                                           "RestorationMethod::AnchorSprings"}));
}

}  // namespace

World::World(WorldSettings settings) {
    validateSettings(settings);
    data_ = std::make_unique<detail::WorldData>(settings);
}

World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

void World::checkBody(BodyId id, const char* what) const {
    if (id >= data_->bodies.size()) throw InputError(kSource, 0, std::string(what) + ": no body " + std::to_string(id));
}

// --- Bodies ---

BodyId World::add(std::shared_ptr<const PartModel> model, const PartSettings& partSettings, const BodySettings& settings,
                  const Pose& pose) {
    detail::WorldData& d = *data_;
    if (model == nullptr) throw InputError(kSource, 0, "add: no part model");
    checkPose(pose, kSource, "add");
    // Everything that can fail comes first; then the body is registered everywhere at once.
    const RigidBody body = makeRigidBody(*model, settings);
    auto part = std::make_unique<Part>(std::move(model), partSettings);
    part->setPose(pose);
    const double stiffness = detail::effectiveContactStiffness(*part, d.settings.timeStep);
    const BodyId id = BodyId(d.bodies.size());
    d.bodies.reserve(id + 1);
    detail::reserveGrowing(d.response.stiffness, id + 1u);
    // A static rigid body never moves nor deforms (an assembly's primary is made moving when
    // its rule is added): fixed in the broad phase.
    const Mobility mobility = settings.motion == MotionType::Static && !part->deforms() ? Mobility::Fixed : Mobility::Moving;
    d.collision.add(id, *part, settings.boundingVolume, mobility);  // strong: registers all or nothing
    d.bodies.add(std::move(part), body);                   // no throw after the reserve
    d.response.stiffness.push_back(stiffness);
    noteDefaultFraction(d, id, partSettings);
    return id;
}

std::size_t World::bodyCount() const { return data_->bodies.size(); }
const Part& World::part(BodyId id) const {
    checkBody(id, "part");
    return *data_->bodies.parts[id];
}
const RigidBody& World::body(BodyId id) const {
    checkBody(id, "body");
    return data_->bodies.rigid[id];
}
const WorldSettings& World::settings() const { return data_->settings; }
Vec3 World::centreOfMass(BodyId id) const {
    checkBody(id, "centre of mass");
    return data_->bodies.centreOfMass(id);
}

void World::setPartSettings(BodyId id, const PartSettings& settings) {
    checkBody(id, "settings");
    Part& part = *data_->bodies.parts[id];
    part.setSettings(settings);
    data_->response.stiffness[id] = detail::effectiveContactStiffness(part, data_->settings.timeStep);
    noteDefaultFraction(*data_, id, settings);
}

const std::vector<std::string>& World::warnings() const { return data_->warnings; }

double World::contactStiffness(BodyId id) const {
    checkBody(id, "stiffness");
    return data_->response.stiffness[id];
}

ZoneId World::openZone(BodyId id, ZoneSeed seed, int level) {
    checkBody(id, "zone");
    if (seed.kind == ZoneSeed::Kind::Mass) seed.index = massOfUserVertex(id, seed.index, "zone");
    return data_->bodies.parts[id]->openZone(seed, level);
}

void World::applyForce(BodyId id, const Vec3& worldForce) {
    checkBody(id, "force");
    if (!worldForce.allFinite()) throw InputError(kSource, 0, "force on body " + std::to_string(id) + " must be finite");
    RigidBody& body = data_->bodies.rigid[id];
    if (body.motion == MotionType::Dynamic) body.force += worldForce;
}

void World::applyForceAt(BodyId id, const Vec3& worldForce, const Vec3& worldPoint) {
    checkBody(id, "force");
    if (!worldForce.allFinite() || !worldPoint.allFinite())
        throw InputError(kSource, 0, "force on body " + std::to_string(id) + " and its point must be finite");
    RigidBody& body = data_->bodies.rigid[id];
    if (body.motion != MotionType::Dynamic) return;
    body.force += worldForce;
    body.torque += (worldPoint - centreOfMass(id)).cross(worldForce);
}

void World::setVelocity(BodyId id, const Vec3& linear, const Vec3& angular) {
    checkBody(id, "velocity");
    if (!linear.allFinite() || !angular.allFinite())
        throw InputError(kSource, 0, "velocity of body " + std::to_string(id) + " must be finite");
    data_->bodies.rigid[id].linearVelocity = linear;
    data_->bodies.rigid[id].angularVelocity = angular;
}

void World::setKinematicTarget(BodyId id, const Pose& target) {
    checkBody(id, "kinematic target");
    checkPose(target, kSource, "kinematic target");
    if (data_->bodies.rigid[id].motion == MotionType::Kinematic) data_->bodies.kinematicTargets[id] = target;
}

// --- The operator ---

void World::grab(BodyId id, const GrabSettings& settings) { detail::grab(id, settings, data_->settings.timeStep, data_->bodies, data_->op); }
void World::setGrabTarget(const Pose& target) {
    checkPose(target, kSource, "grab target");
    data_->op.target = target;
}
void World::release() { detail::release(data_->op); }
std::optional<BodyId> World::grabbed() const { return data_->op.grabbed; }
const Pose& World::grabTarget() const { return data_->op.target; }
const Coupling& World::coupling() const { return data_->op.coupling; }

Index World::massOfUserVertex(BodyId id, Index vertex, const char* what) const {
    checkBody(id, what);
    const PartModel& model = data_->bodies.parts[id]->model();
    const Index mass = model.massOf(vertex);  // throws for a file vertex without a mass
    if (mass >= model.massCount())
        throw InputError(kSource, 0, std::string(what) + ": vertex " + std::to_string(vertex) + " out of range for body " + std::to_string(id));
    return mass;
}

void World::applyMassForce(BodyId id, Index vertex, const Vec3& worldForce) {
    applyForceOnMass(id, massOfUserVertex(id, vertex, "force"), worldForce);
}

void World::applyForceOnMass(BodyId id, Index mass, const Vec3& worldForce) {
    Part& part = *data_->bodies.parts[id];
    if (part.deforms())
        part.applyForce(mass, worldForce);
    else
        applyForceAt(id, worldForce, part.worldPosition(mass));
}

void World::kickMass(BodyId id, Index vertex, const Vec3& worldVelocityChange) {
    const Index mass = massOfUserVertex(id, vertex, "kick");
    if (!worldVelocityChange.allFinite()) throw InputError(kSource, 0, "kick on body " + std::to_string(id) + " must be finite");
    Part& part = *data_->bodies.parts[id];
    if (part.deforms()) {
        part.kickMass(mass, worldVelocityChange);
        return;
    }
    RigidBody& body = data_->bodies.rigid[id];
    if (body.motion != MotionType::Dynamic) return;
    const Vec3 impulse = part.model().mass[mass] * worldVelocityChange;
    const Eigen::Matrix3d r = part.pose().rotation.toRotationMatrix();
    body.linearVelocity += body.inverseMass * impulse;
    body.angularVelocity += r * body.inverseInertia * r.transpose() * (part.worldPosition(mass) - centreOfMass(id)).cross(impulse);
}

void World::applyFaceForce(BodyId id, Index face, const Vec3& worldForce) {
    checkBody(id, "force");
    const auto& faces = data_->bodies.parts[id]->model().mesh.faces;
    if (face >= faces.size())
        throw InputError(kSource, 0, "force: face " + std::to_string(face) + " out of range for body " + std::to_string(id));
    for (Index m : faces[face]) applyForceOnMass(id, m, worldForce / 3.0);
}

// --- Assembly ---

std::size_t World::addAssembly(const AssemblyRule& rule) {
    const std::size_t index = detail::addRule(rule, data_->bodies.size(), data_->assembly);
    data_->collision.setMoving(rule.primary);  // a snap will move it, static or not
    return index;
}
std::size_t World::assemblyCount() const { return data_->assembly.rules.size(); }
const std::vector<AssemblyEvent>& World::assemblyEvents() const { return data_->assembly.events; }
bool World::assembled(std::size_t rule) const {
    if (rule >= data_->assembly.rules.size()) throw InputError(kSource, 0, "assembled: no rule " + std::to_string(rule));
    return data_->assembly.rules[rule].phase == detail::RuleState::Phase::Assembled;
}

// --- The step ---

void World::prepare() {
    detail::WorldData& d = *data_;
    d.collision.warmUp();
    detail::clearRefittedChanges(d.collision, d.bodies);  // as after every narrow phase
    detail::sizeResponseScratch(d.bodies, d.response);
}

namespace {

// The stages of one step, in order (world.hpp).
void stepStages(detail::WorldData& d) {
    const StepContext step = d.context();
    detail::StepProfiler profiler(d.profile, Stage::OperatorInput);
    detail::operatorInput(step, d.op, d.bodies);                   // coupling force, kinematic targets
    profiler.enter(Stage::RigidMotion);
    detail::moveRigidBodies(step, d.settings, d.bodies, d.collision, d.response, d.rigidMotion, profiler, d.profile);  // sub-stepped, solved
    profiler.enter(Stage::BroadPhase);
    d.collision.update();                                          // spheres, candidate pairs
    profiler.enter(Stage::NarrowPhase);
    const std::vector<Contact>& contacts = d.collision.narrowPhase(detail::knownContacts(d.rigidMotion, d.bodies));  // refits deformed hierarchies it needs
    detail::clearRefittedChanges(d.collision, d.bodies);
    profiler.enter(Stage::ContactResponse);
    detail::respondToContacts(step, d.settings.contactDamping, contacts, d.bodies, d.response);  // deformable pushes, reactions
    profiler.enter(Stage::ZoneDynamics);
    detail::advanceZones(step, d.bodies, d.zonesChecked);          // moving masses, restoration
    profiler.enter(Stage::ZoneRetirement);
    detail::retireZones(d.bodies);                                 // zones at rest back to rest
    profiler.enter(Stage::Assembly);
    detail::assemble(step, contacts, d.assembly, d.bodies, d.op);  // snapping rules
    detail::checkFinite(step, d.bodies, d.zonesChecked);           // divergence (charged to assembly)
    profiler.finish();
    d.time += d.settings.timeStep;
    ++d.stepIndex;
    ++d.profile.steps;
    d.profile.faceQueries = d.collision.faceQueries();
    d.profile.faceTraversals = d.collision.faceTraversals();
}

}  // namespace

void World::step() {
    detail::WorldData& d = *data_;
    if (d.diverged)  // its state is that step's, partly non-finite: stepping it would spread garbage
        throw DivergenceError(d.diverged->body(), d.time,
                              "the world diverged in an earlier step and holds that step's state: it cannot be stepped again (that step: " +
                                  d.diverged->problem() + ")");
    try {
        stepStages(d);
    } catch (const DivergenceError& e) {
        d.diverged = e;
        throw;
    }
}

double World::time() const { return data_->time; }
std::uint64_t World::stepCount() const { return data_->stepIndex; }
const std::vector<Contact>& World::contacts() const { return data_->collision.contacts(); }
const Profile& World::profile() const { return data_->profile; }
const CollisionWorld& World::collision() const { return data_->collision; }

std::uint64_t World::stateHash() const {
    const detail::WorldData& d = *data_;
    detail::Fnv1a h;
    h.mix(&d.time, sizeof d.time);
    for (BodyId id = 0; id < d.bodies.size(); ++id) {
        const Pose& pose = d.bodies.parts[id]->pose();
        const RigidBody& body = d.bodies.rigid[id];
        h.mix(pose.rotation.coeffs().data(), 4 * sizeof(double));
        h.mix(pose.translation.data(), 3 * sizeof(double));
        h.mix(body.linearVelocity.data(), 3 * sizeof(double));
        h.mix(body.angularVelocity.data(), 3 * sizeof(double));
        const std::uint64_t part = flexfit::stateHash(d.bodies.parts[id]->state());
        h.mix(&part, sizeof part);
    }
    for (const AssemblyEvent& e : d.assembly.events) {
        h.mix(e.rule.data(), e.rule.size());
        h.mix(&e.time, sizeof e.time);
    }
    return h.value();
}

}  // namespace flexfit
