#include "flexfit/world.hpp"

#include "core/fnv1a.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace flexfit {
namespace {

using Clock = std::chrono::steady_clock;

// Adds the time since `start` to a stage of the profile and restarts the clock.
class StageTimer {
public:
    explicit StageTimer(Profile& profile) : profile_(profile), start_(Clock::now()) {}
    void restart() { start_ = Clock::now(); }
    void charge(Stage stage) {
        const auto now = Clock::now();
        const double seconds = std::chrono::duration<double>(now - start_).count();
        profile_.lastSeconds[std::size_t(stage)] += seconds;
        profile_.totalSeconds[std::size_t(stage)] += seconds;
        start_ = now;
    }

private:
    Profile& profile_;
    Clock::time_point start_;
};

const std::string kWorldSource = "world";

// The rotation as axis and angle in (-pi, pi]: the short way round.
Eigen::AngleAxisd shortestTurn(const Eigen::Quaterniond& q) {
    Eigen::AngleAxisd turn(q);
    if (turn.angle() > M_PI) turn.angle() -= 2.0 * M_PI;
    return turn;
}

}  // namespace

const char* toString(MotionType motion) {
    switch (motion) {
        case MotionType::Static: return "static";
        case MotionType::Kinematic: return "kinematic";
        case MotionType::Dynamic: return "dynamic";
    }
    return "?";
}

const char* toString(Stage stage) {
    static const char* names[] = {"operator input", "broad phase", "narrow phase", "contact response",
                                  "zone dynamics", "zone retirement", "assembly"};
    return stage < Stage::Count ? names[std::size_t(stage)] : "?";
}

World::World(WorldSettings settings) : settings_(settings), collision_(settings.collision) {
    SimulationSettings check;
    check.timeStep = settings_.timeStep;
    check.gravity = settings_.gravity;
    validateSettings(check);
    if (!(settings_.maxTravelFraction > 0.0 && settings_.maxTravelFraction <= 1.0))
        throw InputError(kWorldSource, 0, "max travel fraction must be in (0, 1]");
    if (settings_.maxSubsteps < 1 || settings_.contactIterations < 1)
        throw InputError(kWorldSource, 0, "max substeps and contact iterations must be >= 1");
}

BodyId World::add(std::shared_ptr<const PartModel> model, const PartSettings& partSettings, const BodySettings& settings,
                  const Pose& pose) {
    if (!(settings.density > 0.0) || !std::isfinite(settings.density))
        throw InputError(kWorldSource, 0, "body density must be finite and > 0");
    if (!(settings.thickness >= 0.0) || !settings.linearVelocity.allFinite() || !settings.angularVelocity.allFinite())
        throw InputError(kWorldSource, 0, "body thickness and velocities must be finite");
    RigidBody body;
    body.motion = settings.motion;
    const Eigen::AlignedBox3d box = boundingBox(model->mesh);
    body.thickness = settings.thickness > 0.0 ? settings.thickness : 0.5 * box.sizes().minCoeff();
    body.centreOfMass = box.center();
    if (settings.motion == MotionType::Dynamic) {
        const MassProperties mp = computeMassProperties(model->mesh, model->name);
        body.mass = settings.density * mp.volume;
        body.inverseMass = 1.0 / body.mass;
        body.centreOfMass = mp.centroid;
        body.inverseInertia = (settings.density * mp.inertia).inverse();
    }
    for (const Vec3& p : model->restPositions) body.boundingRadius = std::max(body.boundingRadius, (p - body.centreOfMass).norm());
    body.linearVelocity = settings.linearVelocity;
    body.angularVelocity = settings.angularVelocity;

    auto part = std::make_unique<Part>(std::move(model), inWorld(partSettings));
    part->setPose(pose);
    collision_.add(*part, settings.boundingVolume);
    parts_.push_back(std::move(part));
    bodies_.push_back(body);
    kinematicTargets_.emplace_back();
    reactionMarks_.emplace_back();
    return BodyId(parts_.size() - 1);
}

PartSettings World::inWorld(PartSettings settings) const {
    settings.simulation.timeStep = settings_.timeStep;
    // Gravity moves bodies, not zone masses: the rest shape is the part's shape under its own
    // weight, and in a falling body's frame the masses feel no gravity.
    settings.simulation.gravity = Vec3::Zero();
    return settings;
}

