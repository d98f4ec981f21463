// The step of an active region (rigid-deformable parts): springs, then moving masses.
#include "flexfit/simulation.hpp"
#include "flush_denormals.hpp"
#include "full_step.hpp"
#include "implicit_step.hpp"
#include "mass_update.hpp"
#include "model/spring_blocks.hpp"

#include <algorithm>

namespace flexfit {

void stepActiveRegion(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region,
                      PartState& state, StepCounters* counters) {
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
    detail::listedSpringForces(model, region.looseSprings().members(), mask, x, v, f, detail::fullStepKernel());
    // Moving masses: body forces, integration, restoration; pending forces consumed. Whole
    // octets by the vector kernel, then the others one at a time (each mass alone: same bits).
    detail::integrateOctets(model, p, region.fullOctets().members(), state, detail::fullStepKernel());
    for (Index i : region.looseMasses()) detail::integrateMass(model, p, state, i);
    state.time += settings.timeStep;
    ++state.stepCount;
    if (counters != nullptr) {
        counters->springsEvaluated += computed.size();
        counters->massesIntegrated += moving.size();
    }
}

void stepRegionByFullModel(const PartModel& model, const SimulationSettings& settings, const ActiveRegion& region,
                           PartState& state, StepCounters* counters) {
    detail::stepAllMasses(model, settings, {}, region.coverCounts().data(), state, counters);
}

RegionWork RegionWork::of(const ActiveRegion& region) {
    return {region.looseSprings().size(), SpringBlocks::kWidth * region.vectorBlocks().size(), region.masses().size()};
}

bool fullStepCostsLess(const PartModel& model, const RegionWork& work) {
    // Costs in ns on the reference machine (simulation.hpp); only their ratios matter. A loose
    // spring's ends and constants are gathered: it costs more once the part's state outgrows
    // the nearest caches, fitted as a ramp over the mass count (576 to 7,349 masses measured).
    const double regionSpring = 5.0 + 3.0 * std::min(1.0, double(model.massCount()) / 7000.0);
    constexpr double kRegionBlockLane = 2.7, kRegionMass = 2.0;
    constexpr double kBlockSpring = 2.8, kListedSpring = 6.0, kPutBack = 0.3;
    // No margin: near the crossover the two cost the same. (In a world the full step's
    // streaming also evicts what the collision stages keep in cache: measured on the haptic
    // scene, ~35 % of the springs, no difference either way.)
    const double region = regionSpring * double(work.looseSprings) + kRegionBlockLane * double(work.blockLanes) +
                          kRegionMass * double(work.movingMasses);
    const std::size_t blocked = model.springBlocks->blockCount() * SpringBlocks::kWidth;
    const double full = kBlockSpring * double(blocked) + kListedSpring * double(model.springCount() - blocked) +
                        kPutBack * double(model.massCount() - std::min(work.movingMasses, model.massCount()));
    return full < region;
}

}  // namespace flexfit
