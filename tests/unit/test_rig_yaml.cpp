// The calibration YAML: bit-identical round trips, VBR-only files, and every validation error
// with the file, line and key it names.
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "rigcal/core/error.h"
#include "rigcal/rig/rig_yaml.h"
#include "test_rigs.h"

namespace rigcal::rig {
namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_identical(const Rig& a, const Rig& b) {
  ASSERT_EQ(a.sensors.size(), b.sensors.size());
  EXPECT_EQ(a.base_frame, b.base_frame);
  EXPECT_EQ(a.notes, b.notes);
  EXPECT_EQ(a.extra_metadata, b.extra_metadata);
  for (size_t i = 0; i < a.sensors.size(); ++i) {
    const Sensor& x = a.sensors[i];
    const Sensor& y = b.sensors[i];
    SCOPED_TRACE(x.name);
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.type, y.type);
    for (int k = 0; k < 16; ++k) {
      EXPECT_TRUE(same_bits(x.T_base_sensor.matrix()(k), y.T_base_sensor.matrix()(k))) << k;
    }
    EXPECT_TRUE(same_bits(x.time_offset, y.time_offset));
    EXPECT_EQ(x.update_rate.has_value(), y.update_rate.has_value());
    if (x.update_rate) {
      EXPECT_TRUE(same_bits(*x.update_rate, *y.update_rate));
    }
    EXPECT_EQ(x.model, y.model);
    EXPECT_EQ(x.extra_keys, y.extra_keys);
    if (x.type == SensorType::camera) {
      const CameraModel& c = x.camera;
      const CameraModel& d = y.camera;
      EXPECT_TRUE(same_bits(c.fx, d.fx) && same_bits(c.fy, d.fy) && same_bits(c.cx, d.cx) &&
                  same_bits(c.cy, d.cy));
      EXPECT_EQ(c.distortion_model, d.distortion_model);
      ASSERT_EQ(c.distortion_coeffs.size(), d.distortion_coeffs.size());
      for (size_t k = 0; k < c.distortion_coeffs.size(); ++k) {
        EXPECT_TRUE(same_bits(c.distortion_coeffs[k], d.distortion_coeffs[k]));
      }
      EXPECT_EQ(c.width, d.width);
      EXPECT_EQ(c.height, d.height);
    }
    if (x.type == SensorType::imu) {
      EXPECT_EQ(x.imu.gyroscope_noise_density, y.imu.gyroscope_noise_density);
      EXPECT_EQ(x.imu.gyroscope_random_walk, y.imu.gyroscope_random_walk);
      EXPECT_EQ(x.imu.accelerometer_noise_density, y.imu.accelerometer_noise_density);
      EXPECT_EQ(x.imu.accelerometer_random_walk, y.imu.accelerometer_random_walk);
    }
    if (x.type == SensorType::gnss) {
      EXPECT_EQ(x.gnss_frame, y.gnss_frame);
    }
  }
}

TEST(RigYaml, WriteReadIsBitIdenticalOnRandomRigs) {
  std::mt19937_64 rng(2024);
  for (int trial = 0; trial < 200; ++trial) {
    const Rig rig = testing::random_rig(rng);
    const std::string text = rig_to_yaml(rig);
    const Rig back = parse_rig_yaml(text, "roundtrip.yaml");
    expect_identical(rig, back);
    EXPECT_EQ(rig_to_yaml(back), text);  // and the text itself is stable
    if (HasFailure()) {
      ADD_FAILURE() << text;
      break;
    }
  }
}

