// The command line as a user runs it: exit statuses, one-line errors, nothing written on failure.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <GeographicLib/LocalCartesian.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "fixtures.h"
#include "rigcal/core/stats.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/rig/rig_yaml.h"

namespace {

namespace fs = std::filesystem;

struct CliRun {
  int status = -1;
  std::string out, err;
};

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rigcal_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  CliRun run(const std::string& args) {
    const std::string cmd = std::string(RIGCAL_CLI) + " " + args + " > " +
                            (dir_ / "stdout").string() + " 2> " + (dir_ / "stderr").string();
    const int raw = std::system(cmd.c_str());
    CliRun r;
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(dir_ / "stdout");
    r.err = slurp(dir_ / "stderr");
    fs::remove(dir_ / "stdout");
    fs::remove(dir_ / "stderr");
    return r;
  }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  fs::path dir_;
};

const std::string kSample = RIGCAL_SOURCE_DIR "/data/sample_rig.yaml";

TEST_F(Cli, HelpAndVersionExitZero) {
  CliRun r = run("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("rig"), std::string::npos);
  r = run("--version");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out.rfind("rigcal 0.", 0), 0u) << r.out;
  r = run("rig convert --help");
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("mrcal"), std::string::npos);
}

TEST_F(Cli, UsageErrorsExitTwo) {
  EXPECT_EQ(run("").status, 2);
  EXPECT_EQ(run("rig").status, 2);
  EXPECT_EQ(run("rig validate").status, 2);
  EXPECT_EQ(run("--no-such-option").status, 2);
}

TEST_F(Cli, ValidateAndShow) {
  CliRun r = run("rig validate " + kSample);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("valid, 6 sensors"), std::string::npos) << r.out;
  r = run("rig show " + kSample);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("baseline 0.4985 m"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("roll"), std::string::npos);
}

TEST_F(Cli, BadInputIsOneLineNamingFileLineAndKeyWithExitTwo) {
  const fs::path bad =
      write("bad.yaml",
            "cam_l:\n  intrinsics: [0, 100, 10, 10]\n  distortion_coeffs: [0, 0, 0, 0]\n"
            "  resolution: [20, 20]\n  T_b: [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]\n");
  const CliRun r = run("rig validate " + bad.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "rigcal: error: " + bad.string() +
                       ":2: key 'cam_l.intrinsics': focal lengths fx, fy must be > 0 and at most "
                       "1000000 px, got fx = 0, "
                       "fy = 100\n");
  EXPECT_TRUE(r.out.empty());
  const CliRun missing = run("rig show " + (dir_ / "nope.yaml").string());
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.err.find("nope.yaml: cannot open"), std::string::npos) << missing.err;
}

TEST_F(Cli, ConvertWritesEveryFormatAndNothingOnFailure) {
  for (const char* to : {"rigcal", "vbr", "kalibr", "opencv"}) {
    const fs::path out = dir_ / (std::string(to) + ".yaml");
    const CliRun r = run("rig convert " + kSample + " --to " + to + " --out " + out.string());
    EXPECT_EQ(r.status, 0) << to << ": " << r.err;
    EXPECT_TRUE(fs::exists(out)) << to;
  }
  // The rigcal export of the sample is itself a valid rig.
  EXPECT_EQ(run("rig validate " + (dir_ / "rigcal.yaml").string()).status, 0);
  for (const char* to : {"ros", "mrcal"}) {
    const CliRun r =
        run("rig convert " + kSample + " --to " + to + " --out " + (dir_ / to).string());
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(std::distance(fs::directory_iterator(dir_ / to), fs::directory_iterator()), 2);
  }
  // Unknown format, and a rig that mrcal cannot express: exit 2, no output at all.
  CliRun r = run("rig convert " + kSample + " --to matlab --out " + (dir_ / "m.yaml").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("unknown export format 'matlab'"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "m.yaml"));
  std::string text = slurp(kSample);
  const size_t at = text.find("distortion_model: radtan", text.find("cam_r:"));
  text.replace(at, 24, "distortion_model: equidistant");
  const fs::path fisheye = write("fisheye.yaml", text);
  r = run("rig convert " + fisheye.string() + " --to mrcal --out " + (dir_ / "mr").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("cam_r: mrcal 2.2 has no equidistant"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "mr" / "cam_l.cameramodel"));
}

// A helix: `drift` scales the estimate's path, `offset` shifts its stamps (s).
std::string helix_tum(int n, double drift, double offset) {
  std::string out;
  for (int i = 0; i < n; ++i) {
    const double s = 0.1 * i;
    out += fmt::format("{:.9f} {} {} {} 0 0 {} {}\n", 1000.0 + s + offset,
                       (1 + drift) * 3 * std::cos(0.05 * s) * s,
                       (1 + drift) * 3 * std::sin(0.05 * s) * s, 0.01 * s, std::sin(0.025 * s),
                       std::cos(0.025 * s));
  }
  return out;
}

