// The per-session pipeline as a user runs it: a simulated session rewritten exactly as vbr-devkit's
// `convert kitti` writes a recording (its IMU CSV header, full-field point clouds with
// .metadata.json, colour PNGs), calibrated in one `rigcal calibrate` run; the board missing from
// the LiDAR-camera images (the step named, the others kept, nothing published, exit 2) and the
// rerun after the fix (only that step runs); publishing into sequence folders; the session layout.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "bag_writer.h"
#include "browser.h"
#include "cli_run.h"
#include "devkit_layout.h"
#include "fixtures.h"
#include "rigcal/core/error.h"
#include "rigcal/core/sha256.h"
#include "rigcal/io/files.h"
#include "rigcal/io/image_sets.h"
#include "rigcal/io/rates_io.h"
#include "rigcal/io/session.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/rig/rig_yaml.h"
#include "rigcal/session/provenance.h"
#include "rigcal/session/publish.h"
#include "test_rigs.h"

namespace rigcal {
namespace {

namespace fs = std::filesystem;

using testing::CliRun;
using testing::rigcal_cli;
using testing::slurp;

// The IMU CSV under the devkit's header: rigcal's simulator writes the same columns (acc, gyro,
// quaternion wxyz, three covariances) under the ROS field names.
void devkit_imu(const fs::path& topic) {
  const fs::path file = topic / "data" / "imu.txt";
  std::string text = slurp(file);
  text = std::string(testing::kDevkitImuHeader) + text.substr(text.find('\n'));
  io::write_file_atomic(file, text);
}

// KITTI x y z intensity + rigcal's fields/ (t, ring) -> the driver's full records + metadata.
void devkit_points(const fs::path& topic) {
  size_t n_files = 0;
  for (const fs::directory_entry& e : fs::directory_iterator(topic / "data")) {
    const std::string xyzi = slurp(e.path());
    const std::string fields = slurp(topic / "fields" / e.path().filename());
    const size_t n = xyzi.size() / 16;
    std::string full(48 * n, '\0');
    for (size_t i = 0; i < n; ++i) {
      char* r = full.data() + 48 * i;
      std::memcpy(r, xyzi.data() + 16 * i, 12);           // x y z
      std::memcpy(r + 16, xyzi.data() + 16 * i + 12, 4);  // intensity
      std::memcpy(r + 20, fields.data() + 8 * i, 4);      // t
      std::memcpy(r + 26, fields.data() + 8 * i + 4, 2);  // ring
      float p[3];
      std::memcpy(p, r, 12);
      const uint32_t range_mm =
          static_cast<uint32_t>(1e3 * std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]));
      std::memcpy(r + 32, &range_mm, 4);
    }
    io::write_file_atomic(e.path(), full);
    ++n_files;
  }
  fs::remove_all(topic / "fields");
  io::write_file_atomic(topic / ".metadata.json",
                        testing::ouster_metadata_json("/ouster/points", n_files));
}

// The devkit's default image conversion (Bayer to RGB, written by cv2.imwrite): 3 channels.
void devkit_images(const fs::path& topic) {
  for (const fs::directory_entry& e : fs::directory_iterator(topic / "data")) {
    cv::Mat gray = cv::imread(e.path().string(), cv::IMREAD_GRAYSCALE), bgr;
    cv::cvtColor(gray, bgr, cv::COLOR_GRAY2BGR);
    cv::imwrite(e.path().string(), bgr);
  }
  fs::remove(topic / "corners_truth.csv");
}

// A session of the sample rig simulated with the parts in `what` (the odometry stands in for
// rigcal's own), rewritten in the devkit's layout.
fs::path simulate_devkit_session(const fs::path& dir, const std::string& what,
                                 const std::string& config) {
  std::ofstream(dir / "sim.yaml") << config;
  const fs::path root = dir / "session";
  const CliRun sim = rigcal_cli(fmt::format("simulate --out {} --config {} --what {}",
                                            root.string(), (dir / "sim.yaml").string(), what),
                                dir);
  if (sim.status != 0) throw std::runtime_error("simulate failed: " + sim.err);
  for (const char* cam :
       {"stereo/camera_left", "stereo/camera_right", "lidar_camera/camera_right"}) {
    if (fs::exists(root / cam)) devkit_images(root / cam);
  }
  if (fs::exists(root / "lidar_camera")) devkit_points(root / "lidar_camera" / "ouster_points");
  if (fs::exists(root / "ouster_points")) devkit_points(root / "ouster_points");
  if (fs::exists(root / "imu")) {
    devkit_imu(root / "imu");
    devkit_imu(root / "ouster_imu");
  }
  return root;
}

class Session : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           fmt::format("rigcal_session_{}_{}", ::getpid(),
                       ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // The whole session: 20 stereo views, 8 LiDAR-camera pairs, the two IMUs, the trajectories.
  // Images integrated on 3 x 3 samples a pixel (the simulator's default is 5 x 5): these tests
  // judge the session's workflow, not the corners' last hundredth of a pixel.
  fs::path whole_session() {
    return simulate_devkit_session(
        dir_, "stereo,lidar-camera,imu,trajectories",
        "stereo:\n  views: 20\nlidar_camera:\n  pairs: 8\nimage:\n  supersample: 3\n");
  }
  // The same parts, fewer views and pairs: where the steps' outputs are compared, not judged.
  fs::path small_session() {
    return simulate_devkit_session(
        dir_, "stereo,lidar-camera,imu,trajectories",
        "stereo:\n  views: 8\nlidar_camera:\n  pairs: 4\nimage:\n  supersample: 3\n");
  }
  // The motion recording only.
  fs::path motion_session() { return simulate_devkit_session(dir_, "imu,trajectories", ""); }
  fs::path dir_;
};

