// The world step while a ball is in contact with the container mouth (issue 5's haptic-rate
// goal: >= 1 kHz with the mouth at heart resolution, about 7,300 masses). Each iteration loads
// the scene, runs it (untimed) to `settle` steps after the first contact, then times
// kTimedSteps steps in contact. Counters: steps_per_s (in contact), contacts, moving masses,
// and the mean time per step of each stage and of the whole World::step, in microseconds (the
// world's own profile over the timed steps), and the whole step's 99th percentile (nearest rank,
// over every timed step of every iteration): a haptic loop's worst steps, not its mean; beside
// them BM_FixedWorkTail, the same work repeated, whose spread is the machine's own.
#include "collision/sampling_kernel.hpp"
#include "flexfit/scene_file.hpp"
#include "flexfit/scene_run.hpp"

#include <benchmark/benchmark.h>

#include <chrono>
#include <vector>

using namespace flexfit;

namespace {

constexpr int kTimedSteps = 200;

Scene scene(const char* file, bool push, bool faceQuery) {
    Scene s = loadScene(std::string(FLEXFIT_EXAMPLES_DIR) + "/" + file);
    if (!push) s.actions.clear();  // gravity only: the ball rests on the rim
    if (faceQuery) s.world.collision.rigidDeformable = RigidDeformableQuery::Faces;
    return s;
}

// p50 and p99 (nearest rank) of the timed steps, in µs, and their ratio. One set of names for
// every benchmark here: Google Benchmark's CSV has one header.
void setTailCounters(benchmark::State& state, const std::vector<double>& micros) {
    state.counters["us_world_step_p50"] = nearestRankPercentile(micros, 50.0);
    state.counters["us_world_step_p99"] = nearestRankPercentile(micros, 99.0);
    state.counters["p99_over_p50"] = state.counters["us_world_step_p99"] / state.counters["us_world_step_p50"];
}

void stepInContact(benchmark::State& state, const char* file, bool push, int settle, bool faceQuery = false) {
    const Scene base = scene(file, push, faceQuery);
    double seconds = 0.0, contacts = 0.0, moving = 0.0;
    std::array<double, kStageCount> stages{};
    double stepSeconds = 0.0;
    std::vector<double> stepMicros;  // every timed step of every iteration
    for (auto _ : state) {
        SceneRun run(base);
        World& w = run.world();
        int touching = 0;
        for (int i = 0; i < 100000 && touching <= settle; ++i) {
            run.step();
            if (!w.contacts().empty() || touching > 0) ++touching;
        }
        const Profile before = w.profile();
        const auto start = std::chrono::steady_clock::now();
        for (int i = 0; i < kTimedSteps; ++i) {
            run.step();
            stepMicros.push_back(1e6 * w.profile().lastStepSeconds);
        }
        const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        state.SetIterationTime(elapsed);
        seconds += elapsed;
        contacts += double(w.contacts().size());
        moving += double(w.part(0).movingMasses().size());
        for (std::size_t s = 0; s < stages.size(); ++s) stages[s] += w.profile().totalSeconds[s] - before.totalSeconds[s];
        stepSeconds += w.profile().totalStepSeconds - before.totalStepSeconds;
    }
    const double n = double(state.iterations());
    state.counters["steps_per_s"] = double(kTimedSteps) * n / seconds;
    state.counters["contacts"] = contacts / n;
    state.counters["moving_masses"] = moving / n;
    for (std::size_t s = 0; s < stages.size(); ++s) state.counters[std::string("us_") + toString(Stage(s))] = 1e6 * stages[s] / (n * kTimedSteps);
    state.counters["us_world_step"] = 1e6 * stepSeconds / (n * kTimedSteps);
    setTailCounters(state, stepMicros);
}

// The machine's own tail, for reading the steps' p99 beside it: the same work every time (a
// read-modify-write walk of kNoiseDoubles doubles, 4 MB, with a stride coprime to its size,
// about 130 us a repetition on the Intel machine), timed kNoiseRepetitions times. Whatever
// spread its times show is the machine's (interrupts, the hypervisor, caches shared with other
// guests), not the work's.
constexpr std::size_t kNoiseDoubles = std::size_t(1) << 19;
constexpr std::size_t kNoiseTouches = 56 * 1024;
constexpr int kNoiseRepetitions = 3000;

void BM_FixedWorkTail(benchmark::State& state) {
    std::vector<double> buffer(kNoiseDoubles, 1.0);
    std::vector<double> micros;
    std::size_t at = 0;
    double sum = 0.0;
    for (auto _ : state) {
        double seconds = 0.0;
        for (int r = 0; r < kNoiseRepetitions; ++r) {
            const auto start = std::chrono::steady_clock::now();
            for (std::size_t i = 0; i < kNoiseTouches; ++i) {
                double& x = buffer[(at + i * 67) % kNoiseDoubles];
                sum += x;
                x = sum * 1e-9;
            }
            at = (at + kNoiseTouches) % kNoiseDoubles;
            const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            micros.push_back(1e6 * elapsed);
            seconds += elapsed;
        }
        state.SetIterationTime(seconds);
    }
    benchmark::DoNotOptimize(sum);
    setTailCounters(state, micros);  // the step benchmarks' column names: here a repetition's times
}

// Pushed with 2,500 through the mouth: the timed steps start 20 steps after the first contact,
// while the rim is being pushed open (the deepest contact of the run). The scene's point-shell
// query, and beside it the face-face query it replaces for this pair.
void BM_HapticMouthPushed(benchmark::State& s) { stepInContact(s, "ball_torus_haptic.toml", true, 20); }
// The same with the point shell's masses sampled one by one (the distance field's scalar path).
void BM_HapticMouthPushedScalarSampling(benchmark::State& s) {
    const flexfit::detail::ScopedScalarSampling scalar;
    stepInContact(s, "ball_torus_haptic.toml", true, 20);
}
void BM_HapticMouthPushedFaceQuery(benchmark::State& s) { stepInContact(s, "ball_torus_haptic.toml", true, 20, true); }
// Resting on the rim under its weight, 500 steps after the first contact.
void BM_HapticMouthResting(benchmark::State& s) { stepInContact(s, "ball_torus_haptic.toml", false, 500); }
void BM_HapticMouthRestingFaceQuery(benchmark::State& s) { stepInContact(s, "ball_torus_haptic.toml", false, 500, true); }
// The same at the container-mouth resolution (64 x 24 = 1,536 masses).
void BM_MouthPushed(benchmark::State& s) { stepInContact(s, "ball_torus.toml", true, 20); }
void BM_MouthPushedFaceQuery(benchmark::State& s) { stepInContact(s, "ball_torus.toml", true, 20, true); }
void BM_MouthResting(benchmark::State& s) { stepInContact(s, "ball_torus.toml", false, 500); }
void BM_MouthRestingFaceQuery(benchmark::State& s) { stepInContact(s, "ball_torus.toml", false, 500, true); }
// A rigid mouth: the ball rests on it, projected by the rigid contact dynamics.
void BM_RigidMouthResting(benchmark::State& s) { stepInContact(s, "ball_torus_rigid.toml", false, 500); }

}  // namespace

BENCHMARK(BM_HapticMouthPushed)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_HapticMouthPushedScalarSampling)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_HapticMouthPushedFaceQuery)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_HapticMouthResting)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_HapticMouthRestingFaceQuery)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_MouthPushed)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_MouthPushedFaceQuery)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_MouthResting)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_MouthRestingFaceQuery)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_RigidMouthResting)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_FixedWorkTail)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);

BENCHMARK_MAIN();