TEST_F(Cli, BenchPrintsTableWritesReportAndRefusesBadFiles) {
  const fs::path gt = write("seq_gt.txt", helix_tum(2000, 0.0, 0.0));
  const fs::path est = write("seq_es.txt", helix_tum(2000, 0.01, 0.004));
  CliRun r = run("bench --gt " + gt.string() + " --est " + est.string() + " --report " +
                 (dir_ / "rep").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("ATE"), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(slurp(dir_ / "rep" / "bench.json"));
  EXPECT_EQ(j["convention"], "rigcal");
  EXPECT_EQ(j["n_pairs"], 1999);  // stamps 4 ms late: the last one is past the GT's end
  for (const char* key : {"rmse", "mean", "median", "std", "min", "max"}) {
    EXPECT_TRUE(j["ate"]["trans"].contains(key)) << key;
    EXPECT_TRUE(j["ate"]["rot"].contains(key)) << key;
  }
  // Positions scaled by 1.01: each segment errs by 1 % of its chord, which on this spiral is
  // shorter than the path length the drift divides by: between 0.8 and 1 %.
  const double drift = j["rpe"]["vbr"]["trans_pct"].get<double>();
  EXPECT_GT(drift, 0.8);
  EXPECT_LE(drift, 1.0 + 1e-9);
  EXPECT_TRUE(j["rpe"]["kitti"].contains("rot_deg_per_m"));
  EXPECT_EQ(j["align"]["T"].size(), 4u);
  EXPECT_TRUE(fs::exists(dir_ / "rep" / "trajectory_top.svg"));
  EXPECT_TRUE(fs::exists(dir_ / "rep" / "ate_along.svg"));

  const fs::path bad = write("bad.txt", "1 0 0 0 0 0 0 1\n2 0 0 0 0 0 0 1\n1.5 0 0 0 0 0 0 1\n");
  r = run("bench --gt " + gt.string() + " --est " + bad.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "rigcal: error: " + bad.string() +
                       ":3: stamp 1.5 is before the previous one (2.000000000 s, line 2); stamps "
                       "must increase\n");
  const fs::path nan = write("nan.txt", "1 0 0 nan 0 0 0 1\n");
  r = run("bench --gt " + gt.string() + " --est " + nan.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("nan.txt:1: field 4 (tz)"), std::string::npos) << r.err;
  const fs::path later = write("later.txt", helix_tum(10, 0.0, 5000.0));
  r = run("bench --gt " + gt.string() + " --est " + later.string() + " --report " +
          (dir_ / "none").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("do not overlap in time"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "none"));
  EXPECT_EQ(run("bench --gt " + gt.string()).status, 2);
  EXPECT_EQ(
      run("bench --gt " + gt.string() + " --est " + est.string() + " --convention foo").status, 2);
}

TEST_F(Cli, BenchLeaderboardCountsMissingSequencesAsFailed) {
  fs::create_directories(dir_ / "gt");
  fs::create_directories(dir_ / "est" / "good");
  fs::create_directories(dir_ / "est" / "poor");
  for (const char* seq : {"a", "b"}) {
    write(std::string("gt/") + seq + "_gt.txt", helix_tum(1500, 0.0, 0.0));
    write(std::string("est/good/") + seq + "_es.txt", helix_tum(1500, 0.005, 0.0));
  }
  write("est/poor/a_es.txt", helix_tum(1500, 0.05, 0.0));  // b missing
  const CliRun r =
      run("bench --gt-dir " + (dir_ / "gt").string() + " --est-dir " + (dir_ / "est").string() +
          " --methods good,poor --report " + (dir_ / "board").string());
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(dir_ / "board" / "leaderboard.json"));
  ASSERT_EQ(j["methods"].size(), 2u);
  EXPECT_EQ(j["methods"][0]["method"], "good");  // best RPE rank first
  EXPECT_EQ(j["methods"][1]["n_failed"], 1);
  EXPECT_FALSE(j["methods"][1]["sequences"]["b"]["ok"].get<bool>());
  EXPECT_NE(j["methods"][1]["sequences"]["b"]["problem"].get<std::string>().find("missing"),
            std::string::npos);
  // Ranks: sum of (10 - RPE %); good has two sequences near 0.5 %.
  EXPECT_NEAR(j["methods"][0]["rpe_rank"].get<double>(), 2 * (10 - 0.5), 0.2);
  for (const char* f :
       {"leaderboard.md", "leaderboard.csv", "cumulative_ate.svg", "cumulative_rpe.svg"}) {
    EXPECT_TRUE(fs::exists(dir_ / "board" / f)) << f;
  }
  EXPECT_NE(r.out.find("| 1 | good |"), std::string::npos) << r.out;
}