TEST(RigYaml, ReadsTheSampleRig) {
  const Rig rig = read_rig_file(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  ASSERT_EQ(rig.sensors.size(), 6u);
  EXPECT_EQ(rig.base_frame, "lidar");
  EXPECT_TRUE(rig.notes.empty());
  const Sensor& cam_l = sensor(rig, "cam_l");
  EXPECT_EQ(cam_l.type, SensorType::camera);
  EXPECT_EQ(cam_l.camera.width, 1388);
  EXPECT_EQ(cam_l.camera.fx, 1085.3);
  EXPECT_EQ(sensor(rig, "imu").imu.gyroscope_noise_density, 0.00016);
  EXPECT_EQ(sensor(rig, "imu").time_offset, -0.0031);
  EXPECT_EQ(sensor(rig, "gnss").gnss_frame, "ins");
  const SE3 T_camr_caml = T_a_b(rig, "cam_r", "cam_l");
  EXPECT_NEAR(T_camr_caml.t.norm(), 0.4985, 5e-4);  // the ~50 cm baseline
}

// The keys of the published VBR file, nothing of rigcal's.
constexpr const char* kVbrOnly = R"(cam_l:
  intrinsics: [1000.0, 1001.0, 690.0, 350.0]
  distortion_coeffs: [-0.1, 0.05, 0.001, -0.002]
  resolution: [1388, 700]
  T_b: [[0, 0, 1, 0.1], [-1, 0, 0, 0.25], [0, -1, 0, -0.08], [0, 0, 0, 1]]
cam_r:
  intrinsics: [1000.0, 1001.0, 690.0, 350.0]
  distortion_coeffs: [-0.1, 0.05, 0.001, -0.002]
  resolution: [1388, 700]
  T_b: [[0, 0, 1, 0.1], [-1, 0, 0, -0.25], [0, -1, 0, -0.08], [0, 0, 0, 1]]
lidar:
  T_b: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
imu:
  T_b: [[1, 0, 0, 0.01], [0, 1, 0, 0], [0, 0, 1, -0.1], [0, 0, 0, 1]]
  gyroscope_noise_density: 0.0002
  gyroscope_random_walk: 2.0e-05
  accelerometer_noise_density: 0.002
  accelerometer_random_walk: 0.0002
  update_rate: 100
os_imu:
  T_b: [[1, 0, 0, 0.006], [0, 1, 0, -0.012], [0, 0, 1, 0.008], [0, 0, 0, 1]]
)";

TEST(RigYaml, ReadsAVbrOnlyFileAssumingPinholeRadtan) {
  const Rig rig = parse_rig_yaml(kVbrOnly, "vbr_calib.yaml");
  ASSERT_EQ(rig.sensors.size(), 5u);
  EXPECT_EQ(sensor(rig, "cam_l").type, SensorType::camera);
  EXPECT_EQ(sensor(rig, "cam_l").camera.distortion_model, DistortionModel::radtan);
  EXPECT_EQ(sensor(rig, "lidar").type, SensorType::lidar);
  EXPECT_EQ(sensor(rig, "imu").type, SensorType::imu);
  EXPECT_EQ(sensor(rig, "imu").update_rate, 100.0);
  EXPECT_EQ(sensor(rig, "os_imu").type, SensorType::imu);
  EXPECT_EQ(rig.base_frame, "lidar");
  ASSERT_EQ(rig.notes.size(), 3u);  // one per camera, one for the file
  EXPECT_NE(rig.notes[0].find("cam_l: camera_model and distortion_model not given; pinhole with "
                              "radtan distortion assumed (the VBR convention)"),
            std::string::npos)
      << rig.notes[0];
  EXPECT_NE(rig.notes[2].find("no 'rigcal' section"), std::string::npos);
  // Converting to rigcal and back keeps everything, notes included.
  const Rig again = parse_rig_yaml(rig_to_yaml(rig), "converted.yaml");
  expect_identical(rig, again);
  // The VBR export has only VBR keys and reads back to the same numbers.
  const std::string vbr = rig_to_vbr_yaml(rig);
  EXPECT_EQ(vbr.find("sensor_type"), std::string::npos);
  EXPECT_EQ(vbr.find("rigcal"), std::string::npos);
  Rig from_vbr = parse_rig_yaml(vbr, "exported.yaml");
  from_vbr.notes = rig.notes;
  expect_identical(rig, from_vbr);
}

TEST(RigYaml, TCamLidarIsInverseCamTbTimesLidarTb) {
  Rig rig = parse_rig_yaml(kVbrOnly, "vbr_calib.yaml");
  // Camera optical axes in the LiDAR frame (x fwd, y left, z up), camera at (0.1, 0.25, -0.08).
  // A LiDAR point 5 m ahead, 1 m left, 2 m up is, in the camera: x = -(1 - 0.25) (left is -x),
  // y = -(2 + 0.08) (up is -y), z = 5 - 0.1.
  const Eigen::Vector3d p_lidar(5, 1, 2);
  const SE3 T_cam_lidar = T_a_b(rig, "cam_l", "lidar");
  EXPECT_TRUE((T_cam_lidar * p_lidar).isApprox(Eigen::Vector3d(-0.75, -2.08, 4.9), 1e-14));
  // The identity holds for a base sensor whose T_b is not the identity too.
  sensor(rig, "lidar").T_base_sensor =
      SE3::from_rotation_vector(Eigen::Vector3d(0.1, -0.2, 0.3), Eigen::Vector3d(1, 2, 3));
  const SE3 expected =
      sensor(rig, "cam_l").T_base_sensor.inverse() * sensor(rig, "lidar").T_base_sensor;
  EXPECT_TRUE(T_a_b(rig, "cam_l", "lidar").matrix().isApprox(expected.matrix(), 1e-15));
  EXPECT_TRUE(
      (T_a_b(rig, "cam_l", "cam_r") * T_a_b(rig, "cam_r", "cam_l")).matrix().isIdentity(1e-15));
}