double rotation_error_deg(const SE3& a, const SE3& b) {
  return rotation_angle(a.R.transpose() * b.R) * 180.0 / M_PI;
}

TEST_F(Session, TheDevkitImuHeaderReads) {
  const fs::path session = motion_session();
  const io::RateFile f = io::read_rates(session / "imu");
  EXPECT_EQ(f.format, "vbr");
  EXPECT_EQ(f.rates.stamps.size(), f.rates.rates.size());
  EXPECT_GT(f.rates.stamps.size(), 1000u);
  EXPECT_GT(f.rates.rates[100].norm(), 0.0);  // the gyro columns, not the accelerometer's
}

TEST_F(Session, TheLayoutResolves) {
  const fs::path session = motion_session();
  const io::Session s = io::read_session(session);
  EXPECT_TRUE(s.cameras.empty());
  EXPECT_EQ(fs::canonical(s.motion), fs::canonical(session));
  EXPECT_EQ(s.target, session / "target.yaml");
  EXPECT_EQ(s.odometry, session / "trajectories" / "lidar_odometry.tum");
  EXPECT_EQ(s.gnss, session / "trajectories" / "gnss_ins.tum");
  EXPECT_THROW(io::recording_for(s, "cameras"), Error);
  // Without session.yaml: the default folder names, or the root as the one recording.
  fs::remove(session / "session.yaml");
  fs::create_directories(dir_ / "root" / "motion");
  fs::rename(session / "imu", dir_ / "root" / "motion" / "imu");
  const io::Session d = io::read_session(dir_ / "root");
  EXPECT_EQ(d.motion, dir_ / "root" / "motion");
  EXPECT_TRUE(d.odometry.empty());
  EXPECT_EQ(io::read_session(session).motion, session);  // ouster_imu/ is still there
  EXPECT_EQ(io::read_session(dir_ / "root" / "motion").motion, dir_ / "root" / "motion");
}

TEST_F(Session, SessionYamlErrorsNameKeyAndLine) {
  const fs::path root = dir_ / "bad_yaml";
  fs::create_directories(root / "stereo");
  std::ofstream(root / "session.yaml") << "cameras: stereo\nodometry_file: x.tum\n";
  try {
    io::read_session(root);
    FAIL() << "an unknown key was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("session.yaml:2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("odometry_file"), std::string::npos) << e.what();
  }
  for (const char* text : {"cameras: nowhere\n", "motion: stereo\nmotion: stereo\n"}) {
    std::ofstream(root / "session.yaml") << text;
    try {
      io::read_session(root);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("session.yaml:"), std::string::npos) << e.what();
    }
  }
  // A name the file system refuses (longer than 255 bytes) is the key's error, with its line.
  std::ofstream(root / "session.yaml") << "cameras: stereo\nrig: " << std::string(300, 'r') << "\n";
  const std::string too_long = testing::error_message_of([&] { io::read_session(root); });
  EXPECT_NE(too_long.find("session.yaml:2"), std::string::npos) << too_long;
  EXPECT_NE(too_long.find("too long"), std::string::npos) << too_long;
  EXPECT_THROW(io::read_session(root / "absent"), Error);
  // A file that is neither a bag nor a capture is said to be neither.
  std::ofstream(root / "notes.txt") << "not a recording\n";
  const std::string text_file =
      testing::error_message_of([&] { io::read_session(root / "notes.txt"); });
  EXPECT_NE(text_file.find("nor a ROS1 bag"), std::string::npos) << text_file;
}

