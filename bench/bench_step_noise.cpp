// How much of a measured step-time tail is the machine's: a step of fixed work (the same
// arithmetic over the same ~96 KB every time, about as long as the step of interest) timed like
// World::step, --runs runs of --steps steps. Every step does the same work, so the floor (each
// step's fastest time over the runs) is flat, and any spread in a run's own percentiles is the
// machine's: interrupts, the hypervisor taking the core, frequency changes. Compare a scene's
// measured p99 over its floor p99 (tools/tail_repeats.py) with this one's at the same step time,
// in the same hour: what a scene's measured tail exceeds this by is the work's own.
// (bench_world's BM_FixedWorkTail reads the same kind of spread as p99 over p50 inside Google
// Benchmark's repetitions, at one fixed step; this takes tail_repeats' percentiles, measured and
// floor over runs, at the step time asked.)
//
//   build/release/bench/bench_step_noise --work-us 100 --runs 15 --steps 1000
//
// Prints CSV: the target and calibrated work, measured p50 / p99 (median over the runs of each
// run's nearest-rank percentile, as tail_repeats' measured_*), floor p50 / p99 and the measured
// p99 over the floor p99.
#include "flexfit/profile.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

namespace {

using flexfit::nearestRankPercentile;

struct Options {
    double workUs = 100.0;
    int runs = 15;
    int steps = 1000;
};

[[noreturn]] void usage(const char* problem) {
    std::fprintf(stderr, "bench_step_noise: %s\nusage: bench_step_noise [--work-us US in (0, 1e6)] [--runs N in 1..1000] [--steps N in 100..1e7]\n", problem);
    std::exit(2);
}

Options parse(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string_view flag = argv[i];
        if (i + 1 >= argc) usage("a flag without its value");
        const char* value = argv[++i];
        char* end = nullptr;
        const double number = std::strtod(value, &end);
        if (end == value || *end != '\0') usage("a value that is not a number");
        if (flag == "--work-us" && number > 0.0 && number < 1e6)
            o.workUs = number;
        else if (flag == "--runs" && number >= 1 && number <= 1000 && number == double(int(number)))
            o.runs = int(number);
        else if (flag == "--steps" && number >= 100 && number <= 1e7 && number == double(int(number)))
            o.steps = int(number);
        else
            usage((std::string("unknown flag or value out of range: ") + std::string(flag) + " " + value).c_str());
    }
    return o;
}

// The fixed work: `rounds` passes over `data`, each depending on the last (nothing is hoisted).
double work(std::vector<double>& data, int rounds) {
    double sum = 0.0;
    for (int r = 0; r < rounds; ++r)
        for (double& d : data) {
            sum += d * 1.0000001;
            d = sum * 1e-9 + 1.0;
        }
    return sum;
}

double microseconds(std::chrono::steady_clock::duration d) { return std::chrono::duration<double, std::micro>(d).count(); }

double timedWork(std::vector<double>& data, int rounds, volatile double& sink) {
    const auto start = std::chrono::steady_clock::now();
    sink = work(data, rounds);
    return microseconds(std::chrono::steady_clock::now() - start);
}

// Rounds of work that take about `us`, from the fastest of repeated timings of 16 rounds.
int calibrate(std::vector<double>& data, double us, volatile double& sink) {
    double fastest = 1e300;
    for (int i = 0; i < 200; ++i) fastest = std::min(fastest, timedWork(data, 16, sink));
    return std::max(1, int(us / (fastest / 16.0) + 0.5));
}

}  // namespace

int main(int argc, char** argv) {
    const Options o = parse(argc, argv);
    std::vector<double> data(12000, 1.0);
    volatile double sink = 0.0;
    const int rounds = calibrate(data, o.workUs, sink);
    std::vector<std::vector<double>> times(std::size_t(o.runs), std::vector<double>(std::size_t(o.steps)));
    for (auto& run : times)
        for (double& t : run) t = timedWork(data, rounds, sink);
    std::vector<double> p50s, p99s, floor(std::size_t(o.steps), 1e300);
    for (const auto& run : times) {
        p50s.push_back(nearestRankPercentile(run, 50.0));
        p99s.push_back(nearestRankPercentile(run, 99.0));
        for (std::size_t s = 0; s < run.size(); ++s) floor[s] = std::min(floor[s], run[s]);
    }
    // The median over the runs of each run's percentile, as tail_repeats' measured_* (odd run counts).
    const double measuredP50 = nearestRankPercentile(p50s, 50.0), measuredP99 = nearestRankPercentile(p99s, 50.0);
    const double floorP99 = nearestRankPercentile(floor, 99.0);
    std::printf("work_us,rounds,runs,steps,measured_p50,measured_p99,floor_p50,floor_p99,measured_p99_over_floor_p99\n");
    std::printf("%.1f,%d,%d,%d,%.1f,%.1f,%.1f,%.1f,%.3f\n", o.workUs, rounds, o.runs, o.steps, measuredP50, measuredP99,
                nearestRankPercentile(floor, 50.0), floorP99, measuredP99 / floorP99);
}