void World::setPartSettings(BodyId id, const PartSettings& settings) {
    if (id >= parts_.size()) throw InputError(kWorldSource, 0, "settings: no body " + std::to_string(id));
    parts_[id]->setSettings(inWorld(settings));
    collision_.refreshStiffness(std::uint32_t(id));
}

void World::applyForce(BodyId id, const Vec3& worldForce) {
    if (bodies_[id].motion == MotionType::Dynamic) bodies_[id].force += worldForce;
}

void World::applyForceAt(BodyId id, const Vec3& worldForce, const Vec3& worldPoint) {
    if (bodies_[id].motion != MotionType::Dynamic) return;
    bodies_[id].force += worldForce;
    bodies_[id].torque += (worldPoint - centreOfMass(id)).cross(worldForce);
}

void World::setVelocity(BodyId id, const Vec3& linear, const Vec3& angular) {
    bodies_[id].linearVelocity = linear;
    bodies_[id].angularVelocity = angular;
}

void World::setKinematicTarget(BodyId id, const Pose& target) {
    if (bodies_[id].motion == MotionType::Kinematic) kinematicTargets_[id] = target;
}

// --- The operator ---

World::CouplingGains World::couplingGains(BodyId id, const GrabSettings& g) const {
    const RigidBody& body = bodies_[id];
    const double h = settings_.timeStep;
    const double omega = std::min(2.0 * M_PI * g.frequency, 0.4 / h);
    const double smallestInertia = 1.0 / Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(body.inverseInertia).eigenvalues().maxCoeff();
    CouplingGains c;
    c.k = g.stiffness > 0.0 ? g.stiffness : body.mass * omega * omega;
    c.b = g.damping >= 0.0 ? g.damping : 2.0 * std::sqrt(c.k * body.mass);
    c.kr = g.angularStiffness > 0.0 ? g.angularStiffness : smallestInertia * omega * omega;
    c.br = g.angularDamping >= 0.0 ? g.angularDamping : 2.0 * std::sqrt(c.kr * smallestInertia);
    // Explicit coupling: stable while h sqrt(k/m) and h b/m stay below 1 (with margin to 2).
    const bool stable = h * std::sqrt(c.k / body.mass) <= 1.0 && h * c.b / body.mass <= 1.0 &&
                        h * std::sqrt(c.kr / smallestInertia) <= 1.0 && h * c.br / smallestInertia <= 1.0;
    if (!stable)
        throw InputError(kWorldSource, 0, "grab coupling too stiff or too damped for the time step (need h*sqrt(k/m) <= 1 and h*b/m <= 1)");
    return c;
}

void World::grab(BodyId id, const GrabSettings& settings) {
    if (id >= parts_.size()) throw InputError(kWorldSource, 0, "grab: no body " + std::to_string(id));
    const RigidBody& body = bodies_[id];
    if (body.motion == MotionType::Static) throw InputError(kWorldSource, 0, "grab: body " + std::to_string(id) + " is static");
    if (!(settings.frequency > 0.0) || !std::isfinite(settings.frequency) || !(settings.stiffness >= 0.0) ||
        !(settings.angularStiffness >= 0.0) || !std::isfinite(settings.damping) || !std::isfinite(settings.angularDamping))
        throw InputError(kWorldSource, 0, "grab: coupling settings must be finite, frequency > 0 and stiffnesses >= 0");
    gains_ = body.motion == MotionType::Dynamic ? couplingGains(id, settings) : CouplingGains{};
    grabbed_ = id;
    grabTarget_ = previousGrabTarget_ = parts_[id]->pose();
    coupling_ = Coupling{true, id, Vec3::Zero(), Vec3::Zero()};
}

void World::setGrabTarget(const Pose& target) { grabTarget_ = target; }

void World::release() {
    grabbed_.reset();
    coupling_ = Coupling{};
}

void World::applyMassForce(BodyId id, Index mass, const Vec3& worldForce) {
    if (id >= parts_.size()) throw InputError(kWorldSource, 0, "force: no body " + std::to_string(id));
    Part& part = *parts_[id];
    if (mass >= part.model().massCount())
        throw InputError(kWorldSource, 0, "force: mass " + std::to_string(mass) + " out of range for body " + std::to_string(id));
    if (part.mode() != PartMode::Rigid)
        part.applyForce(mass, worldForce);
    else
        applyForceAt(id, worldForce, part.worldPosition(mass));
}