// Acceptance: one run on the devkit-layout session with the board missing from every
// LiDAR-camera image names that step, keeps the others, publishes nothing and exits 2; after the
// fix a rerun runs only that step and publishes a calibration within the earlier issues' bars.
TEST_F(Session, CalibrateNamesTheFailedStepThenRerunsOnlyIt) {
  const fs::path session = whole_session();
  const fs::path images = session / "lidar_camera" / "camera_right" / "data";
  const fs::path kept = dir_ / "kept_images";
  fs::copy(images, kept);
  for (const fs::directory_entry& e : fs::directory_iterator(images)) {
    const cv::Mat img = cv::imread(e.path().string());
    cv::imwrite(e.path().string(), cv::Mat(img.size(), img.type(), cv::Scalar::all(128)));
  }
  const fs::path out = dir_ / "calibration";
  const std::string args =
      fmt::format("calibrate {} --out {} --rig {}", session.string(), out.string(), kPrior);
  const CliRun bad = rigcal_cli(args, dir_);
  EXPECT_EQ(bad.status, 2) << bad.out << bad.err;
  EXPECT_FALSE(fs::exists(out / "calib.yaml"));
  EXPECT_NE(bad.out.find("== lidar_camera: failed"), std::string::npos) << bad.out;
  // stderr's last line is the failed step's error, naming the step.
  const size_t last = bad.err.rfind('\n', bad.err.size() - 2);
  const std::string last_line = bad.err.substr(last == std::string::npos ? 0 : last + 1);
  EXPECT_EQ(last_line.rfind("rigcal: error: lidar_camera: ", 0), 0u) << bad.err;
  EXPECT_NE(last_line.find("(nothing published)\n"), std::string::npos) << bad.err;
  for (const char* step : {"cameras", "time_sync", "hand_eye"}) {
    EXPECT_NE(bad.out.find(fmt::format("== {}: ok", step)), std::string::npos) << bad.out;
    // The kept steps' reports say so: the JSON parses, status ok.
    const fs::path json = out / "reports" / step / fmt::format("{}.json", step);
    ASSERT_TRUE(fs::exists(json)) << step;
    EXPECT_EQ(nlohmann::json::parse(slurp(json))["status"], "ok") << step;
  }
  // The page a person reads says so first, and names the failed step's reason.
  const std::string bad_page = slurp(out / "report.html");
  EXPECT_NE(bad_page.find("Nothing published: lidar_camera failed"), std::string::npos);

  fs::remove_all(images);
  fs::copy(kept, images);
  const CliRun fixed = rigcal_cli(args, dir_);
  ASSERT_EQ(fixed.status, 0) << fixed.out << fixed.err;
  EXPECT_NE(fixed.out.find("== lidar_camera: ok\n"), std::string::npos) << fixed.out;
  for (const char* step : {"cameras", "time_sync", "hand_eye"})
    EXPECT_NE(fixed.out.find(fmt::format("== {}: ok (cached", step)), std::string::npos) << step;
  std::printf("[ figures ] failing run %.1f s, rerun after the fix %.1f s\n", bad.seconds,
              fixed.seconds);
  // One page: the verdict, each step's section with its numbers and figures (the cached steps'
  // from their stored reports), rendered again the same from OUT/reports/ alone.
  const std::string page = slurp(out / "report.html");
  EXPECT_NE(page.find("Published <code>"), std::string::npos);
  for (const char* id : {"id=\"steps\"", "id=\"step-cameras\"", "id=\"step-lidar_camera\"",
                         "id=\"step-time_sync\"", "id=\"step-hand_eye\""})
    EXPECT_NE(page.find(id), std::string::npos) << id;
  for (const char* text : {"cam_l: inlier corners' |residual|, RMS", "cam_r: residual vectors",
                           "<b>T_cam_r_lidar</b>", "The offset in each window",
                           "<b>T_gnss_lidar</b>", "Each pair's chi-square", "data:image/jpeg"})
    EXPECT_NE(page.find(text), std::string::npos) << text;
  EXPECT_EQ(page.find("roll"), std::string::npos) << "rotations as angle and axis only";
  EXPECT_LT(page.size(), 8u << 20) << "the camera images scaled down";
  fs::remove(out / "report.html");
  const CliRun again = rigcal_cli(fmt::format("report {}", out.string()), dir_);
  EXPECT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(slurp(out / "report.html"), page);
  if (testing::have_chromium()) {
    const testing::BrowserLoad load =
        testing::load_in_browser(out / "report.html", dir_ / "calibrate.png");
    EXPECT_TRUE(load.ran) << load.log;
    EXPECT_EQ(testing::console_messages(load.log), "");
    EXPECT_NE(load.dom.find("id=\"step-hand_eye\""), std::string::npos);
    EXPECT_GT(load.screenshot_bytes, 20000u);
  }

  // The calibration against the truth, sensor by sensor, at the bars of the steps' issues.
  const rig::Rig cal = rig::read_rig_file(out / "calib.yaml");
  const rig::Rig truth = rig::read_rig_file(kTruth);
  const std::vector<session::StepRecord> steps = session::read_steps(cal);
  ASSERT_EQ(steps.size(), 4u);
  // Each estimated pose and lens stored with its correlations: a correlation matrix over keys
  // the step stored sigmas under (cameras: two lenses and the stereo pose; LiDAR-camera and
  // hand-eye: their pose).
  size_t matrices = 0;
  for (const session::StepRecord& s : steps) {
    for (const report::Correlation& c : s.correlations) {
      ++matrices;
      const size_t n = c.names.size();
      ASSERT_EQ(c.rho.size(), n * n) << c.name;
      Eigen::MatrixXd rho(n, n);
      for (size_t i = 0; i < n; ++i) {
        const bool stored =
            std::any_of(s.sigmas.begin(), s.sigmas.end(),
                        [&](const report::Figure& f) { return f.name == c.names[i]; });
        EXPECT_TRUE(stored) << c.names[i];
        for (size_t j = 0; j < n; ++j) rho(i, j) = c.rho[i * n + j];
      }
      EXPECT_LT((rho - rho.transpose()).norm(), 1e-12) << c.name;
      EXPECT_LT((rho.diagonal().array() - 1).abs().maxCoeff(), 1e-12) << c.name;
      EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(rho).eigenvalues().minCoeff(), -1e-5)
          << c.name;
    }
  }
  EXPECT_EQ(matrices, 5u);
  auto sigma = [&](const std::string& step, const std::string& key) -> double {
    for (const session::StepRecord& s : steps) {
      for (const report::Figure& f : s.sigmas) {
        if (s.step == step && f.name == key) return f.value;
      }
    }
    ADD_FAILURE() << step << " has no sigma " << key;
    return NAN;
  };
  for (const char* cam : {"cam_l", "cam_r"}) {
    const rig::CameraModel &m = rig::sensor(cal, cam).camera, &t = rig::sensor(truth, cam).camera;
    // Each intrinsic within 3 of its reported sigmas (the camera issue's statistical bar; its
    // principal-point bar asks more than the data determine, doc/cameras.md).
    const double est[] = {m.fx, m.fy, m.cx, m.cy}, tru[] = {t.fx, t.fy, t.cx, t.cy};
    const char* names[] = {"fx", "fy", "cx", "cy"};
    for (int i = 0; i < 4; ++i) {
      const double s = sigma("cameras", fmt::format("{}.{}_px", cam, names[i]));
      EXPECT_LT(std::abs(est[i] - tru[i]), 3 * s) << cam << "." << names[i];
      std::printf("[ figures ] %s.%s error %.3f px, 1-sigma %.3f px\n", cam, names[i],
                  est[i] - tru[i], s);
    }
  }
  const double baseline_err =
      rig::T_a_b(cal, "cam_r", "cam_l").t.norm() - rig::T_a_b(truth, "cam_r", "cam_l").t.norm();
  EXPECT_LT(std::abs(baseline_err), 2e-4) << "baseline";  // the camera issue: 0.2 mm
  // LiDAR-camera: rotation <= 0.1 deg, translation <= 5 mm (both cameras: the left follows).
  for (const char* cam : {"cam_r", "cam_l"}) {
    const SE3 e = rig::T_a_b(cal, cam, "lidar"), t = rig::T_a_b(truth, cam, "lidar");
    EXPECT_LT(rotation_error_deg(e, t), 0.1) << cam;
    EXPECT_LT((e.t - t.t).norm(), 0.005) << cam;
    std::printf("[ figures ] T_%s_lidar error %.4f deg, %.2f mm\n", cam, rotation_error_deg(e, t),
                1e3 * (e.t - t.t).norm());
  }
  // Clock offsets: the IMU's within 0.5 ms, the GNSS/INS's within 1 ms.
  EXPECT_LT(std::abs(rig::sensor(cal, "imu").time_offset - rig::sensor(truth, "imu").time_offset),
            5e-4);
  EXPECT_LT(std::abs(rig::sensor(cal, "gnss").time_offset - rig::sensor(truth, "gnss").time_offset),
            1e-3);
  // Hand-eye, hand-held: rotation <= 0.05 deg, translation <= 1 cm; the INS's own IMU moved with
  // it (one rigid body).
  const SE3 e = rig::T_a_b(cal, "gnss", "lidar"), t = rig::T_a_b(truth, "gnss", "lidar");
  EXPECT_LT(rotation_error_deg(e, t), 0.05);
  EXPECT_LT((e.t - t.t).norm(), 0.01);
  std::printf("[ figures ] T_gnss_lidar error %.4f deg, %.2f mm\n", rotation_error_deg(e, t),
              1e3 * (e.t - t.t).norm());
  EXPECT_TRUE(rig::T_a_b(cal, "gnss", "imu")
                  .matrix()
                  .isApprox(rig::T_a_b(rig::read_rig_file(kPrior), "gnss", "imu").matrix(), 1e-12));
  // Provenance: every step's inputs with their hashes, the tool version.
  for (const session::StepRecord& s : steps) {
    EXPECT_EQ(s.status, "ok");
    EXPECT_FALSE(s.inputs.empty()) << s.step;
    for (const session::HashedInput& in : s.inputs) EXPECT_EQ(in.sha256.size(), 64u) << s.step;
    EXPECT_EQ(s.tool_version.rfind("rigcal ", 0), 0u);
  }
  const CliRun show = rigcal_cli(fmt::format("rig show {}", (out / "calib.yaml").string()), dir_);
  EXPECT_EQ(show.status, 0);
  EXPECT_NE(show.out.find("Provenance"), std::string::npos);

  // Publishing: every sequence gets vbr_calib.yaml with the hash; a second run changes nothing;
  // another calibration is refused without --force, and then nothing at all is written.
  const fs::path seq_a = dir_ / "vbr" / "campus" / "campus_train0",
                 seq_b = dir_ / "vbr" / "campus" / "campus_train1";
  fs::create_directories(seq_a);
  fs::create_directories(seq_b);
  const std::string publish =
      fmt::format("publish {} {} {} --formats vbr,kalibr,opencv", (out / "calib.yaml").string(),
                  seq_a.string(), seq_b.string());
  const CliRun p1 = rigcal_cli(publish, dir_);
  ASSERT_EQ(p1.status, 0) << p1.err;
  EXPECT_NE(p1.out.find("drops: clock offsets"), std::string::npos) << p1.out;
  const rig::Rig vbr = rig::read_rig_file(seq_a / "vbr_calib.yaml");
  EXPECT_TRUE(rig::T_a_b(vbr, "cam_r", "lidar")
                  .matrix()
                  .isApprox(rig::T_a_b(cal, "cam_r", "lidar").matrix(), 1e-12));
  EXPECT_EQ(session::published_hash(seq_b / "vbr_calib.yaml").size(), 64u);
  EXPECT_EQ(slurp(seq_b / "opencv_stereo.yaml").rfind("%YAML:1.0\n# rigcal calibration", 0), 0u);
  const CliRun p2 = rigcal_cli(publish, dir_);
  EXPECT_EQ(p2.status, 0);
  EXPECT_NE(p2.out.find("holds this calibration already"), std::string::npos) << p2.out;
  const CliRun other = rigcal_cli(
      fmt::format("publish {} {} {}", kTruth, seq_a.string(), (dir_ / "vbr" / "campus").string()),
      dir_);
  EXPECT_EQ(other.status, 2);
  EXPECT_NE(other.err.find("--force"), std::string::npos) << other.err;
  EXPECT_FALSE(fs::exists(dir_ / "vbr" / "campus" / "vbr_calib.yaml"));
}

