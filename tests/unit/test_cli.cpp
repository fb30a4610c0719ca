// The command line as a user runs it: exit statuses, one-line errors, nothing written on failure.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <GeographicLib/LocalCartesian.hpp>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <set>
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

// A report's PNG read back: its size, and that it holds a picture, not a blank canvas.
cv::Mat read_png(const fs::path& p, int width, int height) {
  const cv::Mat img = cv::imread(p.string(), cv::IMREAD_COLOR);
  EXPECT_FALSE(img.empty()) << p << ": not a readable image";
  if (img.empty()) return img;
  EXPECT_EQ(img.cols, width) << p;
  EXPECT_EQ(img.rows, height) << p;
  cv::Scalar mean, stddev;
  cv::meanStdDev(img.reshape(1), mean, stddev);
  EXPECT_GT(stddev[0], 5.0) << p << ": blank";
  return img;
}

// Pixels within `tol` (each channel) of a BGR colour.
int pixels_near(const cv::Mat& img, cv::Vec3b bgr, int tol = 30) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y) {
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      n += std::abs(p[0] - bgr[0]) <= tol && std::abs(p[1] - bgr[1]) <= tol &&
           std::abs(p[2] - bgr[2]) <= tol;
    }
  }
  return n;
}

// A plot rendered by report::render_png (900 x 620, white, series drawn in the SVG palette):
// mostly white, with at least `min_series_px` pixels of its first series' colour (#1f77b4).
void expect_plot_png(const fs::path& p) {
  const cv::Mat img = read_png(p, 900, 620);
  if (img.empty()) return;
  EXPECT_GT(pixels_near(img, {255, 255, 255}, 0), static_cast<int>(img.total() / 2)) << p;
  EXPECT_GT(pixels_near(img, {180, 119, 31}, 40), 50) << p << ": no series drawn";
}

// A report's SVG, parsed for its elements: the root, the title, the polylines (each with its
// points inside the plot frame) and circles; returns the number of points of each polyline.
struct Svg {
  std::string title;
  std::vector<size_t> polyline_points;
  size_t circles = 0;
  size_t bars = 0;  // translucent rects (bars, histogram bins, boxes), each inside the frame
  std::vector<std::string> texts;
};

