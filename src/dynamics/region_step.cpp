// The step of an active region (rigid-deformable parts): springs, then moving masses.
#include "flexfit/simulation.hpp"
#include "flush_denormals.hpp"
#include "full_step.hpp"
#include "implicit_step.hpp"
#include "mass_update.hpp"
#include "region_step.hpp"
#include "model/spring_blocks.hpp"

#include <algorithm>

namespace flexfit {

namespace {

// The moving masses: body forces, integration, restoration; pending forces consumed. The
// region's vector octets by the vector kernel (their masses that do not move put back where they
// are, at rest), then the others as a list (each mass alone: same bits). With
// `check`, mass 0 first when it moves (its octet, or itself), which fixes the origin; then every
// other mass checked as it is written. Masses are independent here: the order changes no bit.
void integrateRegion(const PartModel& model, const detail::MassUpdate& p, const ActiveRegion& region, PartState& state,
                     detail::PositionCheck* check) {
    const detail::BlockKernel kernel = detail::fullStepKernel();
    std::span<const Index> octets = region.vectorOctets().members(), octetsAfter;
    const std::uint16_t* held = region.coverCounts().data();
    std::span<const Index> loose = region.looseMasses().members(), looseAfter;
    if (check == nullptr || kernel == detail::BlockKernel::Scalar) {
        detail::integrateOctets(model, p, octets, held, state, kernel);
        detail::integrateListed(model, p, loose, state, kernel);
        return;
    }
    const bool massZeroFirst = check->fromMassZero() && region.moves(0);
    const bool octetZero = massZeroFirst && region.vectorOctets().contains(0);
    if (octetZero) {  // octet 0 alone, then the octets before and after it in the list
        const std::size_t slot = region.vectorOctets().slotOf(0);
        detail::integrateOctets(model, p, octets.subspan(slot, 1), held, state, kernel);
        octetsAfter = octets.subspan(slot + 1);
        octets = octets.first(slot);
    } else if (massZeroFirst) {  // mass 0 alone, then the loose masses before and after it
        const std::size_t slot = region.looseMasses().slotOf(0);
        detail::integrateMass(model, p, state, 0);
        looseAfter = loose.subspan(slot + 1);
        loose = loose.first(slot);
    }
    check->fixOrigin(state);
    if (octetZero) check->add(state, 0, 8);
    else if (massZeroFirst) check->add(state, 0);
    detail::integrateOctets(model, p, octets, held, state, kernel, check);
    detail::integrateOctets(model, p, octetsAfter, held, state, kernel, check);
    detail::integrateListed(model, p, loose, state, kernel, check);
    detail::integrateListed(model, p, looseAfter, state, kernel, check);
    check->covered = true;
}

}  // namespace

void stepActiveRegion(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region,
                      PartState& state, StepCounters* counters) {
    detail::requireStepInputs(model, settings, state, &region, {}, "stepActiveRegion");
    detail::stepRegion(model, settings, region, state, counters, nullptr);
}

void detail::stepRegion(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region,
                        PartState& state, StepCounters* counters, PositionCheck* check) {
    const detail::FlushDenormals flush;
    if (settings.integrator == Integrator::ImplicitEuler) return detail::stepImplicit(model, settings, &region, state, counters);
    const detail::MassUpdate p = detail::MassUpdate::from(settings);
    const double* x = state.positions.data()->data();
    const double* v = state.velocities.data()->data();
    double* f = state.forces.data()->data();
    const std::uint16_t* mask = region.coverCounts().data();
    const std::span<const Index> computed = region.springs().members(), moving = region.masses().members();

    // Springs: forces reach only the moving ends (a fixed end is held by the rigid body). The
    // vector blocks by the block kernel, then the others by the listed-spring kernel.
    if (!region.vectorBlocks().empty())
        detail::regionBlockForces(*model.springBlocks, region.vectorBlocks().members(), mask, x, v, f,
                                  detail::fullStepKernel());
    detail::listedSpringForces(region.looseSpringList(), mask, x, v, f, detail::fullStepKernel());
    integrateRegion(model, p, region, state, settings.integrator == Integrator::SemiImplicitEuler ? check : nullptr);
    state.time += settings.timeStep;
    ++state.stepCount;
    if (counters != nullptr) {
        counters->springsEvaluated += computed.size();
        counters->massesIntegrated += moving.size();
    }
}

void detail::stepRegionByFullModelFromRest(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region,
                                           PartState& state, StepCounters* counters) {
    detail::stepAllMasses(model, settings, {}, region.coverCounts().data(), state, counters);
}

void stepRegionByFullModel(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region,
                           PartState& state, StepCounters* counters) {
    detail::requireStepInputs(model, settings, state, &region, {}, "stepRegionByFullModel");
    detail::stepRegionByFullModelFromRest(model, settings, region, state, counters);
    // The groups the explicit kernels skipped as at rest may not have been: every held mass back
    // to rest (a selection: the same bits wherever they already were). The implicit step puts
    // them back itself.
    if (settings.integrator != Integrator::ImplicitEuler) detail::holdAtRest(model, region.coverCounts(), state, detail::fullStepKernel());
}

RegionWork RegionWork::of(const ActiveRegion& region) {
    return {region.looseSprings().size(), SpringBlocks::kWidth * region.vectorBlocks().size(), region.masses().size()};
}

bool fullStepCostsLess(const PartModel& model, const RegionWork& work) {
    // Costs in ns on the reference machine (simulation.hpp); only their ratios matter. A loose
    // spring's ends' state is gathered: it costs more once the part's state outgrows the
    // nearest caches, fitted as a ramp over the mass count (576 to 7,349 masses measured). 5.0 +
    // 3.0 before the region kept its loose springs' ends and constants in a list, scaled by what
    // that list did to the regions of loose springs only (0.83-0.88x of their step,
    // bench/results/listed_springs_zones_1207.csv).
    const double regionSpring = 4.3 + 2.6 * std::min(1.0, double(model.massCount()) / 7000.0);
    constexpr double kRegionBlockLane = 2.7, kRegionMass = 2.0;
    constexpr double kBlockLane = 2.8, kListedSpring = 6.0, kPutBack = 0.3;
    // The region step only where it is estimated at most kRegionShare of the full step: the two
    // paths' relative speed moves with the machine's state (simulation.hpp), and taking the
    // full step wrongly costs its put-back (up to 1.06x), taking the region step wrongly up to
    // 1.5x. (In a world the full step's streaming also evicts what the collision stages keep in
    // cache: measured on the haptic scene, ~35 % of the springs, no difference either way.)
    constexpr double kRegionShare = 0.62;
    const double region = regionSpring * double(work.looseSprings) + kRegionBlockLane * double(work.blockLanes) +
                          kRegionMass * double(work.movingMasses);
    const SpringBlocks& blocks = *model.springBlocks;
    const double full = kBlockLane * double(blocks.blockCount() * SpringBlocks::kWidth) +
                        kListedSpring * double(blocks.remainder.size()) +
                        kPutBack * double(model.massCount() - std::min(work.movingMasses, model.massCount()));
    return region >= kRegionShare * full;
}

}  // namespace flexfit