// The cache: unchanged inputs reuse a step; an option or a rig entry it reads reruns it alone;
// a failed run removes an earlier calibration from the output folder.
TEST_F(Session, TheCacheRerunsWhatChanged) {
  const fs::path session = motion_session(), out = dir_ / "calibration";
  const std::string base =
      fmt::format("calibrate {} --out {} --rig {}", session.string(), out.string(), kPrior);
  const CliRun first = rigcal_cli(base, dir_);
  EXPECT_EQ(first.status, 2);  // no stereo or LiDAR-camera recording: those steps fail
  EXPECT_NE(first.out.find("== time_sync: ok\n"), std::string::npos) << first.out;
  EXPECT_NE(first.out.find("== hand_eye: ok\n"), std::string::npos) << first.out;
  const CliRun option = rigcal_cli(base + " --no-estimate-offset", dir_);
  EXPECT_NE(option.out.find("== time_sync: ok (cached"), std::string::npos) << option.out;
  EXPECT_NE(option.out.find("== hand_eye: ok\n"), std::string::npos) << option.out;
  // A prior whose GNSS/INS sits elsewhere: hand-eye reads it (its held directions), time_sync not.
  std::string prior = slurp(kPrior);
  prior.replace(prior.find("[1.0, 0.0, 0.0, -0.05]", prior.find("gnss:")), 22,
                "[1.0, 0.0, 0.0, -0.06]");
  io::write_file_atomic(dir_ / "prior.yaml", prior);
  const CliRun rig_changed =
      rigcal_cli(fmt::format("calibrate {} --out {} --rig {}", session.string(), out.string(),
                             (dir_ / "prior.yaml").string()),
                 dir_);
  EXPECT_NE(rig_changed.out.find("== time_sync: ok (cached"), std::string::npos) << rig_changed.out;
  EXPECT_NE(rig_changed.out.find("== hand_eye: ok\n"), std::string::npos) << rig_changed.out;
  // An earlier calibration in the folder is removed when this run publishes nothing.
  io::write_file_atomic(out / "calib.yaml", slurp(kPrior));
  const CliRun again = rigcal_cli(base, dir_);
  EXPECT_EQ(again.status, 2);
  EXPECT_FALSE(fs::exists(out / "calib.yaml"));
  EXPECT_NE(again.out.find("removed " + (out / "calib.yaml").string()), std::string::npos)
      << again.out;
}