void World::applyFaceForce(BodyId id, Index face, const Vec3& worldForce) {
    if (id >= parts_.size()) throw InputError(kWorldSource, 0, "force: no body " + std::to_string(id));
    const auto& faces = parts_[id]->model().mesh.faces;
    if (face >= faces.size())
        throw InputError(kWorldSource, 0, "force: face " + std::to_string(face) + " out of range for body " + std::to_string(id));
    for (Index m : faces[face]) applyMassForce(id, m, worldForce / 3.0);
}

// The spring-damper between the operator's target and the grabbed body, for this step.
void World::applyCoupling() {
    if (!grabbed_) return;
    const BodyId id = *grabbed_;
    RigidBody& body = bodies_[id];
    if (body.motion == MotionType::Kinematic) {
        kinematicTargets_[id] = grabTarget_;
        coupling_ = Coupling{true, id, Vec3::Zero(), Vec3::Zero()};
        return;
    }
    const double h = settings_.timeStep;
    const Pose& pose = parts_[id]->pose();
    const Vec3 targetCentre = grabTarget_.apply(body.centreOfMass);
    const Vec3 targetVelocity = (targetCentre - previousGrabTarget_.apply(body.centreOfMass)) / h;
    const Eigen::AngleAxisd error = shortestTurn(grabTarget_.rotation * pose.rotation.conjugate());
    const Eigen::AngleAxisd targetTurn = shortestTurn(grabTarget_.rotation * previousGrabTarget_.rotation.conjugate());
    const Vec3 targetSpin = targetTurn.axis() * (targetTurn.angle() / h);
    coupling_.force = gains_.k * (targetCentre - centreOfMass(id)) + gains_.b * (targetVelocity - body.linearVelocity);
    coupling_.torque = gains_.kr * error.angle() * error.axis() + gains_.br * (targetSpin - body.angularVelocity);
    body.force += coupling_.force;
    body.torque += coupling_.torque;
    previousGrabTarget_ = grabTarget_;
}

// --- The step ---

void World::step() {
    profile_.lastSeconds.fill(0.0);
    StageTimer timer(profile_);
    operatorInput();
    timer.charge(Stage::OperatorInput);
    integrateDynamicBodies();  // sub-stepped, with its own contact passes (charged inside)
    timer.restart();  // the sub-steps charged their own stages
    collision_.update();
    timer.charge(Stage::BroadPhase);
    const std::vector<Contact>& contacts = collision_.narrowPhase();
    timer.charge(Stage::NarrowPhase);
    collision_.respond(contacts);
    applyDeformableReactions(contacts);
    timer.charge(Stage::ContactResponse);
    for (auto& part : parts_) part->step();
    timer.charge(Stage::ZoneDynamics);
    timer.charge(Stage::ZoneRetirement);  // inside Part::step: charged to zone dynamics
    assemble();
    timer.charge(Stage::Assembly);
    time_ += settings_.timeStep;
    ++profile_.steps;
}

void World::operatorInput() {
    applyCoupling();
    const double h = settings_.timeStep;
    for (BodyId id = 0; id < parts_.size(); ++id) {
        if (!kinematicTargets_[id]) continue;
        const Pose target = *kinematicTargets_[id];
        RigidBody& body = bodies_[id];
        const Vec3 before = centreOfMass(id);
        const Eigen::AngleAxisd turn(target.rotation * parts_[id]->pose().rotation.conjugate());
        parts_[id]->setPose(target);
        body.linearVelocity = (centreOfMass(id) - before) / h;
        body.angularVelocity = turn.axis() * (turn.angle() / h);
        kinematicTargets_[id].reset();
    }
}

