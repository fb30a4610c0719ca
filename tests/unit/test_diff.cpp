// rigcal diff (calib/session/diff.h): a calibration against itself is zero everywhere; a known
// change comes back as made, in the frames and units documented, with its significance against
// the stored sigmas; the projection difference against closed forms.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "browser.h"
#include "cli_run.h"
#include "rigcal/core/error.h"
#include "rigcal/core/stats.h"
#include "rigcal/report/html.h"
#include "rigcal/report/png.h"
#include "rigcal/report/rotation.h"
#include "rigcal/report/svg_plot.h"
#include "rigcal/rig/export.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/session/diff.h"
#include "rigcal/session/provenance.h"
#include "test_rigs.h"

namespace rigcal {
namespace {

constexpr double kDeg = M_PI / 180.0;

using rig::testing::sample_rig;

// The sigmas a calibrate run would store: the stereo extrinsic's, the LiDAR-camera's, cam_r's
// intrinsics and the IMU's clock.
void store_sigmas(rig::Rig& rig) {
  session::StepRecord cameras{"cameras", "ok", "test", "", {}, {}, {}, {}};
  for (const char* p : {"fx", "fy", "cx", "cy"})
    cameras.sigmas.push_back({fmt::format("cam_r.{}_px", p), 0.5, ""});
  session::StepRecord lidar_camera{"lidar_camera", "ok", "test", "", {}, {}, {}, {}};
  for (int i = 0; i < 3; ++i) {
    lidar_camera.sigmas.push_back({fmt::format("T_cam_r_lidar.t.{}_m", "xyz"[i]), 0.001, ""});
    lidar_camera.sigmas.push_back(
        {fmt::format("T_cam_r_lidar.rotation.{}_deg", "xyz"[i]), 0.05, ""});
  }
  session::StepRecord time_sync{"time_sync", "ok", "test", "", {}, {}, {}, {}};
  time_sync.sigmas.push_back({"imu.time_offset_s", 1e-4, ""});
  rig.extra_metadata.emplace_back("steps", session::steps_yaml({cameras, lidar_camera, time_sync}));
}

TEST(Chi2UpperTail, MatchesTabulatedQuantiles) {
  // The 95 % and 99.9 % points of chi-square (tables), and a closed form.
  EXPECT_NEAR(chi2_upper_tail(3.841459, 1), 0.05, 1e-6);
  EXPECT_NEAR(chi2_upper_tail(5.991465, 2), 0.05, 1e-6);
  EXPECT_NEAR(chi2_upper_tail(7.814728, 3), 0.05, 1e-6);
  EXPECT_NEAR(chi2_upper_tail(12.591587, 6), 0.05, 1e-6);
  EXPECT_NEAR(chi2_upper_tail(16.266236, 3), 0.001, 1e-7);
  EXPECT_NEAR(chi2_upper_tail(2.0, 2), std::exp(-1.0), 1e-12);
  EXPECT_EQ(chi2_upper_tail(0.0, 4), 1.0);
}

TEST(Diff, ACalibrationAgainstItselfIsZero) {
  rig::Rig a = sample_rig();
  store_sigmas(a);
  const session::RigDifference d = session::diff_rigs(a, a);
  // Each sensor but the base (five), and the relation a step stored sigmas of, T_cam_r_lidar.
  ASSERT_EQ(d.poses.size(), 6u);
  for (const session::PoseDifference& p : d.poses) {
    // R R' of a stored rotation is the identity to rounding.
    EXPECT_LT(p.rotation_rad.norm(), 1e-15) << p.a << " " << p.b;
    EXPECT_EQ(p.translation_m.norm(), 0.0) << p.a << " " << p.b;
  }
  for (const session::ClockDifference& c : d.clocks) EXPECT_EQ(c.offset_s, 0.0) << c.sensor;
  ASSERT_EQ(d.cameras.size(), 2u);
  for (const session::CameraDifference& c : d.cameras) {
    for (double v : c.values) EXPECT_EQ(v, 0.0) << c.camera;
    ASSERT_TRUE(c.projection) << c.note;
    EXPECT_LT(c.projection->raw_max_px, 1e-9);
    EXPECT_LT(c.projection->fitted_max_px, 1e-9);
    EXPECT_EQ(c.projection->columns * c.projection->rows, int(c.projection->u.size()));
  }
  EXPECT_TRUE(d.only_in_a.empty());
  EXPECT_TRUE(d.only_in_b.empty());
}

TEST(Diff, AKnownChangeComesBackAsMadeWithItsSignificance) {
  rig::Rig a = sample_rig();
  store_sigmas(a);
  rig::Rig b = a;
  // cam_r turned by phi about the base frame's axes and moved by dt there, its fx and cx
  // changed; the IMU's clock 2 ms later.
  const Eigen::Vector3d phi = Eigen::Vector3d(0.1, -0.2, 0.15) * kDeg;
  const Eigen::Vector3d dt(0.003, -0.001, 0.002);
  rig::Sensor& cam_r = rig::sensor(b, "cam_r");
  cam_r.T_base_sensor.R = rotation_from_vector(phi) * cam_r.T_base_sensor.R;
  cam_r.T_base_sensor.t += dt;
  cam_r.camera.fx += 1.5;
  cam_r.camera.cx -= 2.0;
  rig::sensor(b, "imu").time_offset += 0.002;

  const session::RigDifference d = session::diff_rigs(a, b);
  const SE3 T_base_cam_r = rig::sensor(a, "cam_r").T_base_sensor;
  bool base_pose = false, lidar_camera = false;
  for (const session::PoseDifference& p : d.poses) {
    if (p.a == "lidar" && p.b == "cam_r") {
      base_pose = true;
      EXPECT_LT((p.rotation_rad - phi).norm(), 1e-12);
      EXPECT_LT((p.translation_m - dt).norm(), 1e-12);
    } else if (p.a == "cam_r" && p.b == "lidar") {
      // T_cam_r_lidar = T_base_cam_r^-1 (the base is the LiDAR): its rotation turns by
      // -R' phi about cam_r's axes, its translation t = -R' t_b changes by -R_B' (t_A + dt) + R_A'
      // t_A.
      lidar_camera = true;
      const Eigen::Matrix3d R_a = T_base_cam_r.R, R_b = rotation_from_vector(phi) * R_a;
      EXPECT_LT((p.rotation_rad + R_a.transpose() * phi).norm(), 1e-12);
      const Eigen::Vector3d expected =
          -R_b.transpose() * (T_base_cam_r.t + dt) + R_a.transpose() * T_base_cam_r.t;
      EXPECT_LT((p.translation_m - expected).norm(), 1e-12);
      ASSERT_TRUE(p.significance);
      EXPECT_EQ(p.significance->dof, 6);
      // Both calibrations store the same sigmas: combined sqrt(2) times them.
      double chi2 = 0;
      for (int i = 0; i < 3; ++i) {
        chi2 += std::pow(p.rotation_rad[i] / (std::sqrt(2.0) * 0.05 * kDeg), 2);
        chi2 += std::pow(p.translation_m[i] / (std::sqrt(2.0) * 0.001), 2);
      }
      EXPECT_NEAR(p.significance->chi2, chi2, 1e-9 * chi2);
      EXPECT_NEAR(p.significance->p_value, chi2_upper_tail(chi2, 6), 1e-15);
      EXPECT_LT(p.significance->p_value, 0.01);  // 0.27 deg and 3.7 mm against 0.07 and 1.4
    } else {
      EXPECT_LT(p.rotation_rad.norm(), 1e-15) << p.a << " " << p.b;
      EXPECT_EQ(p.translation_m.norm(), 0.0) << p.a << " " << p.b;
      EXPECT_FALSE(p.significance) << p.a << " " << p.b;
    }
  }
  EXPECT_TRUE(base_pose);
  EXPECT_TRUE(lidar_camera);
  for (const session::ClockDifference& c : d.clocks) {
    if (c.sensor != "imu") {
      EXPECT_EQ(c.offset_s, 0.0) << c.sensor;
      continue;
    }
    EXPECT_NEAR(c.offset_s, 0.002, 1e-15);
    ASSERT_TRUE(c.significance);
    EXPECT_NEAR(c.significance->chi2, std::pow(0.002 / (std::sqrt(2.0) * 1e-4), 2), 1e-6);
  }
  for (const session::CameraDifference& c : d.cameras) {
    ASSERT_TRUE(c.projection);
    if (c.camera == "cam_l") {
      EXPECT_LT(c.projection->raw_max_px, 1e-9);
      continue;
    }
    EXPECT_EQ(c.values[0], 1.5);
    EXPECT_EQ(c.values[2], -2.0);
    ASSERT_TRUE(c.significance);
    EXPECT_NEAR(c.significance->chi2, (1.5 * 1.5 + 2.0 * 2.0) / (2 * 0.25), 1e-9);
    // A pixel's ray by A, projected by B: u moves by dfx / fx (u - cx_A) - 2, v not at all.
    const rig::CameraModel& lens = rig::sensor(a, "cam_r").camera;
    const session::ProjectionDifference& p = *c.projection;
    double max_expected = 0;
    for (size_t i = 0; i < p.u.size(); ++i) {
      if (!std::isfinite(p.raw_px[i])) continue;
      const double expected = std::abs(1.5 / lens.fx * (p.u[i] - lens.cx) - 2.0);
      EXPECT_NEAR(p.raw_px[i], expected, 1e-6) << p.u[i] << " " << p.v[i];
      max_expected = std::max(max_expected, expected);
    }
    EXPECT_NEAR(p.raw_max_px, max_expected, 1e-6);
    // The principal point's shift is almost a turn of the camera (about 2 / fx rad); the scale
    // is not, and what remains is the scale's share.
    EXPECT_NEAR(p.fitted_rotation_deg, 2.0 / lens.fx / kDeg, 0.3 * 2.0 / lens.fx / kDeg);
    EXPECT_LT(p.fitted_rms_px, 0.6 * p.raw_rms_px);
  }
}

// Where the steps stored correlations, the chi-square is d' (C_A + C_B)^-1 d: checked against
// the 2 x 2 inverse written out, with each calibration's own sigmas and correlation.
TEST(Diff, StoredCorrelationsEnterTheChiSquare) {
  const auto with_lens_sigmas = [](double s_fx, double s_cx, double rho) {
    rig::Rig rig = sample_rig();
    session::StepRecord cameras{"cameras", "ok", "test", "", {}, {}, {}, {}};
    cameras.sigmas = {{"cam_r.fx", s_fx, "px"}, {"cam_r.cx", s_cx, "px"}};
    cameras.correlations.push_back({"cam_r", {"cam_r.fx", "cam_r.cx"}, {1, rho, rho, 1}});
    rig.extra_metadata.emplace_back("steps", session::steps_yaml({cameras}));
    return rig;
  };
  const rig::Rig a = with_lens_sigmas(0.5, 0.4, 0.8);
  rig::Rig b = with_lens_sigmas(0.3, 0.6, -0.3);
  // Read back under the keys the sigmas were stored under, with their units.
  const session::StoredUncertainty u = session::stored_uncertainty(a);
  EXPECT_EQ(u.sigma.at("cam_r.fx_px"), 0.5);
  EXPECT_EQ(u.correlation("cam_r.fx_px", "cam_r.cx_px"), 0.8);
  EXPECT_EQ(u.correlation("cam_r.cx_px", "cam_r.fx_px"), 0.8);
  EXPECT_EQ(u.correlation("cam_r.fx_px", "cam_r.fy_px"), 0.0);
  rig::sensor(b, "cam_r").camera.fx += 1.0;
  rig::sensor(b, "cam_r").camera.cx += 1.0;
  const double c11 = 0.25 + 0.09, c22 = 0.16 + 0.36, c12 = 0.8 * 0.5 * 0.4 - 0.3 * 0.3 * 0.6;
  const double det = c11 * c22 - c12 * c12;
  const double expected = (c22 - 2 * c12 + c11) / det;  // d = (1, 1)
  for (const session::CameraDifference& c : session::diff_rigs(a, b).cameras) {
    if (c.camera != "cam_r") continue;
    ASSERT_TRUE(c.significance);
    EXPECT_TRUE(c.significance->correlated);
    EXPECT_EQ(c.significance->dof, 2);
    EXPECT_NEAR(c.significance->chi2, expected, 1e-4 * expected);
    EXPECT_NEAR(c.significance->sigma[0], std::sqrt(c11), 1e-12);
    // A change along fx alone, with cx known: judged against sqrt(det / c22).
    EXPECT_NEAR(c.significance->conditional_sigma[0], std::sqrt(det / c22), 1e-6);
    EXPECT_NEAR(c.significance->conditional_sigma[2], std::sqrt(det / c11), 1e-6);
    // Without the correlations the same difference weighs otherwise.
    EXPECT_GT(std::abs(c.significance->chi2 - (1 / c11 + 1 / c22)), 0.05);
  }
  // A matrix that is not one is refused, naming what is wrong.
  rig::Rig bad = sample_rig();
  bad.extra_metadata.emplace_back(
      "steps",
      "{cameras: {status: ok, tool_version: t, inputs: [], sigmas: {cam_r.fx_px: 0.5}, "
      "residuals: {}, correlations: {cam_r: {keys: [cam_r.fx_px, cam_r.cx_px], rho: [1, 2, 2, "
      "1]}}}}");
  try {
    session::read_steps(bad);
    ADD_FAILURE() << "a correlation of 2 was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not in [-1, 1]"), std::string::npos) << e.what();
  }
}

