// Zones at every coverage against the whole model (issue 16: a rigid-deformable part never
// costs more than its whole model), side by side in one run, on torus2, the heart and torus1
// (spring blocks), the heart with its vertices shuffled (every spring listed), the same renumbered
// for locality (blocks again) and a large torus shuffled and renumbered alike. Six zones at mass
// seeds spread over the mesh, at levels from 2 to 24 (4 to 48 on the large torus); each step
// loads one mass. With the cheaper path (the default) a large region is stepped by the full
// step with the other masses held; without it, always by the region step. Both beside the whole model in one benchmark
// (chosen_over_whole, region_over_whole). The counter `coverage` is the share of the model's
// springs the region computes.
#include "flexfit/flexfit.hpp"
#include "part_bench_support.hpp"
#include "shuffled_mesh.hpp"

#include <benchmark/benchmark.h>

namespace {

using namespace flexfit;

std::shared_ptr<const PartModel> inLocalityOrder(TriMesh mesh) {
    PartModelSettings s;
    s.vertexOrder = VertexOrder::Locality;
    return buildPartModel(std::move(mesh), s);
}

// 0: torus2, 1: heart, 2: the heart shuffled, 3: torus1, 4: the shuffled heart renumbered by
// VertexOrder::Locality (what a scene makes of it as a file), 5: a torus of 24,576 masses
// shuffled and renumbered the same way (a large part as a file delivers it, its state several
// MB: beyond the caches that hold the others).
constexpr int kMeshes = 6, kLargeTorus = 5;
const std::shared_ptr<const PartModel>& model(int which) {
    static const std::shared_ptr<const PartModel> models[kMeshes] = {
        buildPartModel(makeTorus2()),
        buildPartModel(makeHeart()),
        buildPartModel(flexfit::testing::shuffledVertices(makeHeart(), 3)),
        buildPartModel(makeTorus1()),
        inLocalityOrder(flexfit::testing::shuffledVertices(makeHeart(), 3)),
        inLocalityOrder(flexfit::testing::shuffledVertices(makeTorus(10.0, 2.5, 256, 96), 3))};
    return models[which];
}
const char* kNames[kMeshes] = {"torus2", "heart", "heart shuffled", "torus1", "heart shuffled, locality order",
                               "large torus shuffled, locality order"};

PartSettings settings(PartMode mode, bool cheaper) {
    PartSettings s;
    s.mode = mode;
    s.simulation.timeStep = 1e-3;
    s.zones.retireCheckInterval = 1 << 30;  // the zones stay: the coverage is what is measured
    s.zones.fullStepWhenCheaper = cheaper;
    return s;
}

// Six zones at mass seeds spread over the mesh, each grown to `level`.
Part zonesPart(int mesh, int level, bool cheaper) {
    const auto& m = model(mesh);
    Part part(m, settings(PartMode::RigidDeformable, cheaper));
    for (Index seed = 0; seed < m->massCount(); seed += Index(m->massCount() / 6)) part.openZone(ZoneSeed::mass(seed), level);
    return part;
}

// Three parts stepped in alternating chunks (pairedChunkTimes: four copies, each pair of parts
// built in either order twice, as where the allocator puts a state moves its time): the zones
// with the cheaper path (the default), the same zones by the region step only, and the whole model.
void BM_Zones(benchmark::State& state) {
    const int mesh = int(state.range(0)), level = int(state.range(1));
    constexpr int kChunk = 8;
    constexpr std::size_t kCopies = 4;  // each order and its reverse, twice rotated
    const flexfit::bench::PairedTimes t = flexfit::bench::pairedChunkTimes(
        state,
        {[&] { return zonesPart(mesh, level, true); }, [&] { return zonesPart(mesh, level, false); },
         [&] { return Part(model(mesh), settings(PartMode::FullDeformable, true)); }},
        {true, true, true}, kChunk, kCopies);
    state.SetLabel(kNames[mesh]);
    state.counters["chosen_over_whole"] = t.ratio(0, 2);
    state.counters["region_over_whole"] = t.ratio(1, 2);
    state.counters["whole_ns_per_step"] = t.nsPerStep(2, kChunk);
    // The region's size, and the counts fullStepCostsLess weighs (RegionWork), to fit its costs to these timings.
    const Part part = zonesPart(mesh, level, true);
    const RegionWork work = RegionWork::of(part.region());
    state.counters["coverage"] = double(part.computedSprings().size()) / double(part.model().springCount());
    state.counters["computed_springs"] = double(part.computedSprings().size());
    state.counters["loose_springs"] = double(work.looseSprings);
    state.counters["block_lanes"] = double(work.blockLanes);  // 8 a vector block
    state.counters["moving_masses"] = double(part.movingMasses().size());
    state.counters["full_step_chosen"] = part.region().coversEveryMass() || fullStepCostsLess(part.model(), work) ? 1.0 : 0.0;
}

void Coverages(benchmark::internal::Benchmark* b) {
    for (int mesh = 0; mesh < kMeshes; ++mesh)
        for (int level : {2, 4, 8, 12, 16, 24}) b->Args({mesh, mesh == kLargeTorus ? 2 * level : level});
}

BENCHMARK(BM_Zones)->Apply(Coverages);

}  // namespace

BENCHMARK_MAIN();