// The cameras step reuses its detections only on the very images it found them in.
TEST_F(Session, DetectionsAreReusedOnlyOnTheSameImages) {
  const fs::path session = simulate_devkit_session(dir_, "stereo", "stereo:\n  views: 8\n");
  const fs::path out = dir_ / "calibration";
  const std::string args = fmt::format("calibrate {} --out {} --rig {} --only cameras",
                                       session.string(), out.string(), kPrior);
  const CliRun first = rigcal_cli(args, dir_);
  ASSERT_EQ(first.status, 0) << first.err;
  const CliRun same = rigcal_cli(args, dir_);  // forced by --only, the same images
  EXPECT_NE(same.out.find("from " + (out / "reports" / "cameras" / "corners.vnl").string()),
            std::string::npos)
      << same.out;
  // The same file names, the images shifted 20 px to the right: detected again.
  for (const char* cam : {"camera_left", "camera_right"}) {
    for (const fs::directory_entry& e : fs::directory_iterator(session / "stereo" / cam / "data")) {
      const cv::Mat img = cv::imread(e.path().string());
      cv::Mat shifted;
      const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 20, 0, 1, 0);
      cv::warpAffine(img, shifted, shift, img.size(), cv::INTER_NEAREST, cv::BORDER_REPLICATE);
      cv::imwrite(e.path().string(), shifted);
    }
  }
  const CliRun moved = rigcal_cli(args, dir_);
  ASSERT_EQ(moved.status, 0) << moved.err;
  EXPECT_EQ(moved.out.find("corners.vnl)"), std::string::npos) << moved.out;
  // A prior rig without cam_r: the step adds it, the run goes on.
  std::string prior = slurp(kPrior);
  const size_t from = prior.find("cam_r:"), to = prior.find("lidar:");
  io::write_file_atomic(dir_ / "no_cam_r.yaml", prior.erase(from, to - from));
  const CliRun added =
      rigcal_cli(fmt::format("calibrate {} --out {} --rig {} --only cameras", session.string(),
                             out.string(), (dir_ / "no_cam_r.yaml").string()),
                 dir_);
  EXPECT_EQ(added.status, 0) << added.err;
  EXPECT_NE(added.out.find("== cameras: ok"), std::string::npos) << added.out;
}