TEST(RigYaml, KeepsUnknownKeysAndMetadata) {
  const std::string text = std::string(kVbrOnly) +
                           "  ros_topic: /os_cloud_node/imu\n"
                           "  extra: {a: 1, b: [2, 3]}\n"
                           "rigcal:\n  format_version: 1\n  steps: {cameras: {rms_px: 0.2}}\n";
  const Rig rig = parse_rig_yaml(text, "x.yaml");
  const Sensor& os = sensor(rig, "os_imu");
  ASSERT_EQ(os.extra_keys.size(), 2u);
  EXPECT_EQ(os.extra_keys[0].first, "ros_topic");
  ASSERT_EQ(rig.extra_metadata.size(), 1u);
  EXPECT_EQ(rig.extra_metadata[0].first, "steps");
  expect_identical(rig, parse_rig_yaml(rig_to_yaml(rig), "y.yaml"));
}

struct BadCase {
  const char* name;
  std::string yaml;
  std::string expected;  // the whole message
};

// A valid camera entry with one line replaced; line numbers below count from 1.
std::string camera_with(const std::string& replace_key, const std::string& new_line) {
  const std::vector<std::pair<std::string, std::string>> lines = {
      {"head", "cam_l:"},
      {"camera_model", "  camera_model: pinhole"},
      {"distortion_model", "  distortion_model: radtan"},
      {"intrinsics", "  intrinsics: [1000, 1000, 640, 360]"},
      {"distortion_coeffs", "  distortion_coeffs: [0.1, 0.01, 0, 0]"},
      {"resolution", "  resolution: [1280, 720]"},
      {"T_b", "  T_b: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]"},
      {"lidar", "lidar: {T_b: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}"}};
  std::string out;
  for (const auto& [key, line] : lines) {
    if (key == replace_key) {
      if (!new_line.empty()) out += new_line + "\n";
    } else {
      out += line + "\n";
    }
  }
  return out;
}

