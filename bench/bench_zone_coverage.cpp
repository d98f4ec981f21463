// Zones at every coverage against the whole model (issue 16: a rigid-deformable part never
// costs more than its whole model), side by side in one run, on torus2, the heart and torus1
// (spring blocks), the heart with its vertices shuffled (every spring listed) and the same renumbered
// for locality (blocks again). Six zones at mass
// seeds spread over the mesh, at levels from 2 to 24; each step loads one mass. With the
// cheaper path (the default) a large region is stepped by the full step with the other masses
// held; without it, always by the region step. The counter `coverage` is the share of the
// model's springs the region computes.
#include "flexfit/flexfit.hpp"
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
// VertexOrder::Locality (what a scene makes of it as a file).
const std::shared_ptr<const PartModel>& model(int which) {
    static const std::shared_ptr<const PartModel> models[5] = {buildPartModel(makeTorus2()), buildPartModel(makeHeart()),
                                                               buildPartModel(flexfit::testing::shuffledVertices(makeHeart(), 3)),
                                                               buildPartModel(makeTorus1()),
                                                               inLocalityOrder(flexfit::testing::shuffledVertices(makeHeart(), 3))};
    return models[which];
}
const char* kNames[5] = {"torus2", "heart", "heart shuffled", "torus1", "heart shuffled, locality order"};

PartSettings settings(PartMode mode, bool cheaper) {
    PartSettings s;
    s.mode = mode;
    s.simulation.timeStep = 1e-3;
    s.zones.retireCheckInterval = 1 << 30;  // the zones stay: the coverage is what is measured
    s.zones.fullStepWhenCheaper = cheaper;
    return s;
}

void step(benchmark::State& state, Part& part) {
    for (auto _ : state) {
        part.applyForce(0, Vec3(0, 0.05, 0));
        part.step();
    }
    state.SetLabel(kNames[state.range(0)]);
    state.counters["coverage"] = double(part.computedSprings().size()) / double(part.model().springCount());
    // The region's size, and the counts fullStepCostsLess weighs (RegionWork), to fit its costs to these timings.
    const ActiveRegion& region = part.region();
    state.counters["computed_springs"] = double(part.computedSprings().size());
    const RegionWork work = RegionWork::of(region);
    state.counters["loose_springs"] = double(work.looseSprings);
    state.counters["block_lanes"] = double(work.blockLanes);  // 8 a vector block
    state.counters["moving_masses"] = double(part.movingMasses().size());
}

void BM_Whole(benchmark::State& state) {
    Part part(model(int(state.range(0))), settings(PartMode::FullDeformable, true));
    step(state, part);
}

void BM_Zones(benchmark::State& state) {
    const auto& m = model(int(state.range(0)));
    Part part(m, settings(PartMode::RigidDeformable, state.range(2) != 0));
    for (Index seed = 0; seed < m->massCount(); seed += Index(m->massCount() / 6)) part.openZone(ZoneSeed::mass(seed), int(state.range(1)));
    step(state, part);
}

void Coverages(benchmark::internal::Benchmark* b) {
    for (int mesh : {0, 1, 2, 3, 4})
        for (int level : {2, 4, 8, 12, 16, 24})
            for (int cheaper : {1, 0}) b->Args({mesh, level, cheaper});
}

BENCHMARK(BM_Whole)->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Arg(4);
BENCHMARK(BM_Zones)->Apply(Coverages);

}  // namespace

BENCHMARK_MAIN();
