#pragma once
// Rigs for tests: random ones that exercise every field, with full-precision doubles.
#include <random>

#include "rigcal/rig/rig.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::rig::testing {

// The bundled sample rig (data/sample_rig.yaml): two cameras, the LiDAR, two IMUs, a GNSS/INS.
inline Rig sample_rig() { return read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml"); }

inline double any_double(std::mt19937_64& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

inline SE3 random_pose(std::mt19937_64& rng) {
  const Eigen::Vector3d phi(any_double(rng, -2, 2), any_double(rng, -2, 2), any_double(rng, -2, 2));
  const Eigen::Vector3d t(any_double(rng, -1, 1), any_double(rng, -1, 1), any_double(rng, -1, 1));
  return SE3::from_rotation_vector(phi, t);
}

inline Sensor random_camera(std::mt19937_64& rng, const std::string& name, DistortionModel model) {
  Sensor s;
  s.name = name;
  s.type = SensorType::camera;
  s.T_base_sensor = random_pose(rng);
  s.time_offset = any_double(rng, -0.01, 0.01);
  s.camera.fx = any_double(rng, 300, 2000);
  s.camera.fy = s.camera.fx * any_double(rng, 0.99, 1.01);
  s.camera.width = 1388;
  s.camera.height = 700;
  s.camera.cx = any_double(rng, 600, 780);
  s.camera.cy = any_double(rng, 300, 400);
  s.camera.distortion_model = model;
  const size_t n = model == DistortionModel::radtan && rng() % 2 ? 5 : 4;
  for (size_t k = 0; k < n; ++k)
    s.camera.distortion_coeffs.push_back(
        any_double(rng, -0.3, 0.3) * (k < 2 || model == DistortionModel::equidistant ? 1 : 0.01));
  return s;
}

inline Rig random_rig(std::mt19937_64& rng) {
  Rig rig;
  const DistortionModel model = rng() % 2 ? DistortionModel::radtan : DistortionModel::equidistant;
  rig.sensors.push_back(random_camera(rng, "cam_l", model));
  rig.sensors.push_back(random_camera(rng, "cam_r", model));
  Sensor lidar;
  lidar.name = "lidar";
  lidar.type = SensorType::lidar;
  lidar.model = "OS0-128";
  lidar.update_rate = 10.0;
  rig.sensors.push_back(lidar);
  Sensor imu;
  imu.name = "imu";
  imu.type = SensorType::imu;
  imu.T_base_sensor = random_pose(rng);
  imu.time_offset = any_double(rng, -0.1, 0.1);
  imu.update_rate = 100.0;
  imu.imu.gyroscope_noise_density = any_double(rng, 1e-5, 1e-3);
  imu.imu.accelerometer_random_walk = any_double(rng, 1e-6, 1e-3);
  if (rng() % 2) imu.imu.gyroscope_random_walk = any_double(rng, 1e-7, 1e-4);
  if (rng() % 2) imu.imu.accelerometer_noise_density = any_double(rng, 1e-4, 1e-2);
  rig.sensors.push_back(imu);
  Sensor gnss;
  gnss.name = "gnss";
  gnss.type = SensorType::gnss;
  gnss.gnss_frame = rng() % 2 ? "ins" : "antenna";
  gnss.T_base_sensor = random_pose(rng);
  gnss.extra_keys.emplace_back("antenna_lever_arm", "[0.1, 0.2, 0.3]");
  rig.sensors.push_back(gnss);
  if (rng() % 2) rig.notes.push_back("a note: with \"quotes\" and a colon");
  return rig;
}

}  // namespace rigcal::rig::testing

namespace rigcal {
// The bundled sample rig (the simulator's truth) and the prior a session starts from.
inline const std::string kTruth = RIGCAL_SOURCE_DIR "/data/sample_rig.yaml";
inline const std::string kPrior = RIGCAL_SOURCE_DIR "/data/sample_prior_rig.yaml";
}  // namespace rigcal
