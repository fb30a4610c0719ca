#pragma once
// The rig model: named sensors, each with its pose in the base frame (the LiDAR) and its clock
// offset. This is what the calibration YAML holds (doc/calibration-yaml.md); calib/rig/rig_yaml.h
// reads and writes it, calib/rig/export.h turns it into other tools' files.
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rigcal/core/se3.h"
#include "rigcal/core/time.h"

namespace rigcal::rig {

enum class SensorType { camera, lidar, imu, gnss };
enum class DistortionModel {
  radtan,       // OpenCV's plumb_bob: k1 k2 p1 p2 [k3]
  equidistant,  // Kannala-Brandt as in OpenCV's fisheye module and Kalibr: k1 k2 k3 k4
};

std::string_view to_string(SensorType type);
std::string_view to_string(DistortionModel model);
// Throw rigcal::Error listing the accepted names.
SensorType sensor_type_from_string(std::string_view name);
DistortionModel distortion_model_from_string(std::string_view name);
// Coefficient counts a model accepts: radtan 4 or 5, equidistant 4.
bool valid_coefficient_count(DistortionModel model, size_t count);

// A pinhole camera with lens distortion. Pixel coordinates: (0, 0) is the centre of the top-left
// pixel, as in OpenCV and Kalibr.
struct CameraModel {
  double fx = 0, fy = 0, cx = 0, cy = 0;  // px
  DistortionModel distortion_model = DistortionModel::radtan;
  std::vector<double> distortion_coeffs;
  int width = 0, height = 0;  // px

  Eigen::Matrix3d K() const;
};

// Continuous-time IMU noise (Kalibr's definitions); unset means unknown.
struct ImuSpec {
  std::optional<double> gyroscope_noise_density;      // rad/s/sqrt(Hz)
  std::optional<double> gyroscope_random_walk;        // rad/s^2/sqrt(Hz)
  std::optional<double> accelerometer_noise_density;  // m/s^2/sqrt(Hz)
  std::optional<double> accelerometer_random_walk;    // m/s^3/sqrt(Hz)
};

struct Sensor {
  std::string name;
  SensorType type = SensorType::lidar;
  // The YAML's T_b: this sensor's pose in the base frame, p_base = T_base_sensor * p_sensor.
  SE3 T_base_sensor;
  // Seconds added to this sensor's stamps to put them on the base clock.
  double time_offset = 0.0;
  // Clock drift, where measured: t_base = t + time_offset + time_drift_ppm * 1e-6 * (t - epoch),
  // t and epoch on this sensor's clock.
  std::optional<double> time_drift_ppm;
  Time time_drift_epoch;
  std::optional<double> update_rate;  // Hz, where known
  std::string model;                  // free text: "OS0-128", "Ellipse-E" ...

  CameraModel camera;              // type == camera only
  ImuSpec imu;                     // type == imu only
  std::string gnss_frame = "ins";  // type == gnss only: "ins" or "antenna"
  // The sensor this one is rigidly mounted with ("" for none): an estimate that moves that one
  // moves this one too (the INS's own IMU is attached to the GNSS/INS).
  std::string attached_to;

  // Keys rigcal does not know, kept as YAML flow text and written back unchanged.
  std::vector<std::pair<std::string, std::string>> extra_keys;
};

struct Rig {
  std::vector<Sensor> sensors;
  std::string base_frame = "lidar";  // the sensor whose frame is the base (identity T_b)
  // What a reader assumed or noticed (e.g. "cam_l: no distortion_model; radtan assumed").
  std::vector<std::string> notes;
  // Keys under `rigcal:` that this version does not interpret (step summaries, provenance).
  std::vector<std::pair<std::string, std::string>> extra_metadata;
};

// The sensor with that name, or nullptr.
const Sensor* find_sensor(const Rig& rig, std::string_view name);
// A stamp of this sensor's clock on the base clock: its time_offset, and its drift where the rig
// has one (Sensor::time_drift_ppm).
Time on_base_clock(const Sensor& sensor, Time t_sensor);
Sensor* find_sensor(Rig& rig, std::string_view name);
// The sensor with that name; throws rigcal::Error listing the sensors there are.
const Sensor& sensor(const Rig& rig, std::string_view name);
Sensor& sensor(Rig& rig, std::string_view name);
// The cameras in file order.
std::vector<const Sensor*> cameras(const Rig& rig);

// T_a_b between two sensors: maps points of sensor b's frame into sensor a's frame,
// T_a_b = inv(a.T_b) * b.T_b. Example: T_a_b(rig, "cam_l", "lidar") is T_cam_l_lidar.
SE3 T_a_b(const Rig& rig, std::string_view a, std::string_view b);

// Places `sensor` at T_base_sensor and moves every sensor attached to it (attached_to, followed
// transitively) with it, keeping their poses relative to it. Returns the names moved, `sensor`
// first.
std::vector<std::string> move_rigidly(Rig& rig, std::string_view sensor, const SE3& T_base_sensor);

// Sets `sensor`'s clock from a measurement against another clock,
//     t_reference = t_sensor + offset_s + drift_ppm * 1e-6 * (t_sensor - epoch),
// where the reference is sensor `reference` (its own time_offset and drift composed in, to first
// order in the drifts) or, when `reference` is empty, the base clock. The drift keys are set where
// the composed drift is not zero and removed where it is.
void set_clock_from(Rig& rig, std::string_view sensor, std::string_view reference, double offset_s,
                    double drift_ppm = 0.0, Time epoch = {});

// Checks the rig as a whole (also run by the YAML writer). Throws rigcal::Error with the first
// problem, naming sensor and key: duplicate names, bad intrinsics, non-rotations, unknown base.
void validate(const Rig& rig);

// Physical ranges validate() holds a rig to: beyond them a number is a mistake, and the exports
// would carry Inf and NaN (fx 1e308, a translation of 1e308 m).
inline constexpr double kMaxTranslationM = 1e3;  // a rig's sensors lie within metres
inline constexpr double kMaxTimeOffsetS = 1e9;   // GPS against UNIX time is 3.2e8 s
inline constexpr double kMaxPixels = 1e6;        // focal lengths and principal point, px
inline constexpr double kMaxDistortion = 1e3;    // each distortion coefficient
inline constexpr int kMaxImageSide = 100000;     // px
inline constexpr double kMaxRateHz = 1e6;
inline constexpr double kMaxNoise = 1e3;  // IMU noise densities and random walks

// Tolerance of the rotation check: max |R^T R - I| <= 1e-5 passes (a matrix printed with six
// decimals is within it), and det R must be positive.
inline constexpr double kRotationTolerance = 1e-5;

}  // namespace rigcal::rig