// A dynamic body pressing a deformable part feels the springs it displaced: the contacted
// masses sit at x (pushed from their rest positions by the response) and the part pulls them
// back with k_eff (rest - x); through the contact, the body receives that force, for the next
// step. A weak push is stopped by a stiff rim; a strong one deforms it and passes.
void World::applyDeformableReactions(std::span<const Contact> contacts) {
    // Each (body, contacted mass) once, in first-contact order (deterministic).
    for (auto& marks : reactionMarks_) marks.first.clear();
    reactionMasses_.clear();
    for (const Contact& c : contacts)
        for (const auto& [body, part, face, mass] :
             {std::tuple{c.partA, c.partB, c.faceB, c.massB}, std::tuple{c.partB, c.partA, c.faceA, kNoMass}}) {
            if (bodies_[body].motion != MotionType::Dynamic || parts_[part]->mode() == PartMode::Rigid) continue;
            auto& [counted, owners] = reactionMarks_[part];
            if (counted.size() == 0) {
                counted.reset(parts_[part]->model().massCount());
                owners.assign(parts_[part]->model().massCount(), 0u);
            }
            // Contacts come grouped by pair, so a mass pressed by two bodies counts once for each.
            for (Index m : pressedMasses(parts_[part]->model().mesh.faces[face], mass))
                if (counted.insert(m) || owners[m] != body) {
                    owners[m] = body;
                    reactionMasses_.push_back({body, part, m});
                }
        }
    for (const auto& [body, part, m] : reactionMasses_) {
        const Part& p = *parts_[part];
        const Vec3 displacement = p.pose().rotate(p.state().positions[m] - p.model().restPositions[m]);
        bodies_[body].force -= collision_.effectiveStiffness(part) * displacement;
    }
}

// --- Assembly ---

std::size_t World::addAssembly(const AssemblyRule& rule) {
    if (rule.primary >= parts_.size() || rule.secondary >= parts_.size() || rule.primary == rule.secondary)
        throw InputError(kWorldSource, 0, "assembly rule '" + rule.name + "' needs two different existing bodies");
    if (!(rule.snapDuration >= 0.0) || !std::isfinite(rule.snapDuration))
        throw InputError(kWorldSource, 0, "assembly rule '" + rule.name + "': snap duration must be finite and >= 0");
    RuleState state;
    state.rule = rule;
    rules_.push_back(state);
    return rules_.size() - 1;
}

bool World::touching(BodyId a, BodyId b) const {
    for (const Contact& c : collision_.contacts())
        if ((c.partA == a && c.partB == b) || (c.partA == b && c.partB == a)) return true;
    return false;
}

void World::assemble() {
    for (RuleState& state : rules_) {
        const AssemblyRule& rule = state.rule;
        Part& primary = *parts_[rule.primary];
        const Pose target = finalPose(rule, parts_[rule.secondary]->pose());
        if (state.phase == RuleState::Phase::Waiting) {
            if (!snapConditionHolds(rule, primary.pose(), parts_[rule.secondary]->pose(), touching(rule.primary, rule.secondary)))
                continue;
            state.phase = RuleState::Phase::Snapping;
            state.start = time_;
            state.from = primary.pose();
            events_.push_back({rule.name, rule.technique, time_, state.from, target});
            if (grabbed_ == rule.primary) release();  // the snap takes the part from the operator
            RigidBody& body = bodies_[rule.primary];
            body.motion = MotionType::Kinematic;  // the snap drives it from now on
            body.linearVelocity.setZero();
            body.angularVelocity.setZero();
        }
        const double s = rule.snapDuration > 0.0 ? (time_ + settings_.timeStep - state.start) / rule.snapDuration : 1.0;
        primary.setPose(interpolate(state.from, target, s));
        if (s >= 1.0) state.phase = RuleState::Phase::Assembled;  // and stays attached
    }
}

std::uint64_t World::stateHash() const {
    detail::Fnv1a h;
    h.mix(&time_, sizeof time_);
    for (BodyId id = 0; id < parts_.size(); ++id) {
        const Pose& pose = parts_[id]->pose();
        h.mix(pose.rotation.coeffs().data(), 4 * sizeof(double));
        h.mix(pose.translation.data(), 3 * sizeof(double));
        h.mix(bodies_[id].linearVelocity.data(), 3 * sizeof(double));
        h.mix(bodies_[id].angularVelocity.data(), 3 * sizeof(double));
        const std::uint64_t part = flexfit::stateHash(parts_[id]->state());
        h.mix(&part, sizeof part);
    }
    for (const AssemblyEvent& e : events_) {
        h.mix(e.rule.data(), e.rule.size());
        h.mix(&e.time, sizeof e.time);
    }
    return h.value();
}