// --only and --from, and a step the data do not determine (exit 3), on the motion recording.
TEST_F(Session, OnlyFromAndAnUndeterminedStep) {
  const fs::path session = motion_session(), out = dir_ / "calibration";
  const std::string base =
      fmt::format("calibrate {} --out {} --rig {}", session.string(), out.string(), kPrior);
  const CliRun only = rigcal_cli(base + " --only time_sync", dir_);
  EXPECT_EQ(only.status, 0) << only.err;
  EXPECT_NE(only.out.find("== time_sync: ok"), std::string::npos) << only.out;
  EXPECT_EQ(only.out.find("== cameras"), std::string::npos) << only.out;
  EXPECT_NE(only.out.find("nothing published: cameras, lidar_camera, hand_eye not run"),
            std::string::npos)
      << only.out;
  EXPECT_FALSE(fs::exists(out / "calib.yaml"));
  // hand_eye alone: time_sync comes from the cache.
  const CliRun he = rigcal_cli(base + " --only hand_eye", dir_);
  EXPECT_EQ(he.status, 0) << he.err;
  EXPECT_NE(he.out.find("== time_sync: ok (cached"), std::string::npos) << he.out;
  EXPECT_NE(he.out.find("== hand_eye: ok\n"), std::string::npos) << he.out;
  // --from needs the earlier steps cached.
  const CliRun from = rigcal_cli(base + " --from hand_eye", dir_);
  EXPECT_EQ(from.status, 2);
  EXPECT_NE(from.err.find("--from hand_eye: the earlier step cameras has no cached result"),
            std::string::npos)
      << from.err;
  EXPECT_NE(from.err.find("it cannot run: session"), std::string::npos) << from.err;
  const CliRun bad_step = rigcal_cli(base + " --only handeye", dir_);
  EXPECT_EQ(bad_step.status, 2);
  EXPECT_NE(bad_step.err.find("the steps are cameras, lidar_camera, time_sync, hand_eye"),
            std::string::npos)
      << bad_step.err;
  // The external IMU held still: no offset, said as undetermined with the remedy, exit 3.
  std::string imu = slurp(session / "imu" / "data" / "imu.txt");
  std::string still = imu.substr(0, imu.find('\n') + 1);
  const std::string row = "0.0,0.0,9.81,0.001,-0.002,0.0005,1.0,0.0,0.0,0.0";
  size_t lines = 0;
  for (char c : imu) lines += c == '\n';
  for (size_t k = 1; k < lines; ++k) {
    still += row;
    for (int i = 0; i < 27; ++i) still += ",0.0";
    still += "\n";
  }
  io::write_file_atomic(session / "imu" / "data" / "imu.txt", still);
  const CliRun u = rigcal_cli(base + " --only time_sync", dir_);
  EXPECT_EQ(u.status, 3) << u.out << u.err;
  EXPECT_NE(u.out.find("== time_sync: undetermined"), std::string::npos) << u.out;
  EXPECT_NE(u.out.find("not enough excitation"), std::string::npos) << u.out;
  EXPECT_NE(u.out.find("what would settle it: record the two IMUs"), std::string::npos) << u.out;
}

// No odometry file: hand-eye runs rigcal's own odometry on the motion recording's sweeps (the
// devkit's layout, a 20 s walk through a courtyard, OS0-128 at 1024 columns, each sweep's motion
// estimated) and estimates from it what `rigcal hand-eye` estimates from the trajectory it
// writes; the GNSS/INS lands where the truth has it, within the step's own 3 sigma.
TEST_F(Session, HandEyeRunsRigcalsOdometryOnTheMotionScans) {
  const fs::path session = simulate_devkit_session(
      dir_, "trajectories",
      "trajectories:\n  duration_s: 20\n  motion: walk\n  scans: true\nlidar:\n  columns: 1024\n");
  EXPECT_EQ(slurp(session / "session.yaml").find("odometry:"), std::string::npos);
  const fs::path out = dir_ / "calibration";
  const CliRun he = rigcal_cli(fmt::format("calibrate {} --out {} --rig {} --only hand_eye",
                                           session.string(), out.string(), kPrior),
                               dir_);
  ASSERT_EQ(he.status, 0) << he.out << he.err;
  EXPECT_NE(he.out.find("== hand_eye: ok"), std::string::npos) << he.out;
  EXPECT_NE(he.out.find("LiDAR odometry (rigcal's, preset os0-128, each sweep's motion): 201 scans "
                        "registered of 201"),
            std::string::npos)
      << he.out;
  const fs::path report = out / "reports" / "hand_eye";
  for (const char* f :
       {"hand_eye.json", "lidar_odometry.tum", "lidar_odometry_covariances.txt", "odometry.json"})
    EXPECT_TRUE(fs::exists(report / f)) << f;
  const nlohmann::json j = nlohmann::json::parse(slurp(report / "hand_eye.json"));
  EXPECT_NE(j["inputs"]["lidar"].get<std::string>().find("rigcal's odometry on"),
            std::string::npos);
  auto T_gnss_lidar = [](const nlohmann::json& r) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 4; ++b) m(a, b) = r["T_gnss_lidar"]["matrix"][a][b].get<double>();
    return SE3::from_matrix(m);
  };
  // The same estimate from the written trajectory through `rigcal hand-eye`.
  const CliRun alone =
      rigcal_cli(fmt::format("hand-eye --lidar {} --gnss {} --rig {} --estimate-offset --report {}",
                             (report / "lidar_odometry.tum").string(),
                             (session / "trajectories" / "gnss_ins.tum").string(), kPrior,
                             (dir_ / "alone").string()),
                 dir_);
  ASSERT_EQ(alone.status, 0) << alone.err;
  const SE3 e = T_gnss_lidar(j);
  const SE3 e_alone = T_gnss_lidar(nlohmann::json::parse(slurp(dir_ / "alone" / "hand_eye.json")));
  EXPECT_LT((e.t - e_alone.t).norm(), 1e-9);
  EXPECT_LT(rotation_error_deg(e, e_alone), 1e-7);
  // The odometry's steps against the truth, and the extrinsic.
  const Trajectory odom = io::read_trajectory(report / "lidar_odometry.tum").trajectory;
  const Trajectory truth =
      io::read_trajectory(session / "trajectories" / "truth_lidar.tum").trajectory;
  ASSERT_EQ(odom.size(), truth.size());
  Eigen::Vector3d sq = Eigen::Vector3d::Zero();
  for (size_t k = 1; k < truth.size(); ++k) {
    const SE3 d = (truth.T_world_body[k - 1].inverse() * truth.T_world_body[k]).inverse() *
                  (odom.T_world_body[k - 1].inverse() * odom.T_world_body[k]);
    sq += d.t.cwiseAbs2();
  }
  const Eigen::Vector3d step_rms = (sq / double(truth.size() - 1)).cwiseSqrt();
  EXPECT_LT(step_rms.maxCoeff(), 0.003);
  const SE3 t = rig::T_a_b(rig::read_rig_file(kTruth), "gnss", "lidar");
  for (int a = 0; a < 3; ++a) {
    const double sigma = j["T_gnss_lidar"]["t_sigma_m"][a].get<double>();
    EXPECT_LT(std::abs((e.t - t.t)[a]), 3 * sigma) << "axis " << a << ", sigma " << sigma;
  }
  EXPECT_LT(rotation_error_deg(e, t), 0.1);
  EXPECT_LT((e.t - t.t).norm(), 0.01);
  std::printf(
      "[ figures ] walk, rigcal's odometry: step error rms %.1f %.1f %.1f mm (x y z); "
      "T_gnss_lidar error %.3f deg, [%.1f %.1f %.1f] mm, sigmas [%.1f %.1f %.1f] mm\n",
      1e3 * step_rms.x(), 1e3 * step_rms.y(), 1e3 * step_rms.z(), rotation_error_deg(e, t),
      1e3 * (e.t - t.t).x(), 1e3 * (e.t - t.t).y(), 1e3 * (e.t - t.t).z(),
      1e3 * j["T_gnss_lidar"]["t_sigma_m"][0].get<double>(),
      1e3 * j["T_gnss_lidar"]["t_sigma_m"][1].get<double>(),
      1e3 * j["T_gnss_lidar"]["t_sigma_m"][2].get<double>());
}