Svg parse_svg(const fs::path& p) {
  const std::string s = slurp(p);
  Svg svg;
  EXPECT_EQ(s.rfind("<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u) << p;
  EXPECT_NE(s.find("</svg>"), std::string::npos) << p << ": truncated";
  // Every element closed: as many <g> as </g>, every line ending in '>'.
  auto count = [&](const std::string& what) {
    size_t n = 0;
    for (size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("<g "), count("</g>")) << p;
  std::istringstream lines(s);
  for (std::string line; std::getline(lines, line);) {
    EXPECT_FALSE(line.empty()) << p;
    if (!line.empty()) {
      EXPECT_EQ(line.back(), '>') << p << ": " << line;
    }
  }
  const std::regex frame(
      "<rect x=\"([0-9.]+)\" y=\"([0-9.]+)\" width=\"([0-9.]+)\" height=\"([0-9.]+)\" "
      "fill=\"none\" stroke=\"black\"/>");
  std::smatch m;
  EXPECT_TRUE(std::regex_search(s, m, frame)) << p << ": no plot frame";
  const double fx = std::stod(m[1]), fy = std::stod(m[2]), fw = std::stod(m[3]),
               fh = std::stod(m[4]);
  const std::regex text("<text[^>]*>([^<]*)</text>");
  for (auto it = std::sregex_iterator(s.begin(), s.end(), text); it != std::sregex_iterator(); ++it)
    svg.texts.push_back((*it)[1]);
  if (!svg.texts.empty()) svg.title = svg.texts.front();
  const std::regex bar(
      "<rect x=\"(-?[0-9.]+)\" y=\"(-?[0-9.]+)\" width=\"([0-9.]+)\" height=\"([0-9.]+)\" "
      "fill=\"#[0-9a-f]+\" fill-opacity=");
  for (auto it = std::sregex_iterator(s.begin(), s.end(), bar); it != std::sregex_iterator();
       ++it) {
    ++svg.bars;
    const double x = std::stod((*it)[1]), y = std::stod((*it)[2]);
    EXPECT_TRUE(x >= fx - 0.1 && x + std::stod((*it)[3]) <= fx + fw + 0.1 && y >= fy - 0.1 &&
                y + std::stod((*it)[4]) <= fy + fh + 0.1)
        << p << ": a bar outside the plot: " << (*it)[0];
  }
  const std::regex polyline("<polyline [^>]*points=\"([^\"]*)\"/>");
  for (auto it = std::sregex_iterator(s.begin(), s.end(), polyline); it != std::sregex_iterator();
       ++it) {
    std::istringstream pts((*it)[1].str());
    size_t n = 0;
    double x, y;
    char comma;
    while (pts >> x >> comma >> y) {
      ++n;
      EXPECT_TRUE(x >= fx - 0.1 && x <= fx + fw + 0.1 && y >= fy - 0.1 && y <= fy + fh + 0.1)
          << p << ": point " << x << "," << y << " outside the plot";
    }
    svg.polyline_points.push_back(n);
  }
  svg.circles = count("<circle ");
  return svg;
}

bool has_text(const Svg& svg, const std::string& t) {
  return std::find(svg.texts.begin(), svg.texts.end(), t) != svg.texts.end();
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

// Exit 2 and one line on stderr saying what is wrong, nothing on stdout.
TEST_F(Cli, UsageErrorsExitTwo) {
  const std::pair<std::string, std::string> cases[] = {
      {"", "rigcal: A subcommand is required (see rigcal --help)\n"},
      {"rig", "rigcal: A subcommand is required (see rigcal --help)\n"},
      {"rig validate", "rigcal: file is required (see rigcal --help)\n"},
      {"rig show " + kSample + " --no-such-option",
       "rigcal: The following argument was not expected: --no-such-option (see rigcal --help)\n"},
      {"--no-such-option rig show " + kSample,
       "rigcal: The following argument was not expected: --no-such-option (see rigcal --help)\n"}};
  for (const auto& [args, message] : cases) {
    const CliRun r = run(args);
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_EQ(r.err, message) << args;
    EXPECT_TRUE(r.out.empty()) << args << ": " << r.out;
  }
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
    ASSERT_EQ(r.status, 0) << to << ": " << r.err;
  }
  // Each file read back by its format's reader, with the sample rig's numbers.
  namespace rig = rigcal::rig;
  const rig::Rig sample = rig::read_rig_file(kSample);
  const rig::CameraModel& cl = rig::sensor(sample, "cam_l").camera;
  const rig::CameraModel& cr = rig::sensor(sample, "cam_r").camera;
  // The rigcal export is the same rig; the vbr one too, for every sensor's pose and lens.
  for (const char* to : {"rigcal", "vbr"}) {
    SCOPED_TRACE(to);
    const rig::Rig back = rig::read_rig_file(dir_ / (std::string(to) + ".yaml"));
    ASSERT_EQ(back.sensors.size(), sample.sensors.size());
    for (const rig::Sensor& s : sample.sensors) {
      const rig::Sensor& b = rig::sensor(back, s.name);
      EXPECT_EQ(b.T_base_sensor.matrix(), s.T_base_sensor.matrix()) << s.name;
      EXPECT_EQ(b.camera.K(), s.camera.K()) << s.name;
      EXPECT_EQ(b.camera.distortion_coeffs, s.camera.distortion_coeffs) << s.name;
    }
  }
  // Kalibr's camchain (YAML): cam0 = cam_l, cam1 = cam_r, T_cn_cnm1 maps cam0 points into cam1.
  const YAML::Node kalibr = YAML::LoadFile((dir_ / "kalibr.yaml").string());
  EXPECT_EQ(kalibr["cam0"]["intrinsics"].as<std::vector<double>>(),
            (std::vector<double>{cl.fx, cl.fy, cl.cx, cl.cy}));
  EXPECT_EQ(kalibr["cam1"]["intrinsics"].as<std::vector<double>>(),
            (std::vector<double>{cr.fx, cr.fy, cr.cx, cr.cy}));
  EXPECT_EQ(kalibr["cam0"]["distortion_model"].as<std::string>(), "radtan");
  EXPECT_EQ(kalibr["cam0"]["distortion_coeffs"].as<std::vector<double>>(), cl.distortion_coeffs);
  EXPECT_EQ(kalibr["cam1"]["distortion_coeffs"].as<std::vector<double>>(), cr.distortion_coeffs);
  EXPECT_EQ(kalibr["cam1"]["resolution"].as<std::vector<int>>(),
            (std::vector<int>{cr.width, cr.height}));
  auto matrix4 = [](const YAML::Node& n) {
    Eigen::Matrix4d m;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) m(i, j) = n[i][j].as<double>();
    return m;
  };
  EXPECT_TRUE(matrix4(kalibr["cam1"]["T_cn_cnm1"])
                  .isApprox(rig::T_a_b(sample, "cam_r", "cam_l").matrix(), 1e-15));
  EXPECT_TRUE(matrix4(kalibr["cam0"]["T_cam_imu"])
                  .isApprox(rig::T_a_b(sample, "cam_l", "imu").matrix(), 1e-15));
  // OpenCV's FileStorage: K, D, size per camera; R, T with p_r = R p_l + T.
  cv::FileStorage cvfs((dir_ / "opencv.yaml").string(), cv::FileStorage::READ);
  ASSERT_TRUE(cvfs.isOpened());
  auto mat = [&](const char* key) {
    cv::Mat m;
    cvfs[key] >> m;
    Eigen::MatrixXd e;
    cv::cv2eigen(m, e);
    return e;
  };
  EXPECT_EQ(Eigen::Matrix3d(mat("K1")), cl.K());
  EXPECT_EQ(Eigen::Matrix3d(mat("K2")), cr.K());
  const Eigen::MatrixXd D1 = mat("D1"), D2 = mat("D2");
  EXPECT_EQ(std::vector<double>(D1.data(), D1.data() + D1.size()), cl.distortion_coeffs);
  EXPECT_EQ(std::vector<double>(D2.data(), D2.data() + D2.size()), cr.distortion_coeffs);
  cv::Size size2;
  cvfs["image_size2"] >> size2;
  EXPECT_EQ(size2, cv::Size(cr.width, cr.height));
  const rigcal::SE3 T_r_l = rig::T_a_b(sample, "cam_r", "cam_l");
  EXPECT_TRUE(Eigen::Matrix3d(mat("R")).isApprox(T_r_l.R, 1e-15));
  EXPECT_TRUE(Eigen::Vector3d(mat("T")).isApprox(T_r_l.t, 1e-15));
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
  // The plots: ground truth as a line, the estimate as 1999 points coloured by their ATE with its
  // colour bar, in the helix's plane (xy: it climbs 0.2 m over 60 m); the ATE and the RPE along
  // the trajectory as one line of 1999 (1998 pairs) points, with their rmse, mean, median and
  // mean +- std as lines of two points.
  const Svg top = parse_svg(dir_ / "rep" / "trajectory.svg");
  EXPECT_EQ(top.title, "Trajectories in the xy plane (estimate coloured by ATE)");
  EXPECT_EQ(top.polyline_points, std::vector<size_t>{1999});
  EXPECT_EQ(top.circles, 1999u);
  EXPECT_TRUE(has_text(top, "ground truth"));
  EXPECT_TRUE(has_text(top, "ATE [m]"));
  const Svg along = parse_svg(dir_ / "rep" / "ate.svg");
  EXPECT_EQ(along.title, "ATE along the trajectory (translation)");
  EXPECT_EQ(along.polyline_points, (std::vector<size_t>{1999, 2, 2, 2, 2, 2}));
  EXPECT_EQ(along.circles, 0u);
  EXPECT_TRUE(has_text(along, "translation error [m]"));
  EXPECT_TRUE(has_text(along, "time since the first pair [s]"));
  EXPECT_TRUE(
      has_text(along, fmt::format("rmse {:.4g} m", j["ate"]["trans"]["rmse"].get<double>())));
  const Svg rpe = parse_svg(dir_ / "rep" / "rpe.svg");
  EXPECT_EQ(rpe.polyline_points, (std::vector<size_t>{1998, 2, 2, 2, 2, 2}));
  EXPECT_EQ(j["plots"]["plane"], "xy");
  EXPECT_FALSE(fs::exists(dir_ / "rep" / "per_pose.csv"));  // only with --per-pose

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
  r = run("bench --gt " + gt.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "rigcal: error: give --gt and --est (or --gt-dir and --est-dir)\n");
  // A time window without ground truth in it, and one the wrong way round.
  r = run("bench --gt " + gt.string() + " --est " + est.string() + " --t-start 5000");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no ground-truth pose between --t-start and --t-end"), std::string::npos)
      << r.err;
  r = run("bench --gt " + gt.string() + " --est " + est.string() + " --t-start 9 --t-end 3");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--t-start 9 s is after --t-end 3 s"), std::string::npos) << r.err;
  r = run("bench --gt " + gt.string() + " --est " + est.string() + " --delta-unit x");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("expected f (frames), m (metres), d (degrees) or r (radians)"),
            std::string::npos)
      << r.err;
  r = run("bench --gt " + gt.string() + " --est " + est.string() + " --convention foo");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "rigcal: error: unknown convention 'foo'; expected rigcal, evo, kitti or vbr\n");
}

