// A haptic loop on Flexfit's C++ API: an operator's device holds a ball through the world's
// coupling (World::grab) and lowers it through a deformable container mouth, one world step per
// device tick at a fixed rate (1 kHz by default), and renders the coupling's opposite as the
// device's force. What a haptic application does, less the device driver: the "device" here
// is a scripted hand position, eased from above the mouth to below it.
//
//   build/release/examples/cpp/haptic_loop                   # 3 s at 1 kHz, paced by the clock
//   build/release/examples/cpp/haptic_loop --rate 5000       # 5 kHz: a stiffer, cleaner contact
//   build/release/examples/cpp/haptic_loop --free-running    # as fast as it goes, no pacing
//
// Pacing: each tick has a deadline (start + (k + 1) / rate); a step that ends after its tick's
// deadline is a miss, and the loop then starts the next tick at once (it never sleeps to catch
// up, and never skips a step: the simulated time is always k / rate). Between ticks it sleeps,
// then spins the last 200 us (waitUntil). World::prepare() before
// the loop makes the first step cost what the next ones do. The world is single-threaded: a
// device thread would hand the hand pose to this loop and read the force back, at most one
// tick old.
#include <flexfit/flexfit.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace {

using Clock = std::chrono::steady_clock;

struct Options {
    double rate = 1000.0;    // Hz: world steps (device ticks) per second
    double seconds = 3.0;    // simulated, = wall time when paced
    bool freeRunning = false;
};

Options parse(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--free-running") o.freeRunning = true;
        else if (a == "--rate" && i + 1 < argc) o.rate = std::atof(argv[++i]);
        else if (a == "--seconds" && i + 1 < argc) o.seconds = std::atof(argv[++i]);
        else {
            std::fprintf(stderr, "usage: haptic_loop [--rate HZ] [--seconds S] [--free-running]\n");
            std::exit(2);
        }
    }
    if (!(o.rate >= 100.0 && o.rate <= 100000.0) || !(o.seconds > 0.0 && o.seconds <= 600.0)) {
        std::fprintf(stderr, "haptic_loop: --rate must be in [100, 100000] Hz and --seconds in (0, 600]\n");
        std::exit(2);
    }
    return o;
}

// The hand's height at time t: eased from y = 4 (the ball resting on the rim) to y = -12
// (through the mouth) over the first two seconds, then held.
double handHeight(double t) {
    const double s = std::min(t / 2.0, 1.0);
    return 4.0 - 16.0 * s * s * (3.0 - 2.0 * s);
}

// Sleeps until shortly before `deadline`, then spins to it: the system's wake-up from a sleep
// can be late by tens of microseconds (a tick at 10 kHz is 100), a spin is not.
void waitUntil(Clock::time_point deadline) {
    constexpr auto spin = std::chrono::microseconds(200);
    if (Clock::now() + spin < deadline) std::this_thread::sleep_until(deadline - spin);
    while (Clock::now() < deadline) {
    }
}

double percentile(std::vector<double> values, double q) {
    std::sort(values.begin(), values.end());
    return values[std::min(values.size() - 1, std::size_t(q * double(values.size())))];
}

// The device's world: the container mouth and the ball, the ball in the operator's hand.
struct DeviceWorld {
    flexfit::World world;
    flexfit::BodyId mouth = 0, ball = 0;
};