TEST_F(Cli, SimulateWritesTheLayoutAndNothingOnFailure) {
  const fs::path cfg = write("sim.yaml",
                             "seed: 7\nimu_duration_s: 10\ntrajectories:\n  duration_s: 20\n"
                             "  gnss: {outages: [[5, 8]]}\nimu: {drift_ppm: 20}\n");
  const fs::path out = dir_ / "session";
  CliRun r =
      run("simulate --out " + out.string() + " --what imu,trajectories --config " + cfg.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"truth.yaml", "truth.json", "imu/timestamps.txt", "imu/data/imu.txt",
                        "ouster_imu/data/imu.txt", "trajectories/truth_lidar.tum",
                        "trajectories/lidar_odometry.tum", "trajectories/gnss_ins.tum"}) {
    EXPECT_TRUE(fs::exists(out / f)) << f;
  }
  EXPECT_EQ(run("rig validate " + (out / "truth.yaml").string()).status, 0);
  const nlohmann::json truth = nlohmann::json::parse(slurp(out / "truth.json"));
  EXPECT_EQ(truth["seed"], 7);
  EXPECT_EQ(truth["imu"]["imu"]["drift_ppm"], 20.0);
  // 37 columns a line in imu.txt, and as many lines as stamps.
  const std::string imu = slurp(out / "imu" / "data" / "imu.txt");
  const std::string second_line =
      imu.substr(imu.find('\n') + 1, imu.find('\n', imu.find('\n') + 1) - imu.find('\n') - 1);
  EXPECT_EQ(std::count(second_line.begin(), second_line.end(), ','), 36);
  // The odometry scores against the truth with the benchmark.
  r = run("bench --gt " + (out / "trajectories" / "truth_lidar.tum").string() + " --est " +
          (out / "trajectories" / "lidar_odometry.tum").string());
  EXPECT_EQ(r.status, 0) << r.err;

  // The same seed gives byte-identical files.
  const fs::path again = dir_ / "again";
  ASSERT_EQ(
      run("simulate --out " + again.string() + " --what imu,trajectories --config " + cfg.string())
          .status,
      0);
  for (const char* f :
       {"imu/data/imu.txt", "ouster_imu/timestamps.txt", "trajectories/gnss_ins.tum",
        "trajectories/lidar_odometry.tum", "truth.json", "truth.yaml"}) {
    EXPECT_EQ(slurp(out / f), slurp(again / f)) << f;
  }
  // A non-empty folder is refused; bad parts and bad keys write nothing.
  r = run("simulate --out " + out.string() + " --what imu");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("exists and is not empty"), std::string::npos);
  r = run("simulate --out " + (dir_ / "x").string() + " --what imu,video");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("unknown part 'video'"), std::string::npos);
  const fs::path bad = write("bad.yaml", "seed: 1\nstereo:\n  viewz: 3\n");
  r = run("simulate --out " + (dir_ / "y").string() + " --config " + bad.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "rigcal: error: " + bad.string() +
                       ":3: key 'stereo.viewz': unknown key (doc/simulator.md lists the keys)\n");
  for (const auto& e : fs::directory_iterator(dir_)) {
    EXPECT_EQ(e.path().filename().string().find(".partial"), std::string::npos) << e.path();
    EXPECT_NE(e.path().filename(), "x");
    EXPECT_NE(e.path().filename(), "y");
  }
}

TEST_F(Cli, CamerasErrorsAreOneLineAndWriteNothing) {
  const std::string target = RIGCAL_SOURCE_DIR "/targets/checkerboard_9x6_25mm.yaml";
  const std::string out = (dir_ / "out.yaml").string(), report = (dir_ / "rep").string();
  CliRun r = run("cameras --target " + target + " --camera 'left=" + (dir_ / "none*.png").string() +
                 "' --out " + out + " --report " + report);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("camera left: no file matches"), std::string::npos) << r.err;
  // Images without the target anywhere.
  cv::Mat blank(120, 160, CV_8UC1, cv::Scalar(128));
  for (int i = 0; i < 3; ++i) cv::imwrite((dir_ / fmt::format("img{}.png", i)).string(), blank);
  r = run("cameras --target " + target + " --camera 'left=" + (dir_ / "img*.png").string() +
          "' --out " + out + " --report " + report);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("was found in none of the 3 images"), std::string::npos) << r.err;
  // One camera, two image sizes.
  cv::imwrite((dir_ / "img3.png").string(), cv::Mat(100, 100, CV_8UC1, cv::Scalar(128)));
  r = run("cameras --target " + target + " --camera 'left=" + (dir_ / "img*.png").string() +
          "' --out " + out + " --report " + report);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("one camera, one image size"), std::string::npos) << r.err;
  // Two images of one camera with one frame number.
  cv::imwrite((dir_ / "a_7.png").string(), blank);
  cv::imwrite((dir_ / "b_7.png").string(), blank);
  r = run("cameras --target " + target + " --camera 'left=" + (dir_ / "?_7.png").string() +
          "' --out " + out + " --report " + report);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("have the same frame number 7"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(report));
}

TEST_F(Cli, CamerasOnTheOpenCvSamplesWritesRigAndReport) {
  RIGCAL_REQUIRE_FIXTURE(dir, "stereo/opencv_samples");
  const std::string out = (dir_ / "calib.yaml").string(), report = (dir_ / "report").string();
  CliRun r = run("cameras --target " RIGCAL_SOURCE_DIR
                 "/targets/checkerboard_9x6_25mm.yaml --camera 'left=" +
                 dir + "/left*.jpg' --camera 'right=" + dir + "/right*.jpg' --out " + out +
                 " --report " + report);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(run("rig validate " + out).status, 0);
  const nlohmann::json j = nlohmann::json::parse(slurp(fs::path(report) / "cameras.json"));
  EXPECT_LE(j["rms_2d_px"].get<double>(), 0.20);
  EXPECT_NEAR(j["cameras"][1]["T_cam_cam0"]["baseline_m"].get<double>(), 0.0832, 0.0004);
  for (const char* f : {"corners.vnl", "left_corners.png", "left_residuals.png",
                        "left_coverage.png", "right_uncertainty.png"}) {
    EXPECT_TRUE(fs::exists(fs::path(report) / f)) << f;
  }
  // The second run reads the detections back from corners.vnl: same result.
  r = run("cameras --target " RIGCAL_SOURCE_DIR
          "/targets/checkerboard_9x6_25mm.yaml --camera 'left=" +
          dir + "/left*.jpg' --camera 'right=" + dir + "/right*.jpg' --out " + out + " --report " +
          report);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("26 from"), std::string::npos) << r.out;
  const nlohmann::json j2 = nlohmann::json::parse(slurp(fs::path(report) / "cameras.json"));
  EXPECT_NEAR(j2["rms_2d_px"].get<double>(), j["rms_2d_px"].get<double>(), 1e-12);
}

