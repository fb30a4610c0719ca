#include "rigcal/sim/motion.h"

#include <cmath>

namespace rigcal::sim {
namespace {

// value, first and second derivative of a sum of sinusoids
Eigen::Vector3d sum(const std::vector<Sinusoid>& s, double t) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (const Sinusoid& k : s) {
    const double a = k.omega * t + k.phase;
    out += Eigen::Vector3d(k.amplitude * std::sin(a), k.amplitude * k.omega * std::cos(a),
                           -k.amplitude * k.omega * k.omega * std::sin(a));
  }
  return out;
}

// Integral of a sum of sinusoids from 0 to t.
double integral(const std::vector<Sinusoid>& s, double t) {
  double out = 0.0;
  for (const Sinusoid& k : s) {
    out += k.amplitude / k.omega * (std::cos(k.phase) - std::cos(k.omega * t + k.phase));
  }
  return out;
}

std::vector<Sinusoid> random_sum(std::mt19937_64& rng, int n, double amplitude, double w_min,
                                 double w_max) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Sinusoid> out;
  for (int i = 0; i < n; ++i) {
    out.push_back({amplitude * (0.5 + 0.5 * u(rng)) / n * 2.0, w_min + (w_max - w_min) * u(rng),
                   2 * M_PI * u(rng)});
  }
  return out;
}

}  // namespace

Motion random_motion(MotionKind kind, double duration, std::mt19937_64& rng) {
  Motion m;
  m.kind = kind;
  if (kind == MotionKind::handheld) {
    m.speed = 1.3;
    m.x = random_sum(rng, 3, 0.15, 0.5, 4.0);
    m.y = random_sum(rng, 3, 0.15, 0.5, 4.0);
    m.z = random_sum(rng, 3, 0.10, 1.0, 12.0);  // step bobbing
    m.roll = random_sum(rng, 4, 0.40, 0.3, 6.0);
    m.pitch = random_sum(rng, 4, 0.40, 0.3, 6.0);
    m.yaw_rate = random_sum(rng, 4, 0.8, 0.05, 3.0);
  } else if (kind == MotionKind::walk) {
    m.speed = 1.3;
    m.x = random_sum(rng, 2, 0.05, 0.5, 3.0);
    m.y = random_sum(rng, 2, 0.05, 0.5, 3.0);
    m.z = random_sum(rng, 2, 0.02, 10.0, 12.0);  // the step's bob, ~1.7 Hz
    m.roll = random_sum(rng, 3, 0.12, 0.3, 3.0);
    m.pitch = random_sum(rng, 3, 0.12, 0.3, 3.0);
    m.yaw_rate = random_sum(rng, 3, 0.4, 0.05, 1.0);
  } else {
    m.speed = 8.0;
    m.x = random_sum(rng, 2, 0.05, 0.2, 1.0);
    m.y = random_sum(rng, 2, 0.05, 0.2, 1.0);
    m.z = random_sum(rng, 2, 0.03, 0.05, 0.5);
    m.roll = random_sum(rng, 2, 0.008, 0.2, 1.5);
    m.pitch = random_sum(rng, 2, 0.008, 0.2, 1.5);
    m.yaw_rate = random_sum(rng, 3, 0.12, 0.02, 0.15);
  }
  prepare(m, duration);
  return m;
}

constexpr double kStep = 0.01;  // s, travel table

void prepare(Motion& m, double duration) {
  const size_t n = static_cast<size_t>(std::ceil(std::max(duration, 0.0) / kStep)) + 2;
  m.travel.assign(n, Eigen::Vector2d::Zero());
  auto heading = [&](double t) -> Eigen::Vector2d {
    const double a = integral(m.yaw_rate, t);
    return Eigen::Vector2d(std::cos(a), std::sin(a));
  };
  for (size_t i = 1; i < n; ++i) {  // Simpson on each step
    const double t0 = (i - 1) * kStep;
    m.travel[i] =
        m.travel[i - 1] + m.speed * kStep / 6.0 *
                              (heading(t0) + 4.0 * heading(t0 + 0.5 * kStep) + heading(t0 + kStep));
  }
}

MotionState evaluate(const Motion& m, double t) {
  const Eigen::Vector3d roll = sum(m.roll, t), pitch = sum(m.pitch, t), yr = sum(m.yaw_rate, t);
  const double phi = roll[0], theta = pitch[0], psi = integral(m.yaw_rate, t);
  const double dphi = roll[1], dtheta = pitch[1], dpsi = yr[0];
  const double ddphi = roll[2], ddtheta = pitch[2], ddpsi = yr[1];

  MotionState s;
  s.T_world_base.R = from_roll_pitch_yaw(phi, theta, psi);
  // Body rates of R = Rz(psi) Ry(theta) Rx(phi) and their time derivative.
  const double sf = std::sin(phi), cf = std::cos(phi), st = std::sin(theta), ct = std::cos(theta);
  s.omega_base = Eigen::Vector3d(dphi - dpsi * st, dtheta * cf + dpsi * ct * sf,
                                 -dtheta * sf + dpsi * ct * cf);
  s.alpha_base = Eigen::Vector3d(ddphi - ddpsi * st - dpsi * ct * dtheta,
                                 ddtheta * cf - dtheta * sf * dphi + ddpsi * ct * sf -
                                     dpsi * st * dtheta * sf + dpsi * ct * cf * dphi,
                                 -ddtheta * sf - dtheta * cf * dphi + ddpsi * ct * cf -
                                     dpsi * st * dtheta * cf - dpsi * ct * sf * dphi);
  // Travel: cubic Hermite between table nodes, with the exact derivative speed * heading.
  const double u = std::clamp(t / kStep, 0.0, static_cast<double>(m.travel.size() - 2));
  const size_t i = static_cast<size_t>(u);
  const double f = u - i;
  auto heading = [&](double time) -> Eigen::Vector2d {
    const double a = integral(m.yaw_rate, time);
    return Eigen::Vector2d(std::cos(a), std::sin(a)) * m.speed * kStep;
  };
  const Eigen::Vector2d p0 = m.travel[i], p1 = m.travel[i + 1];
  const Eigen::Vector2d d0 = heading(i * kStep), d1 = heading((i + 1) * kStep);
  const double f2 = f * f, f3 = f2 * f;
  const Eigen::Vector2d travel = (2 * f3 - 3 * f2 + 1) * p0 + (f3 - 2 * f2 + f) * d0 +
                                 (-2 * f3 + 3 * f2) * p1 + (f3 - f2) * d1;
  const double px = travel.x(), py = travel.y();
  const Eigen::Vector3d x = sum(m.x, t), y = sum(m.y, t), z = sum(m.z, t);
  s.T_world_base.t = Eigen::Vector3d(px + x[0], py + y[0], z[0]);
  s.v_world = Eigen::Vector3d(m.speed * std::cos(psi) + x[1], m.speed * std::sin(psi) + y[1], z[1]);
  s.a_world = Eigen::Vector3d(-m.speed * std::sin(psi) * dpsi + x[2],
                              m.speed * std::cos(psi) * dpsi + y[2], z[2]);
  return s;
}

}  // namespace rigcal::sim