TEST(RigYaml, EveryValidationErrorNamesFileLineAndKey) {
  const std::vector<BadCase> cases = {
      {"matrix with 3 rows",
       camera_with("T_b", "  T_b: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]"),
       "rig.yaml:7: key 'cam_l.T_b': expected a 4x4 matrix as a list of 4 rows of 4 numbers; got "
       "3 rows"},
      {"row with 3 entries",
       camera_with("T_b",
                   "  T_b:\n  - [1, 0, 0, 0]\n  - [0, 1, 0]\n  - [0, 0, 1, 0]\n  - [0, 0, 0, 1]"),
       "rig.yaml:9: key 'cam_l.T_b': expected a 4x4 matrix as a list of 4 rows of 4 numbers; row 2 "
       "has 3 entries"},
      {"last row",
       camera_with("T_b", "  T_b: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]"),
       "rig.yaml:7: key 'cam_l.T_b': the last row of a rigid transform must be [0, 0, 0, 1], got "
       "[0, 0, 1, 1]"},
      {"not orthonormal",
       camera_with("T_b", "  T_b: [[1, 0.001, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]"),
       "rig.yaml:7: key 'cam_l.T_b': rotation is not orthonormal: max |R^T R - I| = 0.001 exceeds "
       "the tolerance 1e-05"},
      {"reflection",
       camera_with("T_b", "  T_b: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]]"),
       "rig.yaml:7: key 'cam_l.T_b': rotation has determinant < 0 (a reflection, not a rotation)"},
      {"negative focal length", camera_with("intrinsics", "  intrinsics: [-1000, 1000, 640, 360]"),
       "rig.yaml:4: key 'cam_l.intrinsics': focal lengths fx, fy must be > 0 and at most 1000000 "
       "px, got fx = -1000, fy = "
       "1000"},
      {"zero focal length", camera_with("intrinsics", "  intrinsics: [1000, 0, 640, 360]"),
       "rig.yaml:4: key 'cam_l.intrinsics': focal lengths fx, fy must be > 0 and at most 1000000 "
       "px, got fx = 1000, fy = "
       "0"},
      {"intrinsics count", camera_with("intrinsics", "  intrinsics: [1000, 1000, 640]"),
       "rig.yaml:4: key 'cam_l.intrinsics': expected 4 numbers [fx, fy, cx, cy], got 3"},
      {"unknown distortion model", camera_with("distortion_model", "  distortion_model: fisheye"),
       "rig.yaml:3: key 'cam_l.distortion_model': unknown distortion model 'fisheye'; expected "
       "radtan (k1 k2 p1 p2 [k3]) or equidistant (k1 k2 k3 k4)"},
      {"unknown camera model", camera_with("camera_model", "  camera_model: omni"),
       "rig.yaml:2: key 'cam_l.camera_model': unknown camera model 'omni'; rigcal supports "
       "pinhole"},
      {"radtan coefficient count",
       camera_with("distortion_coeffs", "  distortion_coeffs: [0.1, 0.01, 0]"),
       "rig.yaml:5: key 'cam_l.distortion_coeffs': radtan takes 4 (k1 k2 p1 p2) or 5 (k1 k2 p1 p2 "
       "k3) coefficients, got 3"},
      {"equidistant coefficient count",
       "cam_l:\n  distortion_model: equidistant\n  camera_model: pinhole\n"
       "  intrinsics: [1000, 1000, 640, 360]\n  distortion_coeffs: [0.1, 0.01, 0, 0, 0]\n"
       "  resolution: [1280, 720]\n  T_b: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, "
       "1]]\n"
       "lidar: {T_b: [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}\n",
       "rig.yaml:5: key 'cam_l.distortion_coeffs': equidistant takes 4 (k1 k2 k3 k4) coefficients, "
       "got 5"},
      {"missing intrinsics", camera_with("intrinsics", ""),
       "rig.yaml:2: key 'cam_l.intrinsics': missing required key"},
      {"missing T_b", camera_with("T_b", ""), "rig.yaml:2: key 'cam_l.T_b': missing required key"},
      {"bad number", camera_with("resolution", "  resolution: [1280, abc]"),
       "rig.yaml:6: key 'cam_l.resolution': expected a finite number, got 'abc'"},
      {"fractional resolution", camera_with("resolution", "  resolution: [1280.5, 720]"),
       "rig.yaml:6: key 'cam_l.resolution': expected [width, height] in whole pixels"},
      {"duplicate sensor",
       camera_with("lidar", "lidar: {T_b: [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}\ncam_l: {}"),
       "rig.yaml:9: key 'cam_l': duplicate sensor 'cam_l' (a sensor name appears twice)"},
      {"syntax error", camera_with("resolution", "  resolution: [1280, 720"),
       "rig.yaml:7: YAML syntax error: end of sequence flow not found"},
      {"unknown sensor kind",
       camera_with("lidar",
                   "lidar: {T_b: [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}\nthing: {T_b: "
                   "[[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}"),
       "rig.yaml:9: key 'thing': cannot tell what kind of sensor this is; add 'sensor_type: "
       "camera|lidar|imu|gnss'"},
      {"drift without its epoch",
       camera_with("lidar",
                   "lidar: {T_b: [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], time_drift_ppm: 20}"),
       "rig.yaml:8: key 'lidar.time_drift_ppm': needs time_drift_epoch (s, this sensor's clock)"},
      {"epoch without its drift",
       camera_with("lidar",
                   "lidar: {T_b: [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], time_drift_epoch: "
                   "12.5}"),
       "rig.yaml:8: key 'lidar.time_drift_epoch': given without time_drift_ppm"},
      {"camera key on a lidar",
       camera_with(
           "lidar",
           "lidar:\n  sensor_type: lidar\n  T_b: [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n"
           "  intrinsics: [1, 1, 1, 1]"),
       "rig.yaml:11: key 'lidar.intrinsics': 'intrinsics' belongs to cameras, but this sensor is a "
       "lidar"},
      // Finite but absurd numbers, repeated keys and typos of known keys.
      {"fx 1e308", camera_with("intrinsics", "  intrinsics: [1e308, 1000, 640, 360]"),
       "rig.yaml:4: key 'cam_l.intrinsics': focal lengths fx, fy must be > 0 and at most 1000000 "
       "px, got fx = 1e+308, fy = 1000"},
      {"distortion 1e300",
       camera_with("distortion_coeffs", "  distortion_coeffs: [1e300, 0, 0, 0]"),
       "rig.yaml:5: key 'cam_l.distortion_coeffs': coefficients must be finite, within +-1000, got "
       "1e+300"},
      {"a translation of 1e308 m",
       camera_with("T_b", "  T_b: [[1, 0, 0, 1e308], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]"),
       "rig.yaml:7: key 'cam_l.T_b': translation 1e+308 m: a rig's sensors lie within 1000 m of "
       "each other"},
      {"time_offset 1e308",
       camera_with("lidar",
                   "lidar: {T_b: [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], time_offset: 1e308}"),
       "rig.yaml:8: key 'lidar.time_offset': 1e+308 s is beyond 1000000000 s (even GPS against "
       "UNIX time is 3.2e8 s)"},
      {"a key given twice",
       camera_with("resolution", "  resolution: [1280, 720]\n  resolution: [640, 480]"),
       "rig.yaml:7: key 'cam_l.resolution': given twice in this sensor (which one is meant?)"},
      {"a typo of a known key",
       camera_with("lidar",
                   "lidar: {T_b: [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]], time_offsett: 0.1}"),
       "rig.yaml:8: key 'lidar.time_offsett': unknown key; did you mean 'time_offset'? (other "
       "unknown keys are kept as they are)"},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.name);
    try {
      parse_rig_yaml(c.yaml, "rig.yaml");
      ADD_FAILURE() << "no error for:\n" << c.yaml;
    } catch (const Error& e) {
      EXPECT_EQ(std::string(e.what()), c.expected) << c.yaml;
    }
  }
}