// KITTI's poses are in the camera frame, y down: the car drives in the x-z plane, and a plot of
// x-y draws a line. The plane is chosen from the spread; without stamps the plots run over pose
// indices. bench.json stays a summary; the rows go to CSV files only with --per-pose.
TEST_F(Cli, BenchKittiPosesDrawInTheirPlaneAndRowsOnlyWhenAsked) {
  std::string gt_text, est_text;
  const int n = 600;
  for (int i = 0; i < n; ++i) {
    const double yaw = 0.01 * i, x = 20 * std::sin(yaw), z = 20 * (1 - std::cos(yaw)) + 0.5 * i;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
    auto row = [&](double dx) {
      return fmt::format("{} {} {} {} {} {} {} {} {} {} {} {}\n", R(0, 0), R(0, 1), R(0, 2), x + dx,
                         R(1, 0), R(1, 1), R(1, 2), 0.01 * std::sin(0.1 * i), R(2, 0), R(2, 1),
                         R(2, 2), z);
    };
    gt_text += row(0.0);
    est_text += row(0.002 * i);
  }
  const fs::path gt = write("k_gt.txt", gt_text), est = write("k_es.txt", est_text);
  const fs::path rep = dir_ / "krep";
  CliRun r = run("bench --gt " + gt.string() + " --est " + est.string() + " --report " +
                 rep.string() + " --per-pose");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(slurp(rep / "bench.json"));
  EXPECT_EQ(j["plots"]["plane"], "xz");
  EXPECT_EQ(j["plots"]["along"], "pose index");
  EXPECT_LT(fs::file_size(rep / "bench.json"), 8000u);
  const Svg top = parse_svg(rep / "trajectory.svg");
  EXPECT_EQ(top.title, "Trajectories in the xz plane (estimate coloured by ATE)");
  EXPECT_TRUE(has_text(top, "z [m]"));
  EXPECT_TRUE(has_text(parse_svg(rep / "ate.svg"), "pose index"));
  // One row a matched pose, one a segment of each kind, as the summary counts them.
  const std::string per_pose = slurp(rep / "per_pose.csv");
  EXPECT_EQ(per_pose.substr(0, per_pose.find('\n')),
            "index,gt_x,gt_y,gt_z,est_x,est_y,est_z,ate_trans_m,ate_rot_deg");
  EXPECT_EQ(std::count(per_pose.begin(), per_pose.end(), '\n'), n + 1);
  for (const char* kind : {"kitti", "vbr", "delta"}) {
    const std::string rows = slurp(rep / fmt::format("segments_{}.csv", kind));
    EXPECT_EQ(static_cast<size_t>(std::count(rows.begin(), rows.end(), '\n')),
              j["rpe"][kind]["n_segments"].get<size_t>() + 1)
        << kind;
  }
  // --plot-mode overrides the choice; --per-pose needs a folder to write in.
  r = run("bench --gt " + gt.string() + " --est " + est.string() + " --report " +
          (dir_ / "kxy").string() + " --plot-mode xy");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(parse_svg(dir_ / "kxy" / "trajectory.svg").title,
            "Trajectories in the xy plane (estimate coloured by ATE)");
  r = run("bench --gt " + gt.string() + " --est " + est.string() + " --per-pose");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--per-pose"), std::string::npos) << r.err;
  // evo's time options need stamps; rows paired by index have none.
  r = run("bench --gt " + gt.string() + " --est " + est.string() + " --t_offset 0.1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("need stamps on both trajectories"), std::string::npos) << r.err;
}

// Several estimates against one ground truth, then the saved results compared (evo_res): one
// table for both, the same from the run and from the results read back.
TEST_F(Cli, BenchSeveralEstimatesAndTheirSavedResultsCompared) {
  const fs::path gt = write("seq_gt.txt", helix_tum(1500, 0.0, 0.0));
  const fs::path good = write("good.txt", helix_tum(1500, 0.002, 0.004));
  const fs::path poor = write("poor.txt", helix_tum(1500, 0.03, 0.004));
  const fs::path rep = dir_ / "several";
  CliRun r = run("bench --gt " + gt.string() + " --est " + good.string() + " --est " +
                 poor.string() + " --report " + rep.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("== good"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("== poor"), std::string::npos) << r.out;
  const nlohmann::json jg = nlohmann::json::parse(slurp(rep / "good" / "bench.json"));
  const nlohmann::json jp = nlohmann::json::parse(slurp(rep / "poor" / "bench.json"));
  EXPECT_LT(jg["ate"]["trans"]["rmse"].get<double>(), jp["ate"]["trans"]["rmse"].get<double>());
  // The table: a row an estimate, its ATE rmse as each one's bench.json holds it.
  const std::string table = slurp(rep / "compare.md");
  for (const auto& [name, j] : {std::pair{"good", jg}, {"poor", jp}}) {
    const std::string row = fmt::format("| {} | rigcal | {} | {:.6g} |", name, j["n_pairs"].dump(),
                                        j["ate"]["trans"]["rmse"].get<double>());
    EXPECT_NE(table.find(row), std::string::npos) << row << "\n" << table;
  }
  EXPECT_NE(r.out.find(table), std::string::npos);
  // Plots of both: the ground truth and two estimates; two ATE lines.
  EXPECT_EQ(parse_svg(rep / "trajectories.svg").polyline_points.size(), 3u);
  EXPECT_EQ(parse_svg(rep / "ate.svg").polyline_points.size(), 2u);
  EXPECT_TRUE(has_text(parse_svg(rep / "ate.svg"), "poor"));

  // `bench compare` on the saved results gives the same table.
  r = run("bench compare " + (rep / "good").string() + " " +
          (rep / "poor" / "bench.json").string() + " --report " + (dir_ / "cmp").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(dir_ / "cmp" / "compare.md"), table);
  const nlohmann::json cj = nlohmann::json::parse(slurp(dir_ / "cmp" / "compare.json"));
  EXPECT_EQ(cj["results"].size(), 2u);
  // evo_res's plots: the statistics as bars (6 a result), and, from the distributions the
  // reports saved, a box a result and the histograms.
  EXPECT_NE(r.out.find("compare_ate_stats.svg, compare_ate_box.svg, compare_ate_histogram.svg"),
            std::string::npos)
      << r.out;
  const Svg bars = parse_svg(dir_ / "cmp" / "compare_ate_stats.svg");
  EXPECT_EQ(bars.bars, 12u);
  for (const char* stat : {"rmse", "mean", "median", "std", "min", "max"})
    EXPECT_TRUE(has_text(bars, stat)) << stat;
  const nlohmann::json dg = jg["ate"]["trans"]["distribution"];
  EXPECT_EQ(dg["n"], jg["n_pairs"]);
  EXPECT_LE(dg["q1"].get<double>(), jg["ate"]["trans"]["median"].get<double>());
  EXPECT_DOUBLE_EQ(dg["median"].get<double>(), jg["ate"]["trans"]["median"].get<double>());
  size_t counted = 0;
  for (const auto& c : dg["counts"]) counted += c.get<size_t>();
  EXPECT_EQ(counted, jg["n_pairs"].get<size_t>());
  const Svg box = parse_svg(dir_ / "cmp" / "compare_ate_box.svg");
  EXPECT_EQ(box.bars, 2u);
  EXPECT_TRUE(has_text(box, "good"));
  EXPECT_TRUE(has_text(box, "poor"));
  EXPECT_EQ(parse_svg(dir_ / "cmp" / "compare_ate_histogram.svg").bars,
            dg["counts"].size() + jp["ate"]["trans"]["distribution"]["counts"].size());
  EXPECT_TRUE(fs::exists(dir_ / "cmp" / "compare_rpe_box.svg"));
  // What is not a result is named.
  const fs::path other = write("other.json", "{\"a\": 1}");
  r = run("bench compare " + other.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("other.json: not a rigcal bench result"), std::string::npos) << r.err;
  r = run("bench compare " + (dir_ / "missing").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("no such file"), std::string::npos) << r.err;
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
  // The Markdown table ranks both methods; the CSV has a header and a row per method and
  // sequence; each cumulative plot has a step curve per method with its legend.
  const std::string md = slurp(dir_ / "board" / "leaderboard.md");
  EXPECT_NE(md.find("| 1 | good |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 2 | poor |"), std::string::npos) << md;
  const std::string csv = slurp(dir_ / "board" / "leaderboard.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5) << csv;
  EXPECT_NE(csv.find("\npoor,b,0,"), std::string::npos) << csv;
  for (const char* f : {"cumulative_ate.svg", "cumulative_rpe.svg"}) {
    SCOPED_TRACE(f);
    const Svg svg = parse_svg(dir_ / "board" / f);
    EXPECT_EQ(svg.title.rfind("Cumulative ", 0), 0u) << svg.title;
    ASSERT_EQ(svg.polyline_points.size(), 2u);
    EXPECT_GE(svg.polyline_points[0], 3u);  // good: two sequences, steps up to 1
    EXPECT_GE(svg.polyline_points[1], 2u);  // poor: one of two
    EXPECT_TRUE(has_text(svg, "good"));
    EXPECT_TRUE(has_text(svg, "poor"));
    EXPECT_TRUE(has_text(svg, "fraction of sequences"));
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

// --model by rigcal's names or Kalibr's, for all cameras or each by name (different models per
// camera fitted together: each lens as when both cameras have its model, the rig and the report
// with both); Kalibr's models without a counterpart refused, named.
TEST_F(Cli, CamerasModelNamesKalibrsAndPerCamera) {
  RIGCAL_REQUIRE_FIXTURE(dir, "stereo/opencv_samples");
  const std::string out = (dir_ / "calib.yaml").string(), report = (dir_ / "report").string();
  const std::string args = "cameras --target " RIGCAL_SOURCE_DIR
                           "/targets/checkerboard_9x6_25mm.yaml --camera 'left=" +
                           dir + "/left*.jpg' --camera 'right=" + dir + "/right*.jpg' --out " +
                           out + " --report " + report + " --model ";
  CliRun r = run(args + "left=pinhole-equi,right=pinhole-equi");
  ASSERT_EQ(r.status, 0) << r.err;
  const rigcal::rig::Rig calib = rigcal::rig::read_rig_file(out);
  for (const char* cam : {"left", "right"}) {
    EXPECT_EQ(rigcal::rig::sensor(calib, cam).camera.distortion_model,
              rigcal::rig::DistortionModel::equidistant);
  }
  const auto fx = [&](const char* cam) {
    return rigcal::rig::sensor(rigcal::rig::read_rig_file(out), cam).camera.fx;
  };
  const double fx_right_equi = fx("right");
  r = run(args + "pinhole-radtan");
  ASSERT_EQ(r.status, 0) << r.err;
  const double fx_left_radtan = fx("left");
  r = run(args + "left=pinhole-radtan,right=pinhole-equi");
  ASSERT_EQ(r.status, 0) << r.err;
  const rigcal::rig::Rig mixed = rigcal::rig::read_rig_file(out);
  EXPECT_EQ(rigcal::rig::sensor(mixed, "left").camera.distortion_model,
            rigcal::rig::DistortionModel::radtan);
  EXPECT_EQ(rigcal::rig::sensor(mixed, "right").camera.distortion_model,
            rigcal::rig::DistortionModel::equidistant);
  const nlohmann::json j = nlohmann::json::parse(slurp(fs::path(report) / "cameras.json"));
  EXPECT_EQ(j["cameras"][0]["model"]["distortion_model"], "radtan");
  EXPECT_EQ(j["cameras"][1]["model"]["distortion_model"], "equidistant");
  EXPECT_EQ(j["cameras"][1]["stddev"]["distortion_coeffs"].size(), 4u);
  const double sigma_left = j["cameras"][0]["stddev"]["intrinsics"][0].get<double>();
  const double sigma_right = j["cameras"][1]["stddev"]["intrinsics"][0].get<double>();
  std::printf(
      "fx: left %.3f (radtan for both %.3f, 1-sigma %.3f), right %.3f (equidistant for "
      "both %.3f, 1-sigma %.3f)\n",
      fx("left"), fx_left_radtan, sigma_left, fx("right"), fx_right_equi, sigma_right);
  EXPECT_NEAR(fx("left"), fx_left_radtan, sigma_left);
  EXPECT_NEAR(fx("right"), fx_right_equi, sigma_right);
  struct Refusal {
    const char *model, *says;
  };
  for (const Refusal& bad :
       {Refusal{"omni-radtan", "Kalibr's omni-radtan has no counterpart in rigcal"},
        Refusal{"left=pinhole-radtan", "no model for camera 'right'"},
        Refusal{"left=pinhole-radtan,middle=pinhole-radtan", "no camera 'middle'"},
        Refusal{"pinhole-fisheye", "expected pinhole-radtan, pinhole-radtan5 or"}}) {
    r = run(args + bad.model);
    EXPECT_EQ(r.status, 2) << bad.model;
    EXPECT_NE(r.err.find(bad.says), std::string::npos) << bad.model << ": " << r.err;
  }
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
  // The quick-look PNGs at the images' size: the detection with its corners circled (green, point
  // 0 red), the residual vectors (dark blue on white), the coverage and uncertainty maps.
  const fs::path rp(report);
  // corners.vnl (mrcal's format): every image's 54 corners, one line each.
  const std::string vnl = slurp(rp / "corners.vnl");
  size_t left01 = 0;
  for (size_t at = vnl.find("left01.jpg "); at != std::string::npos;
       at = vnl.find("left01.jpg ", at + 1))
    ++left01;
  EXPECT_EQ(left01, 54u);
  const cv::Mat corners = read_png(rp / "left_corners.png", 640, 480);
  EXPECT_GT(pixels_near(corners, {0, 200, 0}, 40), 54 * 10);
  EXPECT_GT(pixels_near(corners, {0, 0, 255}, 40), 10);
  const cv::Mat residuals = read_png(rp / "left_residuals.png", 640, 480);
  EXPECT_GT(pixels_near(residuals, {255, 255, 255}, 0), static_cast<int>(residuals.total() / 2));
  EXPECT_GT(pixels_near(residuals, {120, 60, 0}, 40), 200);
  for (const char* f : {"left_coverage.png", "right_uncertainty.png"}) {
    const cv::Mat map = read_png(rp / f, 640, 480);
    if (map.empty()) continue;
    std::set<int> colours;
    for (int y = 0; y < map.rows; y += 4)
      for (int x = 0; x < map.cols; x += 4) {
        const cv::Vec3b c = map.at<cv::Vec3b>(y, x);
        colours.insert(c[0] << 16 | c[1] << 8 | c[2]);
      }
    EXPECT_GE(colours.size(), 10u) << f << ": a map of a few colours";
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
  // --saddle-fit: cornerSubPix's cache is not the fit's, so every image is detected again; the
  // fit's corners (doc/cameras.md: 0.180 px against 0.194), cached under their own header.
  r = run("cameras --target " RIGCAL_SOURCE_DIR
          "/targets/checkerboard_9x6_25mm.yaml --camera 'left=" +
          dir + "/left*.jpg' --camera 'right=" + dir + "/right*.jpg' --out " + out + " --report " +
          report + " --saddle-fit");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find("26 from"), std::string::npos) << r.out;
  const nlohmann::json j3 = nlohmann::json::parse(slurp(fs::path(report) / "cameras.json"));
  EXPECT_LT(j3["rms_2d_px"].get<double>(), j["rms_2d_px"].get<double>() - 0.01);
  EXPECT_NE(slurp(rp / "corners.vnl").find("(checkerboard 9 x 6), saddle fit\n"),
            std::string::npos);
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
  const CliRun bad = run("cameras --session " + (dir_ / "s" / "stereo").string() +
                         " --target " RIGCAL_SOURCE_DIR
                         "/targets/a3_checkerboard_8x5_40mm.yaml --bayer xyz --out " +
                         (dir_ / "d.yaml").string() + " --report " + (dir_ / "d").string());
  EXPECT_EQ(bad.status, 2);
  EXPECT_EQ(bad.err,
            "rigcal: error: Bayer pattern: expected rggb, bggr, grbg or gbrg, got 'xyz'\n");
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
    EXPECT_TRUE(r.err.find("expected a finite number") != std::string::npos ||
                r.err.find("expected seconds from") != std::string::npos)
        << opt << ": " << r.err;
  }
  r = run("bench --gt-dir " + dir_.string() + " --est-dir " + dir_.string() +
          " --methods a --ate-max nan");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--ate-max: expected a finite number > 0, got 'nan'"), std::string::npos)
      << r.err;
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
    expect_plot_png(fs::path(report) / f);

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
  EXPECT_NE(r.err.find("rigcal: error: " + (dir_ / "missing.txt").string() + ": cannot open"),
            std::string::npos)
      << r.err;
  r = run("time-offset --reference " + a.string() + " --other " + b.string() + " --out " + out3);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("give both"), std::string::npos) << r.err;
  r = run("time-offset --reference " + a.string() + " --other " + b.string() +
          " --max-offset soon");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--max-offset: expected seconds > 0 or 'all', got 'soon'"),
            std::string::npos)
      << r.err;
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
  // The whole extrinsic, T_gnss_lidar (rotation and the horizontal translation; z held at 0).
  Eigen::Matrix4d X = Eigen::Matrix4d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) X(r, c) = j["T_gnss_lidar"]["matrix"][r][c].get<double>();
  const Eigen::Matrix3d R_X = X.topLeftCorner<3, 3>();
  const Eigen::Vector3d t_X = X.topRightCorner<3, 1>();
  const std::vector<double> t_sigma = j["T_gnss_lidar"]["t_sigma_m"];
  auto angle_deg = [](const Eigen::Matrix3d& R) {
    return std::acos(std::clamp((R.trace() - 1) / 2, -1.0, 1.0)) * 180 / M_PI;
  };
  // The source's figure: its initial guess (gnss-to-top_center_lidar-extrinsic.json), the 4 x 4
  // T_lidar_gnss = yaw -90 deg, t (-1, 0, -1.3) m; OpenCalib states no calibrated result. A guess
  // in right angles and whole metres (its z, 1.3 m, the mounting height the motion cannot see):
  // the whole rotation within 1.5 deg (1.12 measured: roll 0.98, pitch -0.54 deg), x and y within
  // 0.5 m (0.19 measured).
  const nlohmann::json guess_json =
      nlohmann::json::parse(slurp(dir + "/gnss-to-top_center_lidar-extrinsic.json"));
  Eigen::Matrix4d T_lidar_gnss;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c)
      T_lidar_gnss(r, c) =
          guess_json["gnss-to-top_center_lidar-extrinsic"]["param"]["sensor_calib"]["data"][r][c]
              .get<double>();
  const Eigen::Matrix4d guess = T_lidar_gnss.inverse();  // T_gnss_lidar
  const double vs_guess_deg = angle_deg(R_X * guess.topLeftCorner<3, 3>().transpose());
  std::printf(
      "OpenCalib: rigcal t (%.4f, %.4f, %.4f) m; against the source's guess: %.3f deg, "
      "x %+.3f m, y %+.3f m\n",
      t_X.x(), t_X.y(), t_X.z(), vs_guess_deg, t_X.x() - guess(0, 3), t_X.y() - guess(1, 3));
  EXPECT_LT(vs_guess_deg, 1.5);
  EXPECT_NEAR(t_X.x(), guess(0, 3), 0.5);
  EXPECT_NEAR(t_X.y(), guess(1, 3), 0.5);
  EXPECT_NEAR(t_X.z(), 0.0, 1e-6);  // --fix z=0 (held to 7e-9 m)
  // And against an independent solve of the same files, written here: the two files' poses at the
  // same stamps, motions over 1 s (10 rows) A = inv(G_i) G_i+10, B likewise; A X = X B. Rotation
  // by Kabsch on the motions' rotation vectors; then (R_A - I) t - k R_X t_B = -t_A, linear in
  // t_x, t_y and the odometry scale k, with t_z = 0.
  auto read_poses = [](const std::string& path) {
    std::ifstream in(path);
    std::vector<std::pair<std::string, Eigen::Matrix4d>> rows;
    std::string name;
    while (in >> name) {
      Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c) in >> T(r, c);
      // Rotations as written are orthonormal to 1e-6: projected onto SO(3).
      const Eigen::JacobiSVD<Eigen::Matrix3d> svd(T.topLeftCorner<3, 3>(),
                                                  Eigen::ComputeFullU | Eigen::ComputeFullV);
      T.topLeftCorner<3, 3>() = svd.matrixU() * svd.matrixV().transpose();
      rows.emplace_back(name, T);
    }
    return rows;
  };
  const auto lidar = read_poses(dir + "/top_center_lidar-pose.txt");
  const auto gnss = read_poses(dir + "/NovAtel-pose-lidar-time.txt");
  ASSERT_EQ(lidar.size(), gnss.size());
  auto log = [](const Eigen::Matrix3d& R) {
    const Eigen::AngleAxisd aa(R);
    return Eigen::Vector3d(aa.angle() * aa.axis());
  };
  std::vector<Eigen::Matrix4d> As, Bs;
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i + 10 < lidar.size(); ++i) {
    ASSERT_EQ(lidar[i].first, gnss[i].first) << i;
    As.push_back(gnss[i].second.inverse() * gnss[i + 10].second);
    Bs.push_back(lidar[i].second.inverse() * lidar[i + 10].second);
    H += log(Bs.back().topLeftCorner<3, 3>()) * log(As.back().topLeftCorner<3, 3>()).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  S(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  const Eigen::Matrix3d R_ind = svd.matrixV() * S * svd.matrixU().transpose();
  Eigen::MatrixXd M(3 * As.size(), 3);
  Eigen::VectorXd rhs(3 * As.size());
  for (size_t k = 0; k < As.size(); ++k) {
    const Eigen::Matrix3d RA = As[k].topLeftCorner<3, 3>() - Eigen::Matrix3d::Identity();
    M.block<3, 2>(3 * k, 0) = RA.leftCols<2>();
    M.block<3, 1>(3 * k, 2) = -R_ind * Bs[k].topRightCorner<3, 1>();
    rhs.segment<3>(3 * k) = -As[k].topRightCorner<3, 1>();
  }
  const Eigen::Vector3d sol = M.colPivHouseholderQr().solve(rhs);
  const double vs_ind_deg = angle_deg(R_X * R_ind.transpose());
  std::printf(
      "OpenCalib: independent solve (%zu motions of 1 s): t (%.4f, %.4f) m, odometry scale %.5f; "
      "rigcal - independent: %.2e deg, x %+.4f m, y %+.4f m (rigcal's 1-sigma %.4f, %.4f m), "
      "scale %+.5f\n",
      As.size(), sol[0], sol[1], sol[2], vs_ind_deg, t_X.x() - sol[0], t_X.y() - sol[1], t_sigma[0],
      t_sigma[1], j["odometry_scale"]["value"].get<double>() - sol[2]);
  // Measured: 5e-6 deg; x, y 0.4 and 0.5 mm (rigcal's 1-sigma 0.7, 0.8 mm); scale 2e-5 (1-sigma
  // 1.2e-4). Asserted within 2 sigmas: the independent solve weighs every motion alike and keeps
  // the pairs rigcal's consensus flags (308).
  EXPECT_LT(vs_ind_deg, 1e-3);
  EXPECT_LE(std::abs(t_X.x() - sol[0]), 2 * t_sigma[0]);
  EXPECT_LE(std::abs(t_X.y() - sol[1]), 2 * t_sigma[1]);
  EXPECT_NEAR(j["odometry_scale"]["value"].get<double>(), sol[2],
              2 * j["odometry_scale"]["sigma"].get<double>());
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
  // What is wrong with these data, first on the page: a sixth of the pairs are outliers, and the
  // tracked camera's distances are 3 % longer than Vicon's (3.4 sigma): the checkerboard-tracked
  // PrimeSense is mis-scaled.
  const std::string page = slurp(fs::path(rep) / "report.html");
  EXPECT_NE(page.find("id=\"step-hand_eye\""), std::string::npos);
  EXPECT_NE(page.find("with 2 warnings to read below"), std::string::npos);
  EXPECT_NE(page.find("motion pairs ("), std::string::npos);
  EXPECT_NE(page.find("% longer than the GNSS/INS"), std::string::npos);
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
  // The quick-look of a pair: the camera image (1388 x 700) with the board's LiDAR points drawn
  // over it in colour (the rendered image is grey).
  const cv::Mat pair = read_png(fs::path(rep) / "pair_01.png", 1388, 700);
  int coloured = 0;
  for (int y = 0; y < pair.rows; ++y)
    for (int x = 0; x < pair.cols; ++x) {
      const cv::Vec3b c = pair.at<cv::Vec3b>(y, x);
      coloured += std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]}) > 100;
    }
  EXPECT_GT(coloured, 500) << "no LiDAR points drawn";
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
  for (const char* f : {"residuals.png", "trajectories.png"}) expect_plot_png(fs::path(rep) / f);
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
  EXPECT_NE(r.err.find("--spacing: expected seconds from 0.001"), std::string::npos) << r.err;
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