TEST_F(Cli, CamerasOnASimulatedRawBayerSession) {
  const fs::path cfg = write("b.yaml", "stereo:\n  views: 6\nimage:\n  bayer: true\n");
  ASSERT_EQ(
      run("simulate --out " + (dir_ / "s").string() + " --what stereo --config " + cfg.string())
          .status,
      0);
  const CliRun r =
      run("cameras --session " + (dir_ / "s" / "stereo").string() +
          " --target " RIGCAL_SOURCE_DIR
          "/targets/a3_checkerboard_8x5_40mm.yaml --bayer rggb --rig " RIGCAL_SOURCE_DIR
          "/data/sample_rig.yaml --out " +
          (dir_ / "c.yaml").string() + " --report " + (dir_ / "r").string());
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(dir_ / "r" / "cameras.json"));
  EXPECT_LT(j["rms_2d_px"].get<double>(), 0.15);
  // The rig keeps its other sensors and cam_l's pose; cam_r moves to the calibrated extrinsic.
  EXPECT_EQ(run("rig validate " + (dir_ / "c.yaml").string()).status, 0);
  EXPECT_NE(slurp(dir_ / "c.yaml").find("gnss:"), std::string::npos);
  EXPECT_EQ(run("cameras --session " + (dir_ / "s" / "stereo").string() +
                " --target " RIGCAL_SOURCE_DIR
                "/targets/a3_checkerboard_8x5_40mm.yaml --bayer xyz --out " +
                (dir_ / "d.yaml").string() + " --report " + (dir_ / "d").string())
                .status,
            2);
}

// No command writes over what it reads (links resolved), and the IMU inputs that crashed
// time-offset are bad input: exit 2, one line, nothing written or destroyed.
TEST_F(Cli, OutputsNeverOverwriteInputsAndEmptyStreamsAreBadInput) {
  const fs::path r = write("r.yaml", slurp(kSample));
  fs::create_symlink(r, dir_ / "link.yaml");
  const fs::path t =
      write("t.yaml", slurp(RIGCAL_SOURCE_DIR "/targets/a3_checkerboard_8x5_40mm.yaml"));
  const fs::path lidar = write("lidar.tum", "0 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n");
  cv::imwrite((dir_ / "img_1.png").string(), cv::Mat(32, 32, CV_8UC1, cv::Scalar(0)));
  const std::string image = (dir_ / "img_1.png").string();
  write("scan_1.bin", std::string(16, '\0'));
  const std::map<std::string, std::string> before = {{r.string(), slurp(r)},
                                                     {t.string(), slurp(t)},
                                                     {lidar.string(), slurp(lidar)},
                                                     {image, slurp(image)}};
  const std::string target = " --target " + t.string();
  for (const std::string& cmd :
       {"rig convert " + r.string() + " --to kalibr --out " + r.string(),
        "rig convert " + r.string() + " --to vbr --out " + (dir_ / "link.yaml").string(),
        "target print " + t.string() + " --out " + t.string(),
        "hand-eye --lidar " + lidar.string() + " --gnss " + lidar.string() + " --out " +
            lidar.string() + " --rig " + r.string(),
        "cameras --camera cam_l=" + image + target + " --out " + image + " --report " +
            (dir_ / "rep").string(),
        "cameras --camera cam_l=" + image + target + " --out " + t.string() + " --report " +
            (dir_ / "rep").string(),
        "lidar-camera --images " + image + " --scans " + (dir_ / "scan_1.bin").string() + target +
            " --rig " + r.string() + " --out " + t.string()}) {
    const CliRun run_ = run(cmd);
    EXPECT_EQ(run_.status, 2) << cmd << "\n" << run_.out << run_.err;
    EXPECT_NE(run_.err.find("is an input"), std::string::npos) << cmd << "\n" << run_.err;
    for (const auto& [file, text] : before) EXPECT_EQ(slurp(file), text) << cmd << ": " << file;
  }
  // An IMU folder with its header and no samples; a one-pose trajectory: either side.
  fs::create_directories(dir_ / "empty" / "data");
  write("empty/timestamps.txt", "");
  write("empty/data/imu.txt", std::string("acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z\n"));
  write("one.tum", "0 0 0 0 0 0 0 1\n");
  const std::string sim = (dir_ / "s").string();
  ASSERT_EQ(run("simulate --what imu --out " + sim).status, 0);
  for (const std::string& bad : {(dir_ / "empty").string(), (dir_ / "one.tum").string()}) {
    for (const std::string& cmd : {"time-offset --reference " + bad + " --other " + sim + "/imu",
                                   "time-offset --reference " + sim + "/imu --other " + bad}) {
      const CliRun run_ = run(cmd);
      EXPECT_EQ(run_.status, 2) << cmd << "\n" << run_.err;
      EXPECT_NE(run_.err.find("rigcal: error: " + bad), std::string::npos) << run_.err;
    }
  }
}

// Options that must be finite and positive say so (NaN included), exit 2; a UTF-8 byte-order
// mark before a TUM file's first line is read past.
TEST_F(Cli, NumericOptionsAreCheckedAndABomIsReadPast) {
  const fs::path tum =
      write("a.tum",
            "\xEF\xBB\xBF"
            "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 2 1 0 0 0 0 1\n3 0 2 1 0 0 0 1\n");
  CliRun r = run("bench --gt " + tum.string() + " --est " + tum.string());
  EXPECT_EQ(r.status, 0) << r.err;
  for (const char* opt : {"--rotation-sigma 0", "--translation-sigma nan", "--stride -1",
                          "--max-sigma inf", "--min-rotation -2"}) {
    r = run("hand-eye --lidar " + tum.string() + " --gnss " + tum.string() + " " +
            std::string(opt));
    EXPECT_EQ(r.status, 2) << opt << ": " << r.err;
    EXPECT_NE(r.err.find("expected a finite number"), std::string::npos) << opt << ": " << r.err;
  }
  r = run("bench --gt-dir " + dir_.string() + " --est-dir " + dir_.string() +
          " --methods a --ate-max nan");
  EXPECT_EQ(r.status, 2) << r.err;
  // A leaderboard where every run failed (the estimate missing) scores nothing: exit 2.
  fs::create_directories(dir_ / "gt");
  fs::create_directories(dir_ / "est" / "a");
  fs::copy_file(tum, dir_ / "gt" / "seq_gt.txt");
  r = run("bench --gt-dir " + (dir_ / "gt").string() + " --est-dir " + (dir_ / "est").string() +
          " --methods a");
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_NE(r.err.find("no run could be scored"), std::string::npos) << r.err;
}

}  // namespace