// A recording in the devkit layout as the messages the rig's drivers publish, under the topic
// names vbr-devkit maps back to the same folders: images as stored (bgr8, mono8 or mono16), the
// Ouster driver's point records, the gyro logs.
testing::bag::Recording recording_messages(const fs::path& recording) {
  const std::map<std::string, std::string> topics = {{"camera_left", "/camera_left/image_raw"},
                                                     {"camera_right", "/camera_right/image_raw"},
                                                     {"ouster_points", "/ouster/points"},
                                                     {"imu", "/imu/data"},
                                                     {"ouster_imu", "/ouster/imu"}};
  testing::bag::Recording r;
  for (const auto& [folder, topic] : topics) {
    const fs::path d = recording / folder;
    if (!fs::exists(d / "timestamps.txt")) continue;
    if (fs::exists(d / "data" / "imu.txt")) {
      const io::RateFile f = io::read_rates(d);
      testing::bag::ImuTopic t{topic, {}, {}};
      for (size_t k = 0; k < f.rates.stamps.size(); ++k) {
        t.stamps_ns.push_back(f.rates.stamps[k].ns);
        t.gyro.push_back({f.rates.rates[k].x(), f.rates.rates[k].y(), f.rates.rates[k].z()});
      }
      r.imus.push_back(std::move(t));
    } else if (folder == "ouster_points") {
      const io::StampedFolder s = io::read_stamped_folder(d, ".bin");
      for (size_t k = 0; k < s.files.size(); ++k) {
        const std::string bytes = slurp(s.files[k]);
        r.clouds.push_back({topic, s.stamps[k].ns, {bytes.begin(), bytes.end()}});
      }
    } else {
      const io::StampedFolder s = io::read_stamped_folder(d, ".png");
      for (size_t k = 0; k < s.files.size(); ++k) {
        const cv::Mat img = cv::imread(s.files[k], cv::IMREAD_UNCHANGED);
        if (img.empty() || !img.isContinuous())
          throw std::runtime_error("cannot read " + s.files[k]);
        const std::string encoding = img.channels() == 3     ? "bgr8"
                                     : img.depth() == CV_16U ? "mono16"
                                                             : "mono8";
        r.images.push_back({topic,
                            s.stamps[k].ns,
                            img.cols,
                            img.rows,
                            encoding,
                            {img.data, img.data + img.total() * img.elemSize()}});
      }
    }
  }
  return r;
}