TEST(RigYaml, ClockDriftKeysRoundTripExactly) {
  const std::string text = camera_with(
      "lidar",
      "lidar: {T_b: [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}\nimu:\n  sensor_type: imu\n"
      "  T_b: [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n  time_offset: -0.0031\n"
      "  time_drift_ppm: 19.993\n  time_drift_epoch: 1403715529.112143517");
  const Rig rig = parse_rig_yaml(text, "rig.yaml");
  const Sensor& imu = sensor(rig, "imu");
  ASSERT_TRUE(imu.time_drift_ppm.has_value());
  EXPECT_EQ(*imu.time_drift_ppm, 19.993);
  EXPECT_EQ(imu.time_drift_epoch.ns, 1403715529112143517);  // every digit kept
  EXPECT_FALSE(sensor(rig, "lidar").time_drift_ppm.has_value());
  const Rig back = parse_rig_yaml(rig_to_yaml(rig), "back.yaml");
  EXPECT_EQ(*sensor(back, "imu").time_drift_ppm, 19.993);
  EXPECT_EQ(sensor(back, "imu").time_drift_epoch, imu.time_drift_epoch);
  EXPECT_FALSE(sensor(back, "cam_l").time_drift_ppm.has_value());
}

TEST(RigYaml, RejectsEmptyAndNewerFiles) {
  try {
    parse_rig_yaml("", "empty.yaml");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "empty.yaml: empty file: expected a map of sensors");
  }
  try {
    parse_rig_yaml(std::string(kVbrOnly) + "rigcal:\n  format_version: 7\n", "new.yaml");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "new.yaml:23: key 'rigcal.format_version': format version 7 is newer than this "
                 "rigcal reads (1); update rigcal");
  }
  EXPECT_THROW(read_rig_file("/nonexistent/rig.yaml"), Error);
}

TEST(RigYaml, ValidateCatchesProblemsOfRigsBuiltInCode) {
  std::mt19937_64 rng(1);
  Rig rig = testing::random_rig(rng);
  rig.sensors.push_back(rig.sensors.front());
  try {
    validate(rig);
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("duplicate sensor"), std::string::npos) << e.what();
  }
  rig = testing::random_rig(rng);
  rig.base_frame = "nope";
  EXPECT_THROW(rig_to_yaml(rig), Error);
}

}  // namespace
}  // namespace rigcal::rig
