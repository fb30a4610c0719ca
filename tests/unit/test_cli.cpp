// The command line as a user runs it: exit statuses, one-line errors, nothing written on failure.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

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
                       ":2: key 'cam_l.intrinsics': focal lengths fx, fy must be > 0, got fx = 0, "
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

}  // namespace
