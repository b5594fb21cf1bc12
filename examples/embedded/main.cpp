// mechbal_embedded: the controller side of the handoff. Loads a balanced design (a case file or the
// balanced.toml of `mechbal balance`) and its [control] table, builds the configured controller
// (make_controller) and runs it in a periodic loop at the table's rate: SCHED_FIFO and mlockall
// where permitted, plain absolute-time sleeps otherwise. Each tick tracks the case's [trajectory]
// (rest to rest in the actuated joints) and predicts the shaking wrench the motion puts on the base.
// With kind = "reactionless" the balancing joints' motion is the controller's own (their [trajectory]
// entries are ignored), the commanded motion is tracked by its computed-torque stage, and the
// predicted wrench is that of the reactionless command: the cancelled components stay ~0. Prints the
// tick statistics and the peak shaking wrench (for reactionless, also the peak of the cancelled
// components against the same motion with the balancing joints held); --trace writes every tick's
// torques and wrench (for comparing builds, e.g. the aarch64 cross-build under qemu with the native
// one).
//
//   mechbal_embedded CASE.toml [CONTROL.toml] [--ticks N] [--no-sleep] [--trace FILE]
//
// Everything that can fail for bad input fails before the loop (mechbal::ConfigError naming the
// field); inside the loop only Status values.
#include <mechbal/mechbal.hpp>

#include <sched.h>
#include <sys/mman.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <memory>
#include <string>
#include <vector>

namespace {

struct Options {
  std::string case_path, control_path, trace_path;
  long ticks = -1;  // default: the trajectory's duration (at least 1 s without one)
  bool sleep = true;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--ticks" && i + 1 < argc) {
      o.ticks = std::strtol(argv[++i], nullptr, 10);
    } else if (a == "--trace" && i + 1 < argc) {
      o.trace_path = argv[++i];
    } else if (a == "--no-sleep") {
      o.sleep = false;
    } else if (!a.empty() && a[0] == '-') {
      throw std::invalid_argument("unknown option " + a);
    } else if (o.case_path.empty()) {
      o.case_path = a;
    } else if (o.control_path.empty()) {
      o.control_path = a;
    } else {
      throw std::invalid_argument("too many arguments: " + a);
    }
  }
  if (o.case_path.empty()) {
    throw std::invalid_argument("usage: mechbal_embedded CASE.toml [CONTROL.toml] [--ticks N] [--no-sleep] [--trace FILE]");
  }
  return o;
}

double seconds(const timespec& t) { return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec); }

void add_ns(timespec& t, long ns) {
  t.tv_nsec += ns;
  while (t.tv_nsec >= 1000000000L) {
    t.tv_nsec -= 1000000000L;
    ++t.tv_sec;
  }
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto k = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(k, v.size() - 1)];
}

}  // namespace

