// mechbal-loop: runs a control tick at a fixed rate with absolute deadlines
// (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME)) and reports the tick computation time
// (p50, p99, p99.9, max), the wake-up latency and the deadline misses (a tick that ends after the
// next release time).
//
// Workloads (--workload):
//   ct6 (default): the real controller, ComputedTorque over MechanismDynamics on the 6-joint bench
//     chain, tracking a quintic rest-to-rest trajectory (back and forth) evaluated every tick;
//   paminsa: the whole PAMINSA tick (PaminsaController::tick: mechanism kinematics at t, t + dt/2,
//     t + dt, D, the reactionless wrist with RK4, wrist kinematics, shaking wrench of 38 bodies),
//     the platform following a smooth 3-D motion around the nominal pose;
//   paminsa_general: the general PAMINSA tick (issue 26): PAMINSA on the general model (38 bodies,
//     9 loop closures; paminsa_general.hpp), computed torque through MechanismDynamics (loop
//     solve warm-started from the last tick, projection, inverse dynamics, C^T tau) with the
//     support wrench (the shaking wrench with the weights) of all bodies, along the same platform
//     and wrist motion, the "measured" state the reference with a small tracking error;
//   reactionless_general: the general reactionless tick (issue 21) on the same model: the
//     ReactionlessController with the three wrist joints balancing the moment, RK4 (loop solve,
//     projection, the balancing columns and the task momentum, the rate solve at four stages,
//     feed-forward, predicted shaking wrench).
//
// Every tick is timed twice: wall clock (CLOCK_MONOTONIC) and the thread's CPU time
// (CLOCK_THREAD_CPUTIME_ID). A tick whose wall time exceeds its CPU time by more than 2 us was
// preempted (another thread ran on the core); the JSON reports the p99.9 of the wall time over
// the ticks that were not (p999_unpreempted_ns) beside the raw one, the number of preempted ticks,
// and the compute overruns (wall > period) of both kinds. A VM's vCPU preemption by the host
// (steal) is charged to the thread's CPU time on the benchmark VM (a tick's CPU time then equals
// its wall time), so it cannot be told apart per tick: the JSON gives the machine's steal fraction
// over the run (/proc/stat) beside the tail, to say how much of it the host's doing may be.
//
// Twin ticks (compute separated from host preemption): the loop builds the workload twice and
// feeds both copies the same inputs every period, one right after the other (order alternating),
// so that both compute exactly the same thing. A tick's own cost (data-dependent iterations, a
// slow path) shows in both copies; a host stall of the vCPU, which the guest cannot see, rarely
// hits both. The JSON's twin_* fields are percentiles of min(copy A, copy B) per period: the
// compute tail with single stalls filtered out. The raw percentiles above stay copy A's; a
// deadline miss is counted when the two copies together end after the next release.
//
// Usage: mechbal-loop [--seconds S] [--rate HZ] [--rt] [--json FILE] [--spin-us S]
//                     [--workload ct6|paminsa|paminsa_general|reactionless_general]
//   --spin-us: sleep until S us before each release, then poll the clock (0: sleep to the release)
//   --rt: try SCHED_FIFO (priority 80) and mlockall(MCL_CURRENT | MCL_FUTURE); when not permitted
//         (no CAP_SYS_NICE / RLIMIT_RTPRIO, RLIMIT_MEMLOCK) it says so and runs without.
#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "mechbal/control/computed_torque.hpp"
#include "mechbal/control/reactionless.hpp"
#include "paminsa_general.hpp"
#include "mechbal/papers/paminsa/paminsa.hpp"
#include "mechbal/control/mechanism_dynamics.hpp"
#include "mechbal/control/trajectory.hpp"
#include "paminsa_motion.hpp"
#include "test_support.hpp"