TEST(Diff, SaysWhatItCannotCompare) {
  rig::Rig a = sample_rig();
  rig::Rig b = a;
  rig::sensor(b, "cam_l").camera.width /= 2;
  b.sensors.erase(std::find_if(b.sensors.begin(), b.sensors.end(),
                               [](const rig::Sensor& s) { return s.name == "imu"; }));
  const session::RigDifference d = session::diff_rigs(a, b);
  EXPECT_EQ(d.only_in_a, std::vector<std::string>{"imu"});
  for (const session::CameraDifference& c : d.cameras) {
    if (c.camera != "cam_l") continue;
    EXPECT_FALSE(c.projection);
    EXPECT_NE(c.note.find("resolutions differ"), std::string::npos) << c.note;
  }
  // Without A's base frame (an import of the cameras alone): compared in A's first sensor that
  // B has, and said.
  rig::Rig cameras_only;
  for (const char* name : {"cam_l", "cam_r"}) cameras_only.sensors.push_back(rig::sensor(a, name));
  cameras_only.base_frame = "cam_l";
  const session::RigDifference c = session::diff_rigs(a, cameras_only);
  EXPECT_EQ(c.base_frame, "cam_l");
  ASSERT_EQ(c.poses.size(), 1u);
  EXPECT_LT(c.poses[0].rotation_rad.norm(), 1e-12);  // T_cam_l_cam_r is the same
  EXPECT_LT(c.poses[0].translation_m.norm(), 1e-12);
  EXPECT_NE(c.notes.at(0).find("poses compared in 'cam_l'"), std::string::npos) << c.notes[0];
  rig::Rig other;
  other.sensors.push_back(rig::sensor(a, "lidar"));
  other.sensors[0].name = "velodyne";
  other.base_frame = "velodyne";
  EXPECT_THROW(session::diff_rigs(a, other), Error);
}