// The whole session as the rig records it: its three recordings written as ROS1 bags, each split
// in an LZ4 and a BZ2 bag. `rigcal calibrate` on the folders of bags directly gives the
// calibration it gives on their `rigcal convert` conversions and on the original folders, to the
// last digit of every value; the provenance names the folders of bags; nothing is left in TMPDIR.
TEST_F(Session, CalibrateOnBagsIsCalibrateOnTheirConversionAndOnTheFolders) {
  const fs::path original = small_session();
  const fs::path bags = dir_ / "bags", converted = dir_ / "converted", tmp = dir_ / "tmp";
  fs::create_directories(tmp);
  const std::string session_yaml =
      "target: target.yaml\ncameras: stereo\nlidar_camera: lidar_camera\nmotion: motion\n"
      "odometry: trajectories/lidar_odometry.tum\ngnss: trajectories/gnss_ins.tum\n";
  for (const fs::path& root : {bags, converted}) {
    fs::create_directories(root / "trajectories");
    fs::copy_file(original / "target.yaml", root / "target.yaml");
    for (const char* t : {"lidar_odometry.tum", "gnss_ins.tum"})
      fs::copy_file(original / "trajectories" / t, root / "trajectories" / t);
    std::ofstream(root / "session.yaml") << session_yaml;
  }
  for (const std::string rec : {"stereo", "lidar_camera", "motion"}) {
    fs::create_directories(bags / rec);
    const testing::bag::Recording messages =
        recording_messages(rec == "motion" ? original : original / rec);
    ASSERT_FALSE(messages.images.empty() && messages.clouds.empty() && messages.imus.empty())
        << rec;
    testing::bag::write_split_bags((bags / rec / rec).string(), messages);
    const CliRun c = rigcal_cli(fmt::format("convert {0}/{1}_0.bag {0}/{1}_1.bag --out {2}",
                                            (bags / rec).string(), rec, (converted / rec).string()),
                                dir_);
    ASSERT_EQ(c.status, 0) << c.out << c.err;
  }
  auto calibrate = [&](const fs::path& session, const std::string& name) {
    const fs::path out = dir_ / ("out_" + name);
    const CliRun r = rigcal_cli(
        fmt::format("calibrate {} --out {} --rig {}", session.string(), out.string(), kPrior), dir_,
        fmt::format("TMPDIR={}", tmp.string()));
    EXPECT_EQ(r.status, 0) << name << "\n" << r.out << r.err;
    std::printf("[ figures ] calibrate on the %s: %.1f s\n", name.c_str(), r.seconds);
    return slurp(out / "calib.yaml");
  };
  const std::string on_bags = calibrate(bags, "bags");
  EXPECT_TRUE(fs::is_empty(tmp));
  const std::string on_conversion = calibrate(converted, "conversion");
  const std::string on_original = calibrate(original, "original");
  // Everything before the provenance: every sensor's values as printed.
  auto values = [](const std::string& yaml) { return yaml.substr(0, yaml.find("\nrigcal:")); };
  ASSERT_NE(values(on_bags).find("T_b"), std::string::npos) << on_bags;
  EXPECT_EQ(values(on_bags), values(on_conversion));
  EXPECT_EQ(values(on_bags), values(on_original));
  // The inputs as the user knows them: the folder of bags and the topic in it, not $TMPDIR.
  for (const fs::path& p :
       {bags / "stereo" / "camera_left", bags / "lidar_camera" / "ouster_points",
        bags / "motion" / "ouster_imu"})
    EXPECT_NE(on_bags.find("path: " + p.string() + ","), std::string::npos) << p << "\n" << on_bags;
  EXPECT_EQ(on_bags.find(tmp.string()), std::string::npos) << on_bags;
}

TEST(Publish, RefusesAnUnknownCalibrationAndReplacesWithForce) {
  const fs::path dir = fs::temp_directory_path() / fmt::format("rigcal_publish_{}", ::getpid());
  fs::remove_all(dir);
  fs::create_directories(dir / "seq");
  std::ofstream(dir / "seq" / "vbr_calib.yaml") << slurp(kTruth);  // the dataset's own file
  EXPECT_THROW(session::publish(kPrior, {dir / "seq"}, {}), Error);
  EXPECT_EQ(slurp(dir / "seq" / "vbr_calib.yaml"), slurp(kTruth));
  session::PublishOptions force;
  force.force = true;
  const session::PublishResult r = session::publish(kPrior, {dir / "seq"}, force);
  ASSERT_EQ(r.sequences.size(), 1u);
  EXPECT_EQ(r.sequences[0].state, "replaced");
  EXPECT_EQ(session::published_hash(dir / "seq" / "vbr_calib.yaml"), r.sha256);
  EXPECT_THROW(session::publish(kPrior, {dir / "absent"}, {}), Error);
  // File by file: more formats later add only the new files; a foreign export is refused.
  session::PublishOptions kalibr;
  kalibr.formats = {rig::ExportFormat::vbr, rig::ExportFormat::kalibr};
  const session::PublishResult more = session::publish(kPrior, {dir / "seq"}, kalibr);
  ASSERT_EQ(more.sequences[0].files.size(), 1u);
  EXPECT_EQ(more.sequences[0].files[0].filename(), "camchain-imucam.yaml");
  fs::create_directories(dir / "seq2");
  std::ofstream(dir / "seq2" / "camchain-imucam.yaml") << "cam0: {}\n";
  EXPECT_THROW(session::publish(kPrior, {dir / "seq2"}, kalibr), Error);
  EXPECT_FALSE(fs::exists(dir / "seq2" / "vbr_calib.yaml"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rigcal

namespace rigcal {
namespace {

// FIPS 180-4 examples, and a file hashed in pieces against the same bytes at once.
TEST(Sha256, KnownVectorsAndFiles) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
  const fs::path file = fs::temp_directory_path() / fmt::format("rigcal_sha_{}", ::getpid());
  std::string bytes;
  for (uint64_t i = 0; i < 3'000'000; ++i) bytes += static_cast<char>(i * 7919 % 251);
  io::write_file_atomic(file, bytes);
  EXPECT_EQ(sha256_file(file), sha256_hex(bytes));
  fs::remove(file);
  EXPECT_THROW(sha256_file(file), Error);
}

}  // namespace
}  // namespace rigcal