double World::minimumThickness() const {
    double thinnest = std::numeric_limits<double>::infinity();
    for (const RigidBody& b : bodies_) thinnest = std::min(thinnest, b.thickness);
    return thinnest;
}

void World::integrateDynamicBodies() {
    const double h = settings_.timeStep;
    const double bound = settings_.maxTravelFraction * minimumThickness();
    for (BodyId id = 0; id < parts_.size(); ++id) {
        RigidBody& body = bodies_[id];
        if (body.motion != MotionType::Dynamic) continue;
        // Velocity first (semi-implicit Euler); then the travel it gives decides the sub-steps.
        const Eigen::Matrix3d r = parts_[id]->pose().rotation.toRotationMatrix();
        const Eigen::Matrix3d inverseInertia = r * body.inverseInertia * r.transpose();
        const Eigen::Matrix3d inertia = inverseInertia.inverse();
        body.linearVelocity += h * (settings_.gravity + body.inverseMass * body.force);
        body.angularVelocity += h * (inverseInertia * (body.torque - body.angularVelocity.cross(inertia * body.angularVelocity)));
        body.force.setZero();
        body.torque.setZero();
        const double travel = h * (body.linearVelocity.norm() + body.angularVelocity.norm() * body.boundingRadius);
        const int substeps = std::clamp(int(std::ceil(travel / bound)), 1, settings_.maxSubsteps);
        for (int s = 0; s < substeps; ++s) {
            advanceBody(id, h / substeps);
            resolveRigidContacts(id);
        }
        profile_.substeps += std::uint64_t(substeps);
    }
}

void World::advanceBody(BodyId id, double dt) {
    RigidBody& body = bodies_[id];
    Part& part = *parts_[id];
    const Vec3 com = centreOfMass(id) + dt * body.linearVelocity;
    Pose pose = part.pose();
    const double speed = body.angularVelocity.norm();
    if (speed > 0.0)
        pose.rotation = (Eigen::Quaterniond(Eigen::AngleAxisd(speed * dt, body.angularVelocity / speed)) * pose.rotation).normalized();
    pose.translation = com - pose.rotation * body.centreOfMass;
    part.setPose(pose);
}

void World::resolveRigidContacts(BodyId id) {
    RigidBody& body = bodies_[id];
    for (int iteration = 0; iteration < settings_.contactIterations; ++iteration) {
        StageTimer timer(profile_);
        const std::vector<Contact>& contacts = collision_.contactsOf(id, true);  // this body's pairs with rigid parts
        timer.charge(Stage::NarrowPhase);
        // This body's contacts with parts that do not deform: direction out of them, depth.
        pushes_.clear();
        for (const Contact& c : contacts) {
            const BodyId other = c.partA == id ? c.partB : c.partA;
            if (parts_[other]->mode() != PartMode::Rigid) continue;
            pushes_.emplace_back(c.partA == id ? c.normal : Vec3(-c.normal), c.depth);
        }
        if (pushes_.empty()) {
            timer.charge(Stage::ContactResponse);
            return;
        }
        // Gauss-Seidel over the contacts: each takes what the correction so far leaves of its
        // depth along its normal. Symmetric contacts (a ball on a ring) cancel sideways and add
        // up along the common direction, instead of pushing the body from side to side.
        Vec3 correction = Vec3::Zero();
        for (int pass = 0; pass < 4; ++pass)
            for (const auto& [out, depth] : pushes_) {
                const double remaining = depth - correction.dot(out);
                if (remaining > 0.0) correction += remaining * out;
            }
        parts_[id]->translate(correction);
        for (const auto& [out, depth] : pushes_) {
            const double into = body.linearVelocity.dot(out);
            if (into < 0.0) body.linearVelocity -= into * out;  // inelastic
        }
        timer.charge(Stage::ContactResponse);
        // Resting contact: nothing left to push out (a nanometre per unit of thickness), so
        // another pass would find the same contacts.
        if (correction.norm() <= 1e-9 * body.thickness) return;
    }
}

}  // namespace flexfit
