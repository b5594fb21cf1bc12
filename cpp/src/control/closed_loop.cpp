#include "mechbal/control/closed_loop.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace mechbal {

namespace {

// Desired motion at stage time t on the trajectory piece that contains t_piece (see header).
void desired_on_piece(const RestToRestTrajectory& traj, double t, double t_piece,
                      Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> qd,
                      Eigen::Ref<Eigen::VectorXd> qdd) noexcept {
  const double T = traj.duration();
  double te;
  if (t_piece < 0.0)
    te = std::min(t, -std::numeric_limits<double>::min());
  else if (t_piece <= T)
    te = std::clamp(t, 0.0, T);
  else
    te = std::max(t, std::nextafter(T, std::numeric_limits<double>::infinity()));
  traj.evaluate(te, q, qd, qdd);
}

// Inelastic stops (ClosedLoopOptions::lower_limit / upper_limit), the state at the end of a step.
// Buffers allocated once before the loop; apply() allocates nothing.
class Stops {
 public:
  Stops(const ClosedLoopOptions& options, int n, const Eigen::VectorXd& q0) {
    const auto& lo = options.lower_limit;
    const auto& hi = options.upper_limit;
    enabled_ = lo.size() != 0 || hi.size() != 0;
    if (!enabled_) return;
    std::ostringstream msg;
    if (lo.size() != n || hi.size() != n) {
      msg << "closed_loop.lower_limit and upper_limit must have " << n << " values each (got "
          << lo.size() << " and " << hi.size() << ")";
      throw std::invalid_argument(msg.str());
    }
    for (int i = 0; i < n; ++i) {
      if (std::isnan(lo(i)) || std::isnan(hi(i)) || lo(i) > hi(i)) {
        msg << "closed_loop: the stops of coordinate " << i << " must satisfy lower_limit <= "
            << "upper_limit (got [" << lo(i) << ", " << hi(i) << "])";
        throw std::invalid_argument(msg.str());
      }
      if (q0(i) < lo(i) || q0(i) > hi(i)) {
        msg << "closed_loop.q0[" << i << "] = " << q0(i) << " is outside its stops [" << lo(i)
            << ", " << hi(i) << "]";
        throw std::invalid_argument(msg.str());
      }
    }
    if (options.stop_sweeps < 1) throw std::invalid_argument("closed_loop.stop_sweeps must be >= 1");
    lower_ = lo;
    upper_ = hi;
    sweeps_ = options.stop_sweeps;
    W_.setZero(n, n);
    impulse_.setZero(n);
    side_.setZero(n);
    a0_.setZero(n);
    a1_.setZero(n);
    unit_.setZero(n);
  }

  // Puts the coordinates beyond a stop back on it and removes their rates towards it; true when a
  // coordinate is on a stop. A plant that fails here leaves those rates zeroed alone.
  bool apply(ForwardDynamics& plant, Eigen::VectorXd& q, Eigen::VectorXd& qd) noexcept {
    if (!enabled_) return false;
    const Eigen::Index n = q.size();
    bool any = false;
    for (Eigen::Index i = 0; i < n; ++i) {
      side_(i) = 0;
      if (q(i) >= upper_(i)) side_(i) = 1;
      else if (q(i) <= lower_(i)) side_(i) = -1;
      if (side_(i) == 0) continue;
      any = true;
      q(i) = side_(i) > 0 ? upper_(i) : lower_(i);
    }
    if (!any) return false;
    // columns of M^-1 of the coordinates on a stop: a(tau = e_i) - a(tau = 0), exact (linear in tau)
    unit_.setZero();
    bool solved = plant.forward_dynamics(q, qd, unit_, a0_) == Status::ok;
    for (Eigen::Index i = 0; solved && i < n; ++i) {
      if (side_(i) == 0) continue;
      unit_(i) = 1.0;
      solved = plant.forward_dynamics(q, qd, unit_, a1_) == Status::ok;
      unit_(i) = 0.0;
      W_.col(i) = a1_ - a0_;
      if (!(W_(i, i) > 0.0) || !W_.col(i).allFinite()) solved = false;
    }
    if (!solved) {  // no inverse mass matrix: stop the coordinates themselves
      for (Eigen::Index i = 0; i < n; ++i)
        if (side_(i) * qd(i) > 0.0) qd(i) = 0.0;
      return true;
    }
    // projected Gauss-Seidel: impulse p_i pushes away from its stop (side_i p_i <= 0), and after it
    // the rate towards the stop is zero where p_i != 0 (inelastic), never positive
    impulse_.setZero();
    for (int sweep = 0; sweep < sweeps_; ++sweep) {
      double change = 0.0;
      for (Eigen::Index i = 0; i < n; ++i) {
        if (side_(i) == 0) continue;
        double p = impulse_(i) - qd(i) / W_(i, i);
        if (side_(i) * p > 0.0) p = 0.0;
        const double dp = p - impulse_(i);
        if (dp == 0.0) continue;
        qd += W_.col(i) * dp;
        impulse_(i) = p;
        change = std::max(change, std::abs(dp) * std::sqrt(W_(i, i)));
      }
      if (change <= 1e-15 * (1.0 + qd.cwiseAbs().maxCoeff())) break;
    }
    for (Eigen::Index i = 0; i < n; ++i)  // the round-off of the last sweep: where a stop pushed,
      if (impulse_(i) != 0.0 || side_(i) * qd(i) > 0.0) qd(i) = 0.0;  // the rate is exactly zero
    return true;
  }