namespace {

constexpr long kNsPerSec = 1000000000L;

long long to_ns(const timespec& t) { return static_cast<long long>(t.tv_sec) * kNsPerSec + t.tv_nsec; }
timespec from_ns(long long ns) {
  timespec t;
  t.tv_sec = static_cast<time_t>(ns / kNsPerSec);
  t.tv_nsec = static_cast<long>(ns % kNsPerSec);
  return t;
}
long long now_ns() {
  timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return to_ns(t);
}

double pct(std::vector<long long> v, double p) {
  if (v.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return static_cast<double>(v[k]);
}

void usage() {
  std::fprintf(stderr,
               "usage: mechbal-loop [--seconds S] [--rate HZ] [--rt] [--json FILE] [--spin-us S] "
               "[--workload ct6|paminsa|paminsa_general|reactionless_general]\n");
}

/// The 6-joint computed-torque workload; tick() is noexcept and allocation-free.
struct ComputedTorqueWorkload {
  static constexpr const char* name = "ct6";
  static constexpr const char* description =
      "ct6: trajectory evaluate + ComputedTorque::step over MechanismDynamics (6 joints)";
  ComputedTorqueWorkload()
      : model(make_chain()),
        dynamics(model),
        controller(dynamics, Eigen::VectorXd::Constant(6, kp), Eigen::VectorXd::Constant(6, kd)),
        trajectory(Eigen::VectorXd::Constant(6, -0.8), Eigen::VectorXd::Constant(6, 0.9), 0.75,
                   mechbal::TimeLaw::quintic),
        q_ref(6), qd_ref(6), qdd_ref(6), q(6), qd(6), tau(6) {}

  static mechbal::MechanismModel make_chain() {
    std::mt19937 rng(1006u);  // the same 6-joint chain as mechbal-bench's ct6 cases
    return mechbal::MechanismModel(mechbal::test::random_chain(rng, "RRRRRR"));
  }

  mechbal::Status tick(double t) noexcept {
    // back and forth along the rest-to-rest trajectory
    const double period = 2.0 * trajectory.duration();
    double tt = std::fmod(t, period);
    if (tt > trajectory.duration()) tt = period - tt;
    mechbal::Status s = trajectory.evaluate(tt, q_ref, qd_ref, qdd_ref);
    // "measured" state: the reference with a small deterministic tracking error
    q = q_ref.array() + 1e-3 * std::sin(50.0 * t);
    qd = qd_ref.array() - 1e-2 * std::cos(50.0 * t);
    s |= controller.step(q, qd, q_ref, qd_ref, qdd_ref, tau);
    return s;
  }

  static constexpr double kp = 100.0, kd = 20.0;
  mechbal::MechanismModel model;
  mechbal::MechanismDynamics dynamics;
  mechbal::ComputedTorque controller;
  mechbal::RestToRestTrajectory trajectory;
  Eigen::VectorXd q_ref, qd_ref, qdd_ref, q, qd, tau;
};

/// The whole PAMINSA tick at 1 kHz with the RK4 wrist; tick() is noexcept and allocation-free.
struct PaminsaWorkload {
  static constexpr const char* name = "paminsa";
  static constexpr const char* description =
      "paminsa: PaminsaController::tick (kinematics at t, t+dt/2, t+dt + D + RK4 reactionless "
      "wrist + shaking wrench of 38 bodies)";
  explicit PaminsaWorkload(double rate)
      : dt(1.0 / rate), controller(mechbal::PaminsaModel{mechbal::PaminsaParameters{}},
                                    config(rate), start) {
    mechbal::PlatformMotion rest = platform_at(0.0);
    rest.velocity.setZero();
    rest.acceleration.setZero();
    controller.reset(rest, start);
  }
  static mechbal::ReactionlessWristConfig config(double rate) {
    mechbal::ReactionlessWristConfig c;
    c.rate_hz = rate;
    c.integrator = mechbal::WristIntegrator::rk4;
    return c;
  }
  static mechbal::PlatformMotion platform_at(double t) noexcept { return mechbal::test::platform_at(t); }
  mechbal::Status tick(double t) noexcept {
    return controller.tick(platform_at(t), platform_at(t + dt / 2), platform_at(t + dt));
  }
  const mechbal::Vec3 start{M_PI / 2, M_PI / 2, M_PI / 2};
  double dt;
  mechbal::PaminsaController controller;
};

/// The general PAMINSA tick: computed torque over MechanismDynamics (closed loops) with the support
/// wrench; the reference precomputed at 1 kHz along 1024 instants, back and forth (no allocation
/// in tick()).
struct PaminsaGeneralWorkload {
  static constexpr const char* name = "paminsa_general";
  static constexpr const char* description =
      "paminsa_general: PAMINSA on the general model (38 bodies, 9 loops): computed torque through "
      "MechanismDynamics (loop solve, projection, inverse dynamics, C^T tau) + support wrench";
  static constexpr int kInstants = 1024;
  PaminsaGeneralWorkload()
      : closed(mechbal::PaminsaParameters{}),
        model(std::make_shared<const mechbal::MechanismModel>(mechbal::bench::paminsa_description(closed))),
        dynamics(model, mechbal::bench::initial_guess(closed, *model, mechbal::test::platform_at(0.0),
                                                      mechbal::test::wrist_at(0.0))) {
    for (int n = 0; n < kInstants; ++n)
      ref.push_back(mechbal::bench::actuated(closed, *model, mechbal::test::platform_at(n * 1e-3),
                                             mechbal::test::wrist_at(n * 1e-3)));
    const auto na = static_cast<Eigen::Index>(model->num_actuated());
    q = qd = v = tau = Eigen::VectorXd::Zero(na);
  }
  mechbal::Status tick(double t) noexcept {
    const long k = std::lround(t * 1e3) % (2 * kInstants - 2);
    const auto& r = ref[static_cast<std::size_t>(k < kInstants ? k : 2 * kInstants - 2 - k)];
    q = r.q.array() + 1e-5 * std::sin(50.0 * t);
    qd = r.v.array() - 1e-4 * std::cos(50.0 * t);
    v = r.a + kp * (r.q - q) + kd * (r.v - qd);
    return dynamics.inverse_dynamics(q, qd, v, tau, &force, &moment);
  }
  static constexpr double kp = 100.0, kd = 20.0;
  mechbal::PaminsaModel closed;
  std::shared_ptr<const mechbal::MechanismModel> model;
  mechbal::MechanismDynamics dynamics;
  std::vector<mechbal::bench::ActuatedState> ref;
  Eigen::VectorXd q, qd, v, tau;
  mechbal::Vec3 force, moment;
};

/// The general reactionless tick (RK4) on PAMINSA's general model, the wrist balancing the moment;
/// the platform's task motion precomputed at t, t + dt/2, t + dt for 1024 ticks, cycled back and forth.
struct ReactionlessGeneralWorkload {
  static constexpr const char* name = "reactionless_general";
  static constexpr const char* description =
      "reactionless_general: ReactionlessController (RK4) on PAMINSA's general model, wrist "
      "balancing the moment (loops, balancing columns and task momentum, rate solve x4, feed-forward, predicted wrench)";
  // the motion is 2 pi periodic: kInstants samples over one period (t_n = n 2 pi / kInstants, about
  // 1 ms apart), cycled forwards, so that each tick starts where the last one's RK4 stage ended
  static constexpr int kInstants = 6284;
  static constexpr double kDt = 2.0 * M_PI / kInstants;
  struct Sample {
    Eigen::VectorXd q, v, a, qh, vh, qn, vn;
  };
  ReactionlessGeneralWorkload() {
    const mechbal::PaminsaModel closed{mechbal::PaminsaParameters{}};
    const auto model = std::make_shared<const mechbal::MechanismModel>(mechbal::bench::paminsa_description(closed));
    mechbal::WristMotion w0;
    w0.angles = mechbal::Vec3(M_PI / 2, M_PI / 2, M_PI / 2);
    const mechbal::PlatformMotion p0 = mechbal::test::platform_at(0.0);
    const auto s0 = mechbal::bench::actuated(closed, *model, p0, w0);
    mechbal::ReactionlessConfig c;
    c.balancing_joints = {"wrist_phi", "wrist_theta", "wrist_psi"};
    c.integrator = mechbal::ReactionlessIntegrator::rk4;
    c.rate_hz = 1.0 / kDt;
    Eigen::VectorXd v0 = s0.v;
    for (int j = 0; j < model->num_actuated(); ++j)
      if (model->coordinate_name(model->actuated_coordinates()[static_cast<std::size_t>(j)]).rfind("wrist_", 0) == 0)
        v0(j) = 0.0;
    ctrl = std::make_unique<mechbal::ReactionlessController>(model, c, s0.q, v0,
                                                             mechbal::bench::initial_guess(closed, *model, p0, w0));
    const auto task = [&](const Eigen::VectorXd& x) {
      Eigen::VectorXd out(ctrl->num_task());
      for (int i = 0; i < ctrl->num_task(); ++i) out(i) = x(ctrl->task_joints()[static_cast<std::size_t>(i)]);
      return out;
    };
    for (int n = 0; n < kInstants; ++n) {
      const auto now = mechbal::bench::actuated(closed, *model, mechbal::test::platform_at(n * kDt), w0);
      const auto half = mechbal::bench::actuated(closed, *model, mechbal::test::platform_at((n + 0.5) * kDt), w0);
      const auto next = mechbal::bench::actuated(closed, *model, mechbal::test::platform_at((n + 1) * kDt), w0);
      in.push_back({task(now.q), task(now.v), task(now.a), task(half.q), task(half.v), task(next.q), task(next.v)});
    }
  }
  mechbal::Status tick(double t) noexcept {
    const long k = std::lround(t * 1e3) % kInstants;  // the tick's index (t = index / 1 kHz)
    const Sample& x = in[static_cast<std::size_t>(k)];
    return ctrl->step(x.q, x.v, x.a, x.qh, x.vh, x.qn, x.vn);
  }
  std::unique_ptr<mechbal::ReactionlessController> ctrl;
  std::vector<Sample> in;
};

/// The machine's CPU time counters of /proc/stat's "cpu" line (USER_HZ ticks): total and steal (the
/// time the hypervisor ran something else while a vCPU wanted to run). {0, 0} when unreadable.
std::pair<double, double> cpu_total_and_steal() {
  std::ifstream in("/proc/stat");
  std::string cpu;
  double v[8] = {0, 0, 0, 0, 0, 0, 0, 0};  // user nice system idle iowait irq softirq steal
  if (!(in >> cpu) || cpu != "cpu") return {0.0, 0.0};
  double total = 0.0;
  for (double& x : v) {
    if (!(in >> x)) return {0.0, 0.0};
    total += x;
  }
  return {total, v[7]};
}

long long thread_cpu_ns() {
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return to_ns(t);
}

}  // namespace

template <class W>
void run_loop(W& work, W& twin, std::size_t ticks, long long period, double rate, double seconds,
              bool fifo, bool locked, long long spin_ns, const std::string& json) {
  // allocated before the loop
  std::vector<long long> compute(ticks), wake(ticks), cpu(ticks), twin_min(ticks);
  // warm caches; the timed ticks continue the same time line (a jump back to t = 0 would restart
  // a loop solve's warm start one second away: one tick of full Newton iterations in both twins,
  // which no controller following its trajectory sees)
  constexpr std::size_t warmup = 1000;
  for (std::size_t i = 0; i < warmup; ++i) {
    work.tick(static_cast<double>(i) / rate);
    twin.tick(static_cast<double>(i) / rate);
  }
  std::size_t twin_mismatch = 0;  // periods whose two copies returned different statuses

  std::size_t misses = 0, overruns = 0, bad_status = 0;
  const auto stat_start = cpu_total_and_steal();
  long long release = now_ns() + period;
  for (std::size_t k = 0; k < ticks; ++k) {
    if (spin_ns > 0) {  // sleep to spin_ns before the release, then poll the clock
      const timespec ts = from_ns(release - spin_ns);
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
      while (now_ns() < release) {
      }
    } else {
      const timespec ts = from_ns(release);
      while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
      }
    }
    wake[k] = now_ns() - release;
    const double t = static_cast<double>(warmup + k) / rate;
    long long twin_ns = 0;
    mechbal::Status twin_status = mechbal::Status::ok;
    if (k % 2 == 1) {  // odd periods: the twin first
      const long long t0 = now_ns();
      twin_status = twin.tick(t);
      twin_ns = now_ns() - t0;
    }
    const long long cpu_start = thread_cpu_ns();
    const long long start = now_ns();
    const mechbal::Status s = work.tick(t);
    const long long end = now_ns();
    cpu[k] = thread_cpu_ns() - cpu_start;
    if (k % 2 == 0) {  // even periods: the twin second
      const long long t0 = now_ns();
      twin_status = twin.tick(t);
      twin_ns = now_ns() - t0;
    }
    if (twin_status != s) ++twin_mismatch;
    twin_min[k] = std::min(end - start, twin_ns);
    if (s != mechbal::Status::ok) ++bad_status;
    if (end - start > period) ++overruns;  // the computation alone did not fit in a period
    compute[k] = end - start;
    const long long next = release + period;
    const long long done = now_ns();  // both copies computed
    if (done > next) {
      ++misses;
      // skip the releases already missed, keep the absolute grid
      while (release + period < done) release += period;
    }
    release += period;
  }