TEST(DiffCli, WritesItsReportAndRefusesBadInput) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / fmt::format("rigcal_diff_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  rig::Rig a = sample_rig();
  store_sigmas(a);
  rig::write_rig_file(a, dir / "a.yaml");
  rig::Rig b = a;
  rig::sensor(b, "cam_r").T_base_sensor.t.x() += 0.01;
  rig::write_rig_file(b, dir / "b.yaml");
  testing::CliRun r = testing::rigcal_cli(
      fmt::format("diff {0}/a.yaml {0}/b.yaml --report {0}/report", dir.string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("T_cam_r_lidar"), std::string::npos) << r.out;
  // 10 mm along one axis against 1.4 mm: chi-square 50 over 6 components.
  EXPECT_NE(r.out.find(": changed"), std::string::npos) << r.out;
  const nlohmann::json j = nlohmann::json::parse(testing::slurp(dir / "report/diff.json"));
  bool found = false;
  for (const nlohmann::json& p : j["poses"]) {
    if (p["relation"] != "T_lidar_cam_r") continue;
    found = true;
    EXPECT_NEAR(p["translation_mm"][0].get<double>(), 10.0, 1e-9);
  }
  EXPECT_TRUE(found);
  // The map: a point a grid pixel, image rows growing downwards (the first row, v = 0, drawn
  // above the last).
  const std::string svg = testing::slurp(dir / "report/projection_diff_cam_l.svg");
  const auto cy = [&](size_t at) { return std::stod(svg.substr(svg.find("cy=\"", at) + 4)); };
  EXPECT_LT(cy(svg.find("<circle")), cy(svg.rfind("<circle")));
  EXPECT_NE(svg.find("|difference| [px]"), std::string::npos);
  // Another tool's file: Kalibr's camchain (written by rigcal's export) validates, and diffs
  // against the rigcal file in cam_l's frame (it has no LiDAR), its poses and lenses the same.
  std::ofstream(dir / "camchain.yaml") << rig::kalibr_camchain_yaml(a);
  r = testing::rigcal_cli(fmt::format("rig validate {0}/camchain.yaml", dir.string()), dir);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("valid, 3 sensors"), std::string::npos) << r.out;
  r = testing::rigcal_cli(
      fmt::format("diff {0}/a.yaml {0}/camchain.yaml --report {0}/kalibr", dir.string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("poses compared in 'cam_l'"), std::string::npos) << r.out;
  const nlohmann::json k = nlohmann::json::parse(testing::slurp(dir / "kalibr/diff.json"));
  EXPECT_EQ(k["poses"].size(), 2u);  // cam_r and the IMU in cam_l's frame
  for (const nlohmann::json& p : k["poses"]) {
    EXPECT_LT(p["rotation_angle_deg"].get<double>(), 1e-9) << p;
    EXPECT_LT(p["translation_norm_mm"].get<double>(), 1e-9) << p;
  }
  for (const nlohmann::json& c : k["cameras"])
    EXPECT_LT(c["projection"]["raw_max_px"].get<double>(), 1e-9) << c;
  EXPECT_EQ(k["only_in_a"].size(), 3u);  // the LiDAR, its IMU, the GNSS/INS
  // A file that is not a calibration: exit 2, one line naming it.
  std::ofstream(dir / "bad.yaml") << "cam_l: [1, 2\n";
  r = testing::rigcal_cli(fmt::format("diff {0}/a.yaml {0}/bad.yaml", dir.string()), dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.yaml"), std::string::npos) << r.err;
  fs::remove_all(dir);
}

// The diff's page in a real browser: it loads with no console message, its sections are in the
// DOM, a screenshot is taken; a page with a script error is caught the same way (the check can
// fail); `rigcal report DIR` renders the same page again from the stored JSON.
TEST(DiffReport, LoadsInChromiumAndRendersAgainFromItsJson) {
  namespace fs = std::filesystem;
  if (!testing::have_chromium()) GTEST_SKIP() << "chromium (Debian package chromium) not installed";
  const fs::path dir = fs::temp_directory_path() / fmt::format("rigcal_diff_page_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir);
  rig::Rig a = sample_rig();
  store_sigmas(a);
  rig::write_rig_file(a, dir / "a.yaml");
  rig::Rig b = a;
  rig::sensor(b, "cam_r").camera.cx += 2.0;
  rig::write_rig_file(b, dir / "b.yaml");
  testing::CliRun r = testing::rigcal_cli(
      fmt::format("diff {0}/a.yaml {0}/b.yaml --report {0}/report", dir.string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string page = testing::slurp(dir / "report/report.html");
  const testing::BrowserLoad load =
      testing::load_in_browser(dir / "report/report.html", dir / "shot.png");
  EXPECT_TRUE(load.ran) << load.log;
  EXPECT_EQ(testing::console_messages(load.log), "");
  for (const char* id : {"id=\"poses\"", "id=\"clocks\"", "id=\"cameras\"", "<svg"})
    EXPECT_NE(load.dom.find(id), std::string::npos) << id;
  EXPECT_GT(load.screenshot_bytes, 20000u);
  std::ofstream(dir / "bad.html") << "<!doctype html><p>x</p><script>undefined_fn();</script>";
  const testing::BrowserLoad bad = testing::load_in_browser(dir / "bad.html", dir / "bad.png");
  EXPECT_NE(testing::console_messages(bad.log).find("Uncaught ReferenceError"), std::string::npos)
      << bad.log;
  // Rendered again from diff.json and the maps: the same page.
  fs::remove(dir / "report/report.html");
  r = testing::rigcal_cli(fmt::format("report {}/report", dir.string()), dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(testing::slurp(dir / "report/report.html"), page);
  r = testing::rigcal_cli(fmt::format("report {}", dir.string()), dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no reports/calibrate.json, run.json, ground_truth.json, check.json or "),
            std::string::npos)
      << r.err;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rigcal

namespace rigcal {
namespace {

TEST(ReportHtml, RotationsAreAnAngleAboutAnAxisEvenAtGimbalLock) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, -1, 1).normalized();
  const Eigen::Matrix3d R = rotation_from_vector(axis * 120 * M_PI / 180);
  const nlohmann::json aa = report::axis_angle_json(R);
  EXPECT_NEAR(aa["angle_deg"].get<double>(), 120, 1e-10);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(aa["axis"][i].get<double>(), axis[i], 1e-12);
  EXPECT_EQ(report::rotation_text(R, {0.01, 0.02, 0.03}, "cam_r"),
            "rotation 120.0000 deg about [0.5774 -0.5774 0.5774], 1-sigma 0.0100 0.0200 0.0300 "
            "deg about cam_r's x y z");
  EXPECT_EQ(report::axis_angle_json(Eigen::Matrix3d::Identity())["angle_deg"], 0.0);
  // A camera looking along the LiDAR's x (pitch 90 deg, where roll and yaw are one angle): its
  // angle and axis give the rotation back.
  const Eigen::Matrix3d lock = from_roll_pitch_yaw(0.3, M_PI / 2, -0.2);
  const nlohmann::json l = report::axis_angle_json(lock);
  const Eigen::Vector3d phi(l["axis"][0].get<double>(), l["axis"][1].get<double>(),
                            l["axis"][2].get<double>());
  EXPECT_TRUE(
      rotation_from_vector(phi * l["angle_deg"].get<double>() * M_PI / 180).isApprox(lock, 1e-12));
}

std::string base64_decode(std::string_view text) {
  std::string out;
  uint32_t v = 0;
  int bits = 0;
  for (const char c : text) {
    const char* digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    const char* at = std::strchr(digits, c);
    if (c == '=' || !at) break;
    v = v << 6 | static_cast<uint32_t>(at - digits), bits += 6;
    if (bits >= 8) out += static_cast<char>((v >> (bits - 8)) & 0xff), bits -= 8;
  }
  return out;
}

TEST(ReportHtml, ImagesShrinkIntoThePageAndEachPlotClipsOnItsOwn) {
  cv::Mat image(1000, 2000, CV_8UC3);
  cv::randu(image, 0, 255);
  const std::string html = report::html_inline_image(report::encode_png(image), "shot <1>");
  const std::string prefix = "<img src=\"data:image/jpeg;base64,";
  ASSERT_EQ(html.rfind(prefix, 0), 0u) << html.substr(0, 80);
  EXPECT_NE(html.find("width=\"1000\" alt=\"shot &lt;1&gt;\""), std::string::npos);
  const std::string jpeg = base64_decode(html.substr(prefix.size()));
  const cv::Mat back = cv::imdecode(std::vector<uchar>(jpeg.begin(), jpeg.end()), cv::IMREAD_COLOR);
  EXPECT_EQ(back.cols, 1000);
  EXPECT_EQ(back.rows, 500);
  EXPECT_THROW(report::html_inline_image("not an image", "x"), Error);

  report::Plot a{"a", "x", "y", "", {{"s", {0, 1}, {0, 1}, {}}}};
  report::Plot b = a;
  b.title = "b";
  const std::string sa = report::html_inline_svg(report::render_svg(a)),
                    sb = report::html_inline_svg(report::render_svg(b));
  auto clip = [](const std::string& svg) {
    const size_t at = svg.find("clipPath id=\"") + 13;
    return svg.substr(at, svg.find('"', at) - at);
  };
  EXPECT_NE(clip(sa), clip(sb));
  EXPECT_NE(sa.find("url(#" + clip(sa) + ")"), std::string::npos);
  EXPECT_EQ(sa.find("url(#area)"), std::string::npos);
}

TEST(ReportHtml, AGridIsDrawnCellByCellWithItsContours) {
  // Values growing with the column: the 1.5 contour runs between columns 1 and 2's centres, at
  // x = 20 in plot units (cells of 10), straight down the three rows' centres.
  report::PlotGrid g;
  g.cols = 4, g.rows = 3, g.cell = 10;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) g.values.push_back(c);
  g.contours = {1.5};
  report::Plot plot{"grid", "x", "y", "value", {}};
  plot.limits = {0, 40, 0, 30};
  plot.grid = g;
  const std::string svg = report::render_svg(plot);
  // 670 x 510 px of plot area from (80, 50): x 20 -> 415, y 5, 15, 25 -> 475, 305, 135.
  EXPECT_NE(svg.find("<path d=\"M415.0 475.0L415.0 305.0M415.0 305.0L415.0 135.0\""),
            std::string::npos)
      << svg;
  size_t cells = 0;
  for (size_t at = svg.find("<rect x="); at != std::string::npos; at = svg.find("<rect x=", at + 1))
    ++cells;
  EXPECT_GE(cells, 12u);  // the cells, then the frame and the colour bar's
  EXPECT_NE(svg.find(">1.5</text>"), std::string::npos);
}

}  // namespace
}  // namespace rigcal