int main(int argc, char** argv) {
  using namespace mechbal;
  // ---- load time: everything that can throw ----
  Options opt;
  std::unique_ptr<LoadedCase> loaded;
  std::unique_ptr<JointController> controller;
  try {
    opt = parse(argc, argv);
    loaded = std::make_unique<LoadedCase>(load_case(opt.case_path));
    if (!opt.control_path.empty()) loaded->control = load_control(opt.control_path, loaded->model);
    const auto& guess = loaded->trajectory.initial_guess;  // the assembly mode of a closed mechanism
    const auto& start = loaded->trajectory.start;  // a reactionless controller starts there
    controller = make_controller(loaded->model, loaded->control,
                                 Eigen::Map<const Eigen::VectorXd>(guess.data(), static_cast<Eigen::Index>(guess.size())),
                                 Eigen::Map<const Eigen::VectorXd>(start.data(), static_cast<Eigen::Index>(start.size())));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mechbal_embedded: %s\n", e.what());
    return 2;
  }
  const LoadedCase& c = *loaded;
  const MechanismModel& model = c.model;
  const int na = model.num_actuated(), n = model.dof();
  const double rate = c.control.rate_hz;
  const long period_ns = std::lround(1e9 / rate);

  Eigen::VectorXd start = Eigen::VectorXd::Zero(na), end = Eigen::VectorXd::Zero(na);
  double duration = 1.0;
  TimeLaw law = TimeLaw::quintic;
  if (c.trajectory.present) {
    start = Eigen::Map<const Eigen::VectorXd>(c.trajectory.start.data(), na);
    end = Eigen::Map<const Eigen::VectorXd>(c.trajectory.end.data(), na);
    duration = c.trajectory.duration;
    law = c.trajectory.law;
  }
  // kind reactionless: make_controller built a ReactionlessJointController (control/factory.hpp);
  // the balancing joints are held at their start in the desired motion (the controller moves them)
  const ReactionlessJointController* reactionless = nullptr;
  std::vector<int> cancelled;
  if (c.control.kind == ControlKind::reactionless) {
    reactionless = static_cast<const ReactionlessJointController*>(controller.get());
    for (int b : reactionless->reactionless().balancing_joints()) end[b] = start[b];
    cancelled = reactionless->reactionless().cancelled_rows();
  }
  const RestToRestTrajectory trajectory(start, end, duration, law);
  Eigen::VectorXd q_full = Eigen::VectorXd::Zero(n);  // the full coordinates (loops: warm start)
  if (!c.trajectory.initial_guess.empty()) q_full = Eigen::Map<const Eigen::VectorXd>(c.trajectory.initial_guess.data(), n);
  const long ticks = opt.ticks > 0 ? opt.ticks : std::max(1L, std::lround(duration * rate));

  // every buffer the loop uses, allocated now
  MechanismData data(model);
  Eigen::VectorXd q_des(na), v_des(na), a_des(na), q(na), v(na), tau(na), v_full(n), a_full(n);
  std::vector<double> compute_us(static_cast<std::size_t>(ticks)), late_us(static_cast<std::size_t>(ticks));
  std::vector<double> trace;
  if (!opt.trace_path.empty()) trace.reserve(static_cast<std::size_t>(ticks) * static_cast<std::size_t>(na + 6));
  Vec3 peak_force = Vec3::Zero(), peak_moment = Vec3::Zero();
  Vec6 peak_held = Vec6::Zero();  // reactionless: the shaking wrench with the balancing joints held
  long bad_ticks = 0, saturated = 0, singular = 0, misses = 0, first_bad = -1;
  Status first_bad_status = Status::ok;

  // ---- real-time setup where permitted ----
  const bool locked = mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
  sched_param sp{};
  sp.sched_priority = 80;
  const bool fifo = sched_setscheduler(0, SCHED_FIFO, &sp) == 0;
  std::printf("case %s: %d actuated of %d coordinates, %d bodies, %d loops; controller %s at %.0f Hz\n",
              c.name.c_str(), na, n, model.num_bodies(), model.num_loops(), control_kind_name(c.control.kind), rate);
  std::printf("scheduling: %s, memory %s, %s\n", fifo ? "SCHED_FIFO 80" : "default (SCHED_FIFO not permitted)",
              locked ? "locked" : "not locked (mlockall not permitted)", opt.sleep ? "periodic sleep" : "no sleep");

  // ---- the loop: no allocation, no exception ----
  timespec next{}, now{}, done{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  for (long k = 0; k < ticks; ++k) {
    if (opt.sleep) {
      add_ns(next, period_ns);
      clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
    }
    clock_gettime(CLOCK_MONOTONIC, &now);
    const double t = static_cast<double>(k) / rate;
    trajectory.evaluate(t, q_des, v_des, a_des);
    // the "sensors": the commanded motion (the desired one; reactionless: the last command, which
    // moves the balancing joints) with a small, deterministic tracking error
    for (int i = 0; i < na; ++i) {
      const bool commanded = reactionless != nullptr && k > 0;
      q[i] = (commanded ? reactionless->reactionless().command().q[i] : q_des[i]) + 1e-4 * std::sin(7.0 * t + i);
      v[i] = (commanded ? reactionless->reactionless().command().v[i] : v_des[i]) + 1e-3 * std::cos(5.0 * t + i);
    }
    const Status s = controller->step(q, v, q_des, v_des, a_des, tau);
    // the shaking wrench the commanded motion puts on the base
    Status w = Status::ok;
    Vec3 F, M;
    if (reactionless != nullptr) {  // the reactionless command's own prediction
      F = reactionless->reactionless().command().shaking_force;
      M = reactionless->reactionless().command().shaking_moment;
    } else if (model.is_closed()) {
      w = closed_motion(model, data, q_des, v_des, a_des, q_full);
      if (!has(w, Status::solver_error)) {
        w |= shaking_wrench(model, data, data.closed_position, data.closed_velocity, data.closed_acceleration);
      }
    } else {
      w = shaking_wrench(model, data, q_des, v_des, a_des);
    }
    if (reactionless == nullptr) F = data.shaking.force, M = data.shaking.moment;
    clock_gettime(CLOCK_MONOTONIC, &done);
    if (reactionless != nullptr) {  // for comparison (not timed): the desired motion, balancing joints held
      w |= shaking_wrench(model, data, q_des, v_des, a_des);
      peak_held.head<3>() = peak_held.head<3>().cwiseMax(data.shaking.force.cwiseAbs());
      peak_held.tail<3>() = peak_held.tail<3>().cwiseMax(data.shaking.moment.cwiseAbs());
    }
    const double compute = 1e6 * (seconds(done) - seconds(now));
    const double late = opt.sleep ? 1e6 * (seconds(now) - seconds(next)) : 0.0;
    compute_us[static_cast<std::size_t>(k)] = compute;
    late_us[static_cast<std::size_t>(k)] = late;
    if (opt.sleep && compute + late > 1e6 / rate) ++misses;
    if (has(s, Status::bad_size) || has(s, Status::non_finite_input) || has(s, Status::solver_error) ||
        has(w, Status::solver_error)) {
      if (bad_ticks == 0) first_bad = k, first_bad_status = s | w;
      ++bad_ticks;
    }
    saturated += has(s, Status::saturated);
    singular += has(s, Status::singular) || has(w, Status::singular);
    peak_force = peak_force.cwiseMax(F.cwiseAbs());
    peak_moment = peak_moment.cwiseMax(M.cwiseAbs());
    if (!opt.trace_path.empty()) {
      for (int i = 0; i < na; ++i) trace.push_back(tau[i]);
      for (int i = 0; i < 3; ++i) trace.push_back(F[i]);
      for (int i = 0; i < 3; ++i) trace.push_back(M[i]);
    }
  }

  // ---- report ----
  std::printf("ticks %ld: compute median %.1f us, p99 %.1f us, max %.1f us", ticks, percentile(compute_us, 0.5),
              percentile(compute_us, 0.99), percentile(compute_us, 1.0));
  if (opt.sleep) {
    std::printf("; wake-up latency median %.1f us, max %.1f us; deadline misses %ld", percentile(late_us, 0.5),
                percentile(late_us, 1.0), misses);
  }
  std::printf("\nstatus: %ld failed, %ld saturated, %ld near a singularity\n", bad_ticks, saturated, singular);
  if (bad_ticks) std::printf("first failed tick %ld: status %s\n", first_bad, status_name(first_bad_status));
  std::printf("predicted peak shaking force  |F| per axis [N]:   %.6g %.6g %.6g\n", peak_force[0], peak_force[1],
              peak_force[2]);
  std::printf("predicted peak shaking moment |M_O| per axis [N m]: %.6g %.6g %.6g\n", peak_moment[0], peak_moment[1],
              peak_moment[2]);
  if (reactionless != nullptr) {
    // the cancelled components (rows of [dP/dt; dH_O/dt]) under the controller and held
    static const char* row_names[6] = {"force_x", "force_y", "force_z", "moment_x", "moment_y", "moment_z"};
    for (int r : cancelled) {
      const double controlled = r < 3 ? peak_force[r] : peak_moment[r - 3];
      std::printf("cancelled %s: peak %.3g (balancing joints held: %.6g), ratio %.3g\n", row_names[r], controlled,
                  peak_held[r], peak_held[r] > 0.0 ? controlled / peak_held[r] : 0.0);
    }
  }
  std::printf("last torque:");
  for (int i = 0; i < na; ++i) std::printf(" %.6g", tau[i]);
  std::printf("\n");
  if (!opt.trace_path.empty()) {
    std::FILE* f = std::fopen(opt.trace_path.c_str(), "w");
    if (!f) {
      std::fprintf(stderr, "mechbal_embedded: cannot write %s\n", opt.trace_path.c_str());
      return 2;
    }
    const std::size_t cols = static_cast<std::size_t>(na + 6);
    for (std::size_t r = 0; r < trace.size() / cols; ++r) {
      for (std::size_t k = 0; k < cols; ++k) std::fprintf(f, k ? " %.17g" : "%.17g", trace[r * cols + k]);
      std::fprintf(f, "\n");
    }
    std::fclose(f);
  }
  return bad_ticks == 0 ? 0 : 1;
}