  const auto stat_end = cpu_total_and_steal();
  const double stat_total = stat_end.first - stat_start.first;
  const double steal = stat_total > 0.0 ? (stat_end.second - stat_start.second) / stat_total : -1.0;
  // preempted ticks: wall time beyond the thread's CPU time (which also holds the two CPU-clock
  // reads, ~0.5 us) by more than 2 us
  std::vector<long long> unpreempted;
  unpreempted.reserve(ticks);
  std::size_t preempted = 0, overruns_unpreempted = 0;
  for (std::size_t k = 0; k < ticks; ++k) {
    if (compute[k] - cpu[k] > 2000) {
      ++preempted;
    } else {
      unpreempted.push_back(compute[k]);
      if (compute[k] > period) ++overruns_unpreempted;
    }
  }
  const double clean999 = pct(unpreempted, 0.999), cpu999 = pct(cpu, 0.999);
  std::size_t twin_overruns = 0;
  for (const long long x : twin_min) twin_overruns += x > period ? 1 : 0;
  const double tw50 = pct(twin_min, 0.5), tw999 = pct(twin_min, 0.999);
  const double twmax = static_cast<double>(*std::max_element(twin_min.begin(), twin_min.end()));
  const double p50 = pct(compute, 0.5), p99 = pct(compute, 0.99), p999 = pct(compute, 0.999);
  const double mx = static_cast<double>(*std::max_element(compute.begin(), compute.end()));
  const double w50 = pct(wake, 0.5), w99 = pct(wake, 0.99), w999 = pct(wake, 0.999);
  const double wmax = static_cast<double>(*std::max_element(wake.begin(), wake.end()));
  std::printf("mechbal-loop: %zu ticks at %.0f Hz (%.1f s), workload %s\n", ticks, rate, seconds,
              W::description);
  std::printf("  SCHED_FIFO %s, mlockall %s\n", fifo ? "on" : "off", locked ? "on" : "off");
  std::printf("  tick time   p50 %8.0f ns  p99 %8.0f ns  p99.9 %8.0f ns  max %8.0f ns\n", p50, p99,
              p999, mx);
  std::printf("  wake-up lat p50 %8.0f ns  p99 %8.0f ns  p99.9 %8.0f ns  max %8.0f ns\n", w50, w99,
              w999, wmax);
  std::printf("  deadline misses %zu / %zu (ticks ending after the next release; of which the "
              "computation alone exceeded the period: %zu), non-ok status %zu\n",
              misses, ticks, overruns, bad_status);
  std::printf("  preempted ticks (wall - thread CPU > 2 us) %zu; without them p99.9 %8.0f ns, overruns %zu; "
              "thread CPU time p99.9 %8.0f ns\n", preempted, clean999, overruns_unpreempted, cpu999);
  std::printf("  machine during the run: %.1f %% of its CPU time stolen by the hypervisor (/proc/stat steal)\n",
              100.0 * steal);
  std::printf("  twin ticks min(A, B): p50 %8.0f ns  p99.9 %8.0f ns  max %8.0f ns; compute overruns %zu; "
              "status mismatches %zu\n", tw50, tw999, twmax, twin_overruns, twin_mismatch);
  if (!json.empty()) {
    std::ofstream out(json);
    out << "{\"workload\": \"" << W::description << "\", "
        << "\"rate_hz\": " << rate << ", \"seconds\": " << seconds << ", \"ticks\": " << ticks
        << ", \"sched_fifo\": " << (fifo ? "true" : "false")
        << ", \"mlockall\": " << (locked ? "true" : "false") << ", \"p50_ns\": " << p50
        << ", \"p99_ns\": " << p99 << ", \"p999_ns\": " << p999 << ", \"max_ns\": " << mx
        << ", \"wakeup_p50_ns\": " << w50 << ", \"wakeup_p99_ns\": " << w99
        << ", \"wakeup_p999_ns\": " << w999 << ", \"wakeup_max_ns\": " << wmax
        << ", \"deadline_misses\": " << misses << ", \"compute_overruns\": " << overruns << ", \"non_ok_status\": " << bad_status
        << ", \"preempted_ticks\": " << preempted << ", \"p999_unpreempted_ns\": " << clean999
        << ", \"compute_overruns_unpreempted\": " << overruns_unpreempted << ", \"cpu_p999_ns\": " << cpu999 << ", \"steal_fraction\": " << steal
        << ", \"twin_p50_ns\": " << tw50 << ", \"twin_p999_ns\": " << tw999 << ", \"twin_max_ns\": " << twmax
        << ", \"twin_compute_overruns\": " << twin_overruns << ", \"twin_status_mismatches\": " << twin_mismatch << "}\n";
  }
}