TEST_F(Cli, TimeOffsetWritesTheSensorsOffsetAndDrift) {
  // A simulated session whose external IMU runs 20 ppm fast; the truth is the sample rig's
  // time_offset of imu (-0.0031 s) at its first stamp.
  const fs::path cfg = write("sim.yaml", "seed: 3\nimu_duration_s: 600\nimu: {drift_ppm: 20}\n");
  const fs::path session = dir_ / "session";
  ASSERT_EQ(
      run("simulate --what imu --out " + session.string() + " --config " + cfg.string()).status, 0);
  const std::string out = (dir_ / "out.yaml").string(), report = (dir_ / "rep").string();
  CliRun r = run("time-offset --session " + session.string() + " --rig " + kSample + " --out " +
                 out + " --report " + report);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(run("rig validate " + out).status, 0);
  const nlohmann::json j = nlohmann::json::parse(slurp(fs::path(report) / "time_sync.json"));
  EXPECT_EQ(j["verdict"], "ok");
  EXPECT_NEAR(j["sensor_time_offset_s"].get<double>(), -0.0031, 0.05e-3);
  EXPECT_TRUE(j["drift"]["significant"].get<bool>());
  EXPECT_NEAR(j["drift"]["drift_ppm"].get<double>(), 20.0, 2.0);
  const std::string yaml = slurp(out);
  EXPECT_NE(yaml.find("time_drift_ppm: "), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("time_drift_epoch: "), std::string::npos) << yaml;
  for (const char* f : {"correlation.png", "aligned.png", "windows.png"})
    EXPECT_TRUE(fs::exists(fs::path(report) / f)) << f;

  // The same rig measured again without drift: the drift keys go away.
  const fs::path still = dir_ / "still";
  ASSERT_EQ(run("simulate --what imu --out " + still.string()).status, 0);
  r = run("time-offset --session " + still.string() + " --rig " + out + " --out " + out);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(out).find("time_drift_ppm"), std::string::npos);

  // Still sensors: no number, exit 3, the report says why, the rig is not written.
  const std::string imu_table = "t wx wy wz\n";
  std::string still_a, still_b;
  for (int i = 0; i < 2000; ++i) {
    still_a += fmt::format("{:.3f} 0.001 0.0 0.0\n", i * 0.01);
    still_b += fmt::format("{:.3f} 0.0 0.001 0.0\n", i * 0.01);
  }
  const fs::path a = write("a.txt", imu_table + still_a), b = write("b.txt", imu_table + still_b);
  const std::string out2 = (dir_ / "out2.yaml").string(), rep2 = (dir_ / "rep2").string();
  r = run("time-offset --reference " + a.string() + " --other " + b.string() +
          " --sensor imu --rig " + kSample + " --out " + out2 + " --report " + rep2);
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("not enough excitation"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out2));
  EXPECT_EQ(nlohmann::json::parse(slurp(fs::path(rep2) / "time_sync.json"))["verdict"],
            "not enough excitation");

  // Bad input: exit 2, one line, nothing written.
  const std::string out3 = (dir_ / "out3.yaml").string(), rep3 = (dir_ / "rep3").string();
  r = run("time-offset --reference " + a.string() + " --other " + b.string() +
          " --sensor nope --rig " + kSample + " --out " + out3 + " --report " + rep3);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--sensor nope: no such sensor"), std::string::npos) << r.err;
  r = run("time-offset --reference " + a.string() + " --other " + (dir_ / "missing.txt").string() +
          " --report " + rep3);
  EXPECT_EQ(r.status, 2);
  r = run("time-offset --reference " + a.string() + " --other " + b.string() + " --out " + out3);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("give both"), std::string::npos) << r.err;
  r = run("time-offset --reference " + a.string() + " --other " + b.string() +
          " --max-offset soon");
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(fs::exists(out3));
  EXPECT_FALSE(fs::exists(rep3));
}

