#pragma once
// Smooth, analytic 6-DoF motion of the rig's base frame in a world frame (z up, gravity -z):
// position and roll/pitch/yaw as sums of sinusoids plus a travel term, so that velocity,
// acceleration and angular velocity are exact at any time, for IMU synthesis at any rate.
#include <random>
#include <vector>

#include "rigcal/core/se3.h"

namespace rigcal::sim {

enum class MotionKind {
  handheld,  // the calibration dance: walking at ~1.3 m/s with a turning path, bobbing, rich
             // rotation (+-25 deg roll/pitch, angular rates to ~3 rad/s): excites IMUs and
             // hand-eye, and is harder than a constant-velocity deskew can follow
  car,       // planar driving at ~8 m/s with curves; roll/pitch below 1 deg; z nearly constant
  walk,      // a rig carried while walking at ~1.3 m/s: +-15 deg sway, a 2 cm bob at the step
             // frequency, turns up to ~1 rad/s
};

struct Sinusoid {
  double amplitude = 0, omega = 0, phase = 0;  // a sin(w t + p)
};

struct Motion {
  MotionKind kind = MotionKind::handheld;
  double speed = 1.3;                           // m/s along the heading
  std::vector<Sinusoid> x, y, z;                // position wobble, m
  std::vector<Sinusoid> roll, pitch, yaw_rate;  // rad, rad, rad/s (yaw is integrated analytically)
  // Travel along the heading, tabulated every 10 ms by prepare(): speed * integral (cos, sin)(yaw).
  std::vector<Eigen::Vector2d> travel;
};

// A random motion of the given kind lasting `duration` s (deterministic in rng).
Motion random_motion(MotionKind kind, double duration, std::mt19937_64& rng);
// Tabulates the travel term for times up to `duration` (random_motion calls it).
void prepare(Motion& motion, double duration);

struct MotionState {
  SE3 T_world_base;
  Eigen::Vector3d v_world;     // m/s
  Eigen::Vector3d a_world;     // m/s^2 (without gravity)
  Eigen::Vector3d omega_base;  // angular velocity in the base frame, rad/s
  Eigen::Vector3d alpha_base;  // angular acceleration in the base frame, rad/s^2
};
// The state at time t (s since the start of the motion, 0 <= t <= the prepared duration).
MotionState evaluate(const Motion& motion, double t);

inline const Eigen::Vector3d kGravityWorld(0.0, 0.0, -9.81);

}  // namespace rigcal::sim