DeviceWorld buildWorld(double rate) {
    using namespace flexfit;
    // No gravity (the hand carries the ball), one step per device tick.
    WorldSettings settings;
    settings.timeStep = 1.0 / rate;
    settings.gravity = Vec3::Zero();
    DeviceWorld d{World(settings)};

    // The container mouth: static, rigid until the ball presses it, then deformed in zones
    // around the contacts (3 rings of neighbours), restored once released by anchor springs
    // (1,000 N/m per 1 kg mass, about critically damped). Springs are the same at any rate;
    // the restoration constraint (the default) is a fraction per step, which at 5 kHz resists
    // a load 25 times as stiffly as at 1 kHz (simulation.hpp).
    PartSettings rim;
    rim.mode = PartMode::RigidDeformable;
    rim.zones.contactLevel = 3;
    rim.simulation.restoration.method = RestorationMethod::AnchorSprings;
    rim.simulation.restoration.anchorStiffness = 1000.0;
    rim.simulation.restoration.anchorDamping = 63.0;
    BodySettings fixed;
    fixed.motion = MotionType::Static;
    d.mouth = d.world.add(buildPartModel(makeContainerMouth()), rim, fixed, Pose{});

    // The ball: rigid, dynamic, radius 8 (wider than the opening's 7.5: it must deform it).
    PartSettings solid;
    solid.mode = PartMode::Rigid;
    BodySettings dynamic;
    dynamic.motion = MotionType::Dynamic;
    dynamic.density = 0.01;
    Pose start;
    start.translation = Vec3(0.0, handHeight(0.0), 0.0);
    d.ball = d.world.add(buildPartModel(makeIcoSphere(8.0, 2)), solid, dynamic, start);

    GrabSettings hand;
    hand.frequency = 10.0;  // the coupling's spring-damper, critically damped at 10 Hz
    d.world.grab(d.ball, hand);
    for (const std::string& warning : d.world.warnings()) std::fprintf(stderr, "warning: %s\n", warning.c_str());  // none with anchors
    d.world.prepare();  // the first step then costs what the next ones do
    return d;
}

// What the loop saw.
struct LoopRecord {
    std::vector<double> stepMicros;
    long misses = 0;
    double largestForce = 0.0, lowestBall = 0.0, wallSeconds = 0.0;
};

// One world step per tick for options.seconds, printing a line every quarter second.
LoopRecord runLoop(DeviceWorld& d, const Options& options) {
    using namespace flexfit;
    const long steps = std::lround(options.seconds * options.rate);
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / options.rate));
    LoopRecord r;
    r.stepMicros.reserve(std::size_t(steps));
    r.lowestBall = d.world.centreOfMass(d.ball).y();
    std::printf("%8s %9s %9s %13s %14s %9s\n", "t (s)", "hand y", "ball y", "device fy (N)", "moving masses", "step us");
    const Clock::time_point loopStart = Clock::now();
    for (long k = 0; k < steps; ++k) {
        Pose target;
        target.translation = Vec3(0.0, handHeight(double(k) / options.rate), 0.0);
        d.world.setGrabTarget(target);  // where the device's hand is at this tick's start
        const Clock::time_point before = Clock::now();
        d.world.step();
        const Clock::time_point after = Clock::now();
        const Vec3 deviceForce = -d.world.coupling().force;  // what the operator feels
        r.stepMicros.push_back(std::chrono::duration<double, std::micro>(after - before).count());
        r.largestForce = std::max(r.largestForce, deviceForce.norm());
        r.lowestBall = std::min(r.lowestBall, d.world.centreOfMass(d.ball).y());
        if ((k + 1) % std::max(1L, std::lround(options.rate / 4.0)) == 0)
            std::printf("%8.3f %9.3f %9.3f %13.1f %14zu %9.1f\n", d.world.time(), target.translation.y(), d.world.centreOfMass(d.ball).y(),
                        deviceForce.y(), d.world.part(d.mouth).movingMasses().size(), r.stepMicros.back());
        if (options.freeRunning) continue;
        const Clock::time_point deadline = loopStart + (k + 1) * period;
        if (after > deadline) ++r.misses;
        else waitUntil(deadline);
    }
    r.wallSeconds = std::chrono::duration<double>(Clock::now() - loopStart).count();
    return r;
}

}  // namespace

int main(int argc, char** argv) {
    const Options options = parse(argc, argv);
    DeviceWorld d = buildWorld(options.rate);
    const LoopRecord r = runLoop(d, options);
    std::printf("%zu steps at %.0f Hz in %.3f s wall%s; step p50 %.1f us, p99 %.1f us, max %.1f us; deadline misses %ld\n",
                r.stepMicros.size(), options.rate, r.wallSeconds, options.freeRunning ? " (free running)" : "",
                percentile(r.stepMicros, 0.5), percentile(r.stepMicros, 0.99), percentile(r.stepMicros, 1.0), r.misses);
    std::printf("largest device force %.3f N; ball lowest at y = %.6f, now %.6f; rim moving masses %zu; state hash %016llx\n",
                r.largestForce, r.lowestBall, d.world.centreOfMass(d.ball).y(), d.world.part(d.mouth).movingMasses().size(),
                static_cast<unsigned long long>(d.world.stateHash()));
    return 0;
}