// What the full bad-input sweep (tests/sweep) found after the first round of fixes: each
// answered with exit 2 and a message naming the file or option, no input touched.
TEST_F(Cli, SweepFindingsAreBadInputNotInternalErrors) {
  const fs::path cfg = write("tiny.yaml", "seed: 3\nimu_duration_s: 4\n");
  // --force on the folder holding the inputs (here the working folder) would remove them.
  const std::string in_dir = "cd " + dir_.string() + " && ";
  const int raw = std::system((in_dir + RIGCAL_CLI +
                               " simulate --out . --force --what imu "
                               "--config tiny.yaml > out.txt 2> err.txt")
                                  .c_str());
  EXPECT_EQ(WEXITSTATUS(raw), 2);
  EXPECT_NE(slurp(dir_ / "err.txt").find("holds the current folder"), std::string::npos)
      << slurp(dir_ / "err.txt");
  EXPECT_TRUE(fs::exists(cfg));
  CliRun r =
      run("simulate --out " + dir_.string() + " --force --what imu --config " + cfg.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("holds"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(cfg));

  // A simulated IMU session: time-offset may not write into the folder it reads.
  const fs::path session = dir_ / "imus";
  ASSERT_EQ(
      run("simulate --what imu --out " + session.string() + " --config " + cfg.string()).status, 0);
  const fs::path imu_txt = session / "imu" / "data" / "imu.txt";
  const std::string before = slurp(imu_txt);
  r = run("time-offset --session " + session.string() + " --rig " + kSample +
          " --sensor imu --out " + imu_txt.string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("is an input"), std::string::npos) << r.err;
  EXPECT_EQ(slurp(imu_txt), before);
  r = run("time-offset --session " + session.string() + " --window 1e-320");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--window"), std::string::npos) << r.err;

  // Spans of seconds checked as options (they used to fail later, naming no option).
  for (const std::string opt : {"--spacing inf", "--spacing 1e-320", "--stride 1e308"}) {
    r = run("hand-eye --lidar a.tum --gnss b.tum " + opt);
    EXPECT_EQ(r.status, 2) << opt;
    EXPECT_NE(r.err.find(opt.substr(0, opt.find(' '))), std::string::npos) << r.err;
  }
  r = run("bench --gt a.txt --est b.txt --max-diff 1e308");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--max-diff"), std::string::npos) << r.err;

  // A link loop as an input: the file system's refusal is bad input (exit 2), naming the path.
  fs::create_symlink(dir_ / "loop_a", dir_ / "loop_b");
  fs::create_symlink(dir_ / "loop_b", dir_ / "loop_a");
  r = run("bench --gt " + (dir_ / "loop_a").string() + " --est " + (dir_ / "loop_a").string());
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("loop_a"), std::string::npos) << r.err;
}