 private:
  bool enabled_ = false;
  int sweeps_ = 0;
  Eigen::VectorXd lower_, upper_, impulse_, a0_, a1_, unit_;
  Eigen::VectorXi side_;
  Eigen::MatrixXd W_;
};

// The loop shared by both desired-motion kinds: `desired(t, t_piece, q, qd, qdd)` writes the
// desired motion at stage time t (t_piece: the midpoint of the step the stage belongs to).
template <typename Desired>
ClosedLoopLog run_closed_loop(ForwardDynamics& plant, JointController& controller,
                              Desired&& desired_at, Eigen::Index desired_size,
                              const Eigen::VectorXd& q0, const Eigen::VectorXd& qd0,
                              const ClosedLoopOptions& options) {
  const int n = plant.dof();
  std::ostringstream msg;
  if (controller.dof() != n || desired_size != n) {
    msg << "closed_loop: plant has " << n << " joints, controller " << controller.dof()
        << ", trajectory " << desired_size;
    throw std::invalid_argument(msg.str());
  }
  if (q0.size() != n || qd0.size() != n || !q0.allFinite() || !qd0.allFinite()) {
    msg << "closed_loop.initial_state must be " << n << " finite values for q0 and qd0";
    throw std::invalid_argument(msg.str());
  }
  if (!std::isfinite(options.dt) || options.dt <= 0.0) {
    msg << "closed_loop.dt must be finite and > 0 (got " << options.dt << ")";
    throw std::invalid_argument(msg.str());
  }
  if (!std::isfinite(options.duration) || options.duration < options.dt ||
      options.duration / options.dt > 1e8) {
    msg << "closed_loop.duration must be finite, >= dt and <= 1e8 dt (got " << options.duration
        << ")";
    throw std::invalid_argument(msg.str());
  }
  Stops stops(options, n, q0);
  const double dt = options.dt;
  const int steps = static_cast<int>(std::lround(options.duration / dt));
  const bool zoh = options.sampling == ControlSampling::zero_order_hold;

  ClosedLoopLog log;
  log.t.resize(steps + 1);
  log.q.resize(steps + 1, n);
  log.qd.resize(steps + 1, n);
  log.q_des.resize(steps + 1, n);
  log.qd_des.resize(steps + 1, n);
  log.tau.resize(steps + 1, n);
  log.tick_status.setZero(steps + 1);

  using Vec = Eigen::VectorXd;
  Vec q = q0, qd = qd0, qs(n), qds(n), tau(n), hold(n), qdes(n), qddes(n), qdddes(n);
  Vec k1q(n), k1v(n), k2q(n), k2v(n), k3q(n), k3v(n), k4q(n), k4v(n);
  Status status = Status::ok;

  Status tick = Status::ok;  // status of the current tick
  auto control = [&](double t, double t_piece, const Vec& qx, const Vec& qdx, Vec& out) {
    desired_at(t, t_piece, qdes, qddes, qdddes);
    const Status s = controller.step(qx, qdx, qdes, qddes, qdddes, out);
    status |= s;
    tick |= s;
    return s;
  };
  // one stage: derivative of (q, qd) at time t
  auto stage = [&](double t, double t_piece, const Vec& qx, const Vec& qdx, Vec& dq, Vec& dqd) {
    if (!zoh) control(t, t_piece, qx, qdx, tau);
    const Status s = plant.forward_dynamics(qx, qdx, zoh ? hold : tau, dqd);
    dq = qdx;
    return s;
  };

  log.steps_completed = steps;
  bool failed = false;
  for (int k = 0; k <= steps; ++k) {
    const double t = k * dt;
    const double t_piece = t + 0.5 * dt;
    log.t(k) = t;
    log.q.row(k) = q.transpose();
    log.qd.row(k) = qd.transpose();
    tick = Status::ok;
    // record the desired motion and the command at the start of the step
    const Status sc = control(t, t_piece, q, qd, hold);
    if (has(sc, Status::saturated)) ++log.saturated_ticks;
    log.q_des.row(k) = qdes.transpose();
    log.qd_des.row(k) = qddes.transpose();
    log.tau.row(k) = hold.transpose();
    if (k == steps || failed) {
      log.tick_status(k) = static_cast<std::uint32_t>(tick);
      continue;
    }
    Status sp = stage(t, t_piece, q, qd, k1q, k1v);
    qs = q + 0.5 * dt * k1q;
    qds = qd + 0.5 * dt * k1v;
    sp |= stage(t + 0.5 * dt, t_piece, qs, qds, k2q, k2v);
    qs = q + 0.5 * dt * k2q;
    qds = qd + 0.5 * dt * k2v;
    sp |= stage(t + 0.5 * dt, t_piece, qs, qds, k3q, k3v);
    qs = q + dt * k3q;
    qds = qd + dt * k3v;
    sp |= stage(t + dt, t_piece, qs, qds, k4q, k4v);
    status |= sp;
    tick |= sp;
    if (sp != Status::ok) {
      log.tick_status(k) = static_cast<std::uint32_t>(tick);
      failed = true;
      log.steps_completed = k;
      continue;
    }
    qs = q + dt / 6.0 * (k1q + 2.0 * k2q + 2.0 * k3q + k4q);
    qds = qd + dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    if (!qs.allFinite() || !qds.allFinite()) {
      status |= Status::non_finite_input;
      log.tick_status(k) = static_cast<std::uint32_t>(tick | Status::non_finite_input);
      failed = true;
      log.steps_completed = k;
      continue;
    }
    log.tick_status(k) = static_cast<std::uint32_t>(tick);
    if (stops.apply(plant, qs, qds)) ++log.stop_ticks;
    q = qs;
    qd = qds;
  }
  log.status = status;
  return log;
}

}  // namespace