// Acceptance 3 of issue 7 on real data. OpenCalib's figure-8 drive (NovAtel GNSS/INS and LiDAR
// poses at the LiDAR's stamps, read in their own format): flagged near-planar, the vertical not
// estimated (exit 3); with it fixed, an answer, the note in the report.
TEST_F(Cli, HandEyeOpenCalibCarIsFlaggedNearPlanar) {
  RIGCAL_REQUIRE_FIXTURE(dir, "hand_eye/opencalib");
  const std::string args = " --lidar " + dir + "/top_center_lidar-pose.txt --gnss " + dir +
                           "/NovAtel-pose-lidar-time.txt";
  CliRun r = run("hand-eye" + args);
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("near-planar motion, the plane's normal"), std::string::npos) << r.err;
  const std::string rep = (dir_ / "rep").string();
  r = run("hand-eye" + args + " --fix z=0 --report " + rep);
  ASSERT_EQ(r.status, 0) << r.err;
  std::printf("%s", r.out.c_str());
  const nlohmann::json j = nlohmann::json::parse(slurp(fs::path(rep) / "hand_eye.json"));
  EXPECT_TRUE(j["observability"]["near_planar"].get<bool>());
  EXPECT_GT(std::abs(j["observability"]["dominant_rotation_axis"][2].get<double>()), 0.99);
  ASSERT_EQ(j["observability"]["unobservable_directions"].size(), 1u);
  EXPECT_NE(r.out.find("note: near-planar motion"), std::string::npos);
  // OpenCalib's initial guess (gnss-to-top_center_lidar-extrinsic.json) is T_lidar_gnss = yaw
  // -90 deg, t (-1, 0, -1.3): the answer turns the same way within 2 deg (it is a guess).
  const std::vector<double> rpy = j["T_gnss_lidar"]["roll_pitch_yaw_deg"];
  EXPECT_NEAR(rpy[2], 90.0, 2.0);
  std::vector<double> rot, trans;
  for (const auto& p : j["pairs"]) {
    rot.push_back(p["rotation_residual_deg"]);
    trans.push_back(p["translation_residual_m"]);
  }
  std::printf("OpenCalib: %zu pairs, median residual %.2g deg, %.4f m\n", rot.size(),
              rigcal::median(rot), rigcal::median(trans));
}

// Motion-capture pairs (ETH's PrimeSense camera tracked against a target, and its Vicon body,
// 100 Hz stamped to 10 ms): the clock offset estimated, an extrinsic, per-pair residuals in the
// report. The fit explains the motions: among the 1 s pairs, the median rotation residual is a
// small fraction of the median rotation of a pair (the 0.3 s pairs turn 3-4 times less with the
// same per-pose noise of the camera's tracking; the report gives each length its noise level).
TEST_F(Cli, HandEyeEthMotionCapture) {
  RIGCAL_REQUIRE_FIXTURE(dir, "hand_eye/ethz/prime_sense_color_w_vicon_1/prime_sense_1");
  const std::string rep = (dir_ / "rep").string();
  CliRun r = run("hand-eye --lidar " + dir + "/2017-04-09-18-13-10_W_camera_rgb_image_raw.csv" +
                 " --gnss " + dir + "/2017-04-09-18-13-10_vicon_prime_sense.csv" +
                 " --estimate-offset --report " + rep);
  EXPECT_EQ(r.status, 2);  // equal stamps in the Vicon log
  EXPECT_NE(r.err.find("--duplicate-stamps"), std::string::npos) << r.err;
  r = run("hand-eye --lidar " + dir + "/2017-04-09-18-13-10_W_camera_rgb_image_raw.csv" +
          " --gnss " + dir + "/2017-04-09-18-13-10_vicon_prime_sense.csv" +
          " --estimate-offset --duplicate-stamps drop --report " + rep);
  ASSERT_EQ(r.status, 0) << r.err;
  std::printf("%s", r.out.c_str());
  const nlohmann::json j = nlohmann::json::parse(slurp(fs::path(rep) / "hand_eye.json"));
  std::vector<double> rot, res_rot, res_trans;
  for (const auto& p : j["pairs"]) {
    const double length =
        std::stod(p["t1_s"].get<std::string>()) - std::stod(p["t0_s"].get<std::string>());
    if (length < 0.9) continue;
    rot.push_back(p["rotation_deg"]);
    res_rot.push_back(p["rotation_residual_deg"]);
    res_trans.push_back(p["translation_residual_m"]);
  }
  ASSERT_GE(rot.size(), 30u);
  for (auto* v : {&rot, &res_rot, &res_trans}) std::sort(v->begin(), v->end());
  const size_t m = rot.size() / 2;
  std::printf(
      "ETH prime_sense_1: %zu pairs, median rotation %.2f deg, median residuals %.3f deg, %.4f m; "
      "clock offset %.4f s\n",
      rot.size(), rot[m], res_rot[m], res_trans[m],
      j["inputs"]["gnss_time_offset_s"].get<double>());
  EXPECT_LT(res_rot[m], 0.2 * rot[m]);
  EXPECT_TRUE(j["observability"]["unobservable_directions"].empty());
  ASSERT_EQ(j["pair_noise"]["levels"].size(), 2u);
  for (const auto& level : j["pair_noise"]["levels"]) {
    EXPECT_GT(level["pairs"].get<size_t>(), 100u);
    EXPECT_GT(level["rotation_deg"].get<double>(), 0.0);
  }
}