int main(int argc, char** argv) {
  double seconds = 5.0, rate = 1000.0, spin_us = 0.0;
  bool rt = false;
  std::string json, workload = "ct6";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--seconds" && i + 1 < argc) {
      seconds = std::atof(argv[++i]);
    } else if (a == "--rate" && i + 1 < argc) {
      rate = std::atof(argv[++i]);
    } else if (a == "--rt") {
      rt = true;
    } else if (a == "--workload" && i + 1 < argc) {
      workload = argv[++i];
    } else if (a == "--spin-us" && i + 1 < argc) {
      spin_us = std::atof(argv[++i]);
    } else if (a == "--json" && i + 1 < argc) {
      json = argv[++i];
    } else if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else {
      std::fprintf(stderr, "mechbal-loop: unknown option '%s'\n", a.c_str());
      usage();
      return 2;
    }
  }
  if (!(seconds > 0.0) || !(rate > 0.0) || rate > 100000.0) {
    std::fprintf(stderr, "mechbal-loop: --seconds must be > 0 and --rate in (0, 100000], got %g, %g\n",
                 seconds, rate);
    return 2;
  }
  if (workload != "ct6" && workload != "paminsa" && workload != "paminsa_general" && workload != "reactionless_general") {
    std::fprintf(stderr, "mechbal-loop: --workload must be ct6, paminsa, paminsa_general or reactionless_general, got '%s'\n",
                 workload.c_str());
    return 2;
  }
  const long long period = static_cast<long long>(std::llround(1e9 / rate));
  if (!(spin_us >= 0.0) || spin_us * 1e3 > static_cast<double>(period)) {
    std::fprintf(stderr, "mechbal-loop: --spin-us must be in [0, period], got %g\n", spin_us);
    return 2;
  }
  const auto spin_ns = static_cast<long long>(std::llround(spin_us * 1e3));
  const auto ticks = static_cast<std::size_t>(std::llround(seconds * rate));

  bool fifo = false, locked = false;
  if (rt) {
    sched_param sp{};
    sp.sched_priority = 80;
    if (sched_setscheduler(0, SCHED_FIFO, &sp) == 0) {
      fifo = true;
    } else {
      std::fprintf(stderr,
                   "mechbal-loop: SCHED_FIFO not permitted (%s): running with the default "
                   "scheduler (needs CAP_SYS_NICE or an RLIMIT_RTPRIO >= 80)\n",
                   std::strerror(errno));
    }
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      locked = true;
    } else {
      std::fprintf(stderr,
                   "mechbal-loop: mlockall not permitted (%s): memory may page (needs "
                   "CAP_IPC_LOCK or a large enough RLIMIT_MEMLOCK)\n",
                   std::strerror(errno));
    }
  }

  if (workload == "paminsa_general") {
    PaminsaGeneralWorkload work, twin;
    run_loop(work, twin, ticks, period, rate, seconds, fifo, locked, spin_ns, json);
  } else if (workload == "reactionless_general") {
    ReactionlessGeneralWorkload work, twin;
    run_loop(work, twin, ticks, period, rate, seconds, fifo, locked, spin_ns, json);
  } else if (workload == "paminsa") {
    PaminsaWorkload work(rate), twin(rate);
    run_loop(work, twin, ticks, period, rate, seconds, fifo, locked, spin_ns, json);
  } else {
    ComputedTorqueWorkload work, twin;
    run_loop(work, twin, ticks, period, rate, seconds, fifo, locked, spin_ns, json);
  }
  return 0;
}