ClosedLoopLog simulate_closed_loop(ForwardDynamics& plant, JointController& controller,
                                   const RestToRestTrajectory& desired, const Eigen::VectorXd& q0,
                                   const Eigen::VectorXd& qd0, const ClosedLoopOptions& options) {
  return run_closed_loop(
      plant, controller,
      [&](double t, double t_piece, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) {
        desired_on_piece(desired, t, t_piece, q, qd, qdd);
      },
      desired.size(), q0, qd0, options);
}

ClosedLoopLog simulate_closed_loop(ForwardDynamics& plant, JointController& controller,
                                   const SampledMotion& desired, const Eigen::VectorXd& q0,
                                   const Eigen::VectorXd& qd0, const ClosedLoopOptions& options) {
  const Eigen::Index n = desired.q.cols();
  const double dt = options.dt;
  const long steps = (std::isfinite(dt) && dt > 0.0 && std::isfinite(options.duration))
                         ? std::lround(options.duration / dt) : 0;
  if (steps > 0 && steps <= 100000000L) {
    const Eigen::Index rows = 2 * static_cast<Eigen::Index>(steps) + 1;
    if (desired.q.rows() != rows || desired.qd.rows() != rows || desired.qdd.rows() != rows ||
        desired.qd.cols() != n || desired.qdd.cols() != n) {
      std::ostringstream msg;
      msg << "closed_loop.desired must have " << rows << " rows (2 steps + 1, one every dt/2) of "
          << n << " values for q, qd and qdd, got " << desired.q.rows() << ", "
          << desired.qd.rows() << " and " << desired.qdd.rows() << " rows";
      throw std::invalid_argument(msg.str());
    }
    if (!desired.q.allFinite() || !desired.qd.allFinite() || !desired.qdd.allFinite())
      throw std::invalid_argument("closed_loop.desired must be finite");
  }  // otherwise run_closed_loop refuses dt / duration, naming them
  const Eigen::Index last = desired.q.rows() - 1;
  return run_closed_loop(
      plant, controller,
      [&, dt, last](double t, double, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) {
        const Eigen::Index j = std::clamp<Eigen::Index>(
            static_cast<Eigen::Index>(std::lround(2.0 * t / dt)), 0, last);
        q = desired.q.row(j).transpose();
        qd = desired.qd.row(j).transpose();
        qdd = desired.qdd.row(j).transpose();
      },
      n, q0, qd0, options);
}

ClosedLoopLog simulate_computed_torque(ForwardDynamics& plant, ComputedTorque& controller,
                                       const RestToRestTrajectory& desired,
                                       const Eigen::VectorXd& q0, const Eigen::VectorXd& qd0,
                                       const ClosedLoopOptions& options) {
  return simulate_closed_loop(plant, controller, desired, q0, qd0, options);
}

double pd_error_analytic(double e0, double ed0, double kp, double kd, double t) noexcept {
  const double disc = kd * kd - 4.0 * kp;
  if (std::abs(disc) <= 1e-12 * kd * kd) {  // critically damped: double root -kd/2
    const double lam = -0.5 * kd;
    return (e0 + (ed0 - lam * e0) * t) * std::exp(lam * t);
  }
  if (disc > 0.0) {
    const double r = std::sqrt(disc);
    const double s1 = 0.5 * (-kd + r), s2 = 0.5 * (-kd - r);
    const double a = (ed0 - s2 * e0) / (s1 - s2);
    return a * std::exp(s1 * t) + (e0 - a) * std::exp(s2 * t);
  }
  const double sig = -0.5 * kd, w = 0.5 * std::sqrt(-disc);
  return std::exp(sig * t) * (e0 * std::cos(w * t) + (ed0 - sig * e0) / w * std::sin(w * t));
}

}  // namespace mechbal