// GNSS fixes as CSV: the simulated GNSS/INS poses written as latitude, longitude, height and NED
// roll, pitch, heading (GeographicLib's reverse, origin in Rome), read back to ENU: the same
// extrinsic as from the TUM poses (the hand-eye does not depend on the world frame).
TEST_F(Cli, HandEyeReadsGnssFixes) {
  const fs::path sim = dir_ / "sim";
  ASSERT_EQ(run("simulate --what trajectories --out " + sim.string()).status, 0);
  const rigcal::Trajectory gnss =
      rigcal::io::read_trajectory(sim / "trajectories" / "gnss_ins.tum").trajectory;
  GeographicLib::LocalCartesian enu(41.9, 12.5, 50.0);
  const Eigen::Matrix3d R_enu_ned = (Eigen::Matrix3d() << 0, 1, 0, 1, 0, 0, 0, 0, -1).finished();
  std::string csv =
      "# simulated\ntime,latitude,longitude,height,roll,pitch,yaw,std_east,std_north,std_up\n";
  for (size_t k = 0; k < gnss.size(); ++k) {
    const rigcal::SE3& T = gnss.T_world_body[k];
    double lat, lon, h;
    enu.Reverse(T.t.x(), T.t.y(), T.t.z(), lat, lon, h);
    const Eigen::Matrix3d R = R_enu_ned.transpose() * T.R;  // R_ned_body
    const double yaw = std::atan2(R(1, 0), R(0, 0)), pitch = -std::asin(R(2, 0)),
                 roll = std::atan2(R(2, 1), R(2, 2));
    csv += fmt::format("{},{:.12f},{:.12f},{:.6f},{:.9f},{:.9f},{:.9f},0.02,0.02,0.03\n",
                       rigcal::to_seconds_text(gnss.stamps[k]), lat, lon, h, roll * 180 / M_PI,
                       pitch * 180 / M_PI, yaw * 180 / M_PI);
  }
  const fs::path fixes = write("fixes.csv", csv);
  const std::string lidar = " --lidar " + (sim / "trajectories" / "lidar_odometry.tum").string();
  CliRun r = run("hand-eye" + lidar + " --gnss " + fixes.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("give --attitude"), std::string::npos) << r.err;
  const std::string rep_f = (dir_ / "rep_f").string(), rep_t = (dir_ / "rep_t").string();
  r = run("hand-eye" + lidar + " --gnss " + fixes.string() + " --attitude ned --report " + rep_f);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("GNSS fixes converted to ENU"), std::string::npos) << r.out;
  r = run("hand-eye" + lidar + " --gnss " + (sim / "trajectories" / "gnss_ins.tum").string() +
          " --report " + rep_t);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json jf = nlohmann::json::parse(slurp(fs::path(rep_f) / "hand_eye.json"));
  const nlohmann::json jt = nlohmann::json::parse(slurp(fs::path(rep_t) / "hand_eye.json"));
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(jf["T_gnss_lidar"]["t_m"][i].get<double>(),
                jt["T_gnss_lidar"]["t_m"][i].get<double>(), 1e-4);
    // 1e-3 deg: the local smoothing's outlier cut and the Huber weights can flip on rounding.
    EXPECT_NEAR(jf["T_gnss_lidar"]["roll_pitch_yaw_deg"][i].get<double>(),
                jt["T_gnss_lidar"]["roll_pitch_yaw_deg"][i].get<double>(), 1e-3);
  }
  // A missing column and a latitude out of range are named with file and line.
  const fs::path bad = write("bad.csv", "time,latitude,longitude,height,roll,pitch\n0,1,2,3,4,5\n");
  r = run("hand-eye" + lidar + " --gnss " + bad.string() + " --attitude enu");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.csv:1: the header has no 'yaw' column"), std::string::npos) << r.err;
  const fs::path bad2 =
      write("bad2.csv",
            "time,lat,lon,alt,roll,pitch,heading\n0,41.9,12.5,3,0,0,0\n1,141.9,12.5,3,0,0,0\n");
  r = run("hand-eye" + lidar + " --gnss " + bad2.string() + " --attitude enu");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad2.csv:3: latitude 141.9"), std::string::npos) << r.err;
}

// rigcal lidar-camera on a simulated session: the rig written (cam_r placed, cam_l following
// through the stereo extrinsic), the report with a quick-look PNG per pair; bad input: exit 2,
// nothing written.
TEST_F(Cli, LidarCameraWritesTheRigAndRefusesTooFewBoards) {
  const fs::path sim = dir_ / "sim";
  ASSERT_EQ(run("simulate --what lidar-camera --out " + sim.string()).status, 0);
  const std::string target = RIGCAL_SOURCE_DIR "/targets/a3_checkerboard_8x5_40mm.yaml";
  const std::string out = (dir_ / "out.yaml").string(), rep = (dir_ / "rep").string();
  CliRun r = run("lidar-camera --target " + target + " --rig " + kSample + " --session " +
                 sim.string() + " --out " + out + " --report " + rep);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(run("rig validate " + out).status, 0);
  const nlohmann::json j = nlohmann::json::parse(slurp(fs::path(rep) / "lidar_camera.json"));
  ASSERT_EQ(j["pairs"].size(), 10u);
  for (const auto& p : j["pairs"]) EXPECT_TRUE(p["used"].get<bool>()) << p["note"];
  EXPECT_TRUE(fs::exists(fs::path(rep) / "pair_01.png"));
  // The written rig against the sample rig (the simulator's truth): cam_r within 5 mm, and the
  // stereo extrinsic unchanged.
  namespace rig = rigcal::rig;
  const rig::Rig truth = rig::read_rig_file(kSample), got = rig::read_rig_file(out);
  EXPECT_LT((rig::T_a_b(got, "cam_r", "lidar").t - rig::T_a_b(truth, "cam_r", "lidar").t).norm(),
            0.005);
  EXPECT_LT((rig::T_a_b(got, "cam_r", "cam_l").t - rig::T_a_b(truth, "cam_r", "cam_l").t).norm(),
            1e-9);
  // Two pairs: no calibration, nothing written.
  const std::string out2 = (dir_ / "out2.yaml").string();
  const std::string lc = sim.string() + "/lidar_camera/";
  r = run("lidar-camera --target " + target + " --rig " + kSample + " --images '" + lc +
          "camera_right/data/000000000[01].png' --scans '" + lc +
          "ouster_points/data/000000000[01].bin' --out " + out2);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("at least 3"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out2));
  // A scan without its image.
  r = run("lidar-camera --target " + target + " --rig " + kSample + " --images '" + lc +
          "camera_right/data/000000000[01].png' --scans '" + lc +
          "ouster_points/data/000000000[012].bin' --out " + out2);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("has no image with the same frame number"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out2));
  // --session pairs by stamp on the base clock: with cam_r's clock 5 s off in the rig, no image
  // has a scan within --max-dt (the simulator's pairs are 10 s apart).
  rig::Rig shifted = rig::read_rig_file(kSample);
  rig::sensor(shifted, "cam_r").time_offset = 5.0;
  const fs::path shifted_rig = write("shifted.yaml", rig::rig_to_yaml(shifted));
  r = run("lidar-camera --target " + target + " --rig " + shifted_rig.string() + " --session " +
          sim.string() + " --out " + out2);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no image has a scan within 0.05 s"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out2));
}

TEST_F(Cli, HandEyeWritesTheExtrinsicAndRefusesAnUndeterminedDirection) {
  const fs::path hand = dir_ / "hand", car = dir_ / "car";
  ASSERT_EQ(run("simulate --what trajectories --out " + hand.string()).status, 0);
  const fs::path cfg = write("car.yaml", "trajectories:\n  motion: car\n");
  ASSERT_EQ(run("simulate --what trajectories --out " + car.string() + " --config " + cfg.string())
                .status,
            0);
  auto args = [](const fs::path& s) {
    return " --lidar " + (s / "trajectories" / "lidar_odometry.tum").string() + " --gnss " +
           (s / "trajectories" / "gnss_ins.tum").string();
  };
  const std::string out = (dir_ / "out.yaml").string(), rep = (dir_ / "rep").string();
  CliRun r =
      run("hand-eye" + args(hand) + " --rig " + kSample + " --out " + out + " --report " + rep);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(run("rig validate " + out).status, 0);
  // T_gnss_lidar against the sample rig's (the simulator's truth): within 1 cm.
  const nlohmann::json j = nlohmann::json::parse(slurp(fs::path(rep) / "hand_eye.json"));
  EXPECT_TRUE(j["observability"]["unobservable_directions"].empty());
  const std::vector<double> t = j["T_gnss_lidar"]["t_m"];
  const double truth[3] = {0.0500, 0.0028, -0.1399};  // -R^T t of the sample rig's gnss T_b
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(t[i], truth[i], 0.01) << i;
  for (const char* f : {"hand_eye.json", "residuals.png", "trajectories.png"})
    EXPECT_TRUE(fs::exists(fs::path(rep) / f)) << f;
  // Without the rig's clock offset, estimated from the trajectories: the simulator's GNSS/INS
  // clock is the sample rig's time_offset, -3.1 ms (issue 7's bar: within 1 ms; measured 0.022 ms
  // off, asserted within 0.1 ms).
  const std::string rep_t = (dir_ / "rep_t").string();
  r = run("hand-eye" + args(hand) + " --estimate-offset --report " + rep_t);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json jt = nlohmann::json::parse(slurp(fs::path(rep_t) / "hand_eye.json"));
  EXPECT_NEAR(jt["inputs"]["gnss_time_offset_s"].get<double>(), -0.0031, 0.1e-3);
  // A car without a rig or --fix: the vertical is undetermined; exit 3, no rig written, the
  // report saying why (as every step's: status undetermined, reason, remedy).
  const std::string rep2 = (dir_ / "rep2").string();
  r = run("hand-eye" + args(car) + " --report " + rep2);
  EXPECT_EQ(r.status, 3);
  EXPECT_NE(r.err.find("does not determine the translation"), std::string::npos) << r.err;
  const nlohmann::json ju = nlohmann::json::parse(slurp(fs::path(rep2) / "hand_eye.json"));
  EXPECT_EQ(ju["status"], "undetermined");
  EXPECT_NE(ju["reason"].get<std::string>().find("does not determine"), std::string::npos);
  fs::remove_all(rep2);
  // With --fix it answers, and holds the value.
  r = run("hand-eye" + args(car) + " --fix z=-0.1399 --report " + rep2);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j2 = nlohmann::json::parse(slurp(fs::path(rep2) / "hand_eye.json"));
  EXPECT_NEAR(j2["T_gnss_lidar"]["t_m"][2].get<double>(), -0.1399, 1e-4);
  // With --prior it answers too, within the prior's sigma of the truth, and the covariance
  // carries that sigma along the vertical (the motion adds next to nothing there).
  const std::string rep3 = (dir_ / "rep3").string();
  r = run("hand-eye" + args(car) + " --prior z=-0.13,0.02 --report " + rep3);
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j3 = nlohmann::json::parse(slurp(fs::path(rep3) / "hand_eye.json"));
  EXPECT_NEAR(j3["T_gnss_lidar"]["t_m"][2].get<double>(), -0.1399, 0.02);
  const double sz = j3["T_gnss_lidar"]["t_sigma_m"][2].get<double>();
  EXPECT_GT(sz, 0.015);
  EXPECT_LE(sz, 0.0201);
  r = run("hand-eye" + args(car) + " --prior z=-0.13");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("expected x=METRES,SIGMA"), std::string::npos) << r.err;
  r = run("hand-eye" + args(car) + " --spacing 0.3,0");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("must be positive"), std::string::npos) << r.err;
  // Trajectories that do not overlap in time, and too few pairs: exit 2.
  const fs::path a = write("a.tum", "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n2 2 0 0 0 0 0 1\n");
  const fs::path b = write("b.tum", "100 0 0 0 0 0 0 1\n101 1 0 0 0 0 0 1\n102 2 0 0 0 0 0 1\n");
  r = run("hand-eye --lidar " + a.string() + " --gnss " + b.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("do not overlap in time"), std::string::npos) << r.err;
  r = run("hand-eye --lidar " + a.string() + " --gnss " + a.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("too few or too small motions"), std::string::npos) << r.err;
}
