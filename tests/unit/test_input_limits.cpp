// Hostile and damaged inputs: every reader answers with one rigcal::Error naming the file, within
// documented limits, before allocating what a header claims, and without anything on stderr.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "fixtures.h"
#include "rigcal/camera/target.h"
#include "rigcal/core/error.h"
#include "rigcal/core/text.h"
#include "rigcal/io/files.h"
#include "rigcal/io/gnss_fixes.h"
#include "rigcal/io/image_io.h"
#include "rigcal/io/image_sets.h"
#include "rigcal/io/point_cloud_io.h"
#include "rigcal/io/sim_config.h"
#include "rigcal/io/target_yaml.h"
#include "rigcal/io/trajectory_io.h"
#include "rigcal/io/yaml.h"
#include "rigcal/report/json.h"
#include "rigcal/rig/rig_yaml.h"

namespace rigcal::io {
namespace {

namespace fs = std::filesystem;

using InputLimits = testing::ScratchTest;

std::string slurp_sample_rig() {
  std::ifstream in(RIGCAL_SOURCE_DIR "/data/sample_rig.yaml");
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string be32(uint32_t v) { return {char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }
std::string png_chunk(const std::string& type, const std::string& data) {
  const std::string body = type + data;
  const auto crc = static_cast<uint32_t>(
      crc32(0, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size())));
  return be32(static_cast<uint32_t>(data.size())) + body + be32(crc);
}
// A PNG whose header claims width x height, with valid CRCs and no pixel data.
std::string png_claiming(uint32_t width, uint32_t height) {
  std::string ihdr = be32(width) + be32(height) + std::string("\x08\x00\x00\x00\x00", 5);
  return std::string("\x89PNG\r\n\x1a\n", 8) + png_chunk("IHDR", ihdr) + png_chunk("IEND", "");
}
std::string encoded(const std::string& ext, const cv::Mat& image) {
  std::vector<uchar> buffer;
  cv::imencode(ext, image, buffer);
  return std::string(buffer.begin(), buffer.end());
}
cv::Mat pattern(int rows, int cols, int type) {
  cv::Mat m(rows, cols, type);
  cv::randu(m, 0, 255);
  return m;
}

TEST_F(InputLimits, ImageHeadersClaimingHugeSizesAreRefusedBeforeDecoding) {
  for (auto [w, h] : {std::pair{20000u, 20000u}, std::pair{100000u, 100000u}}) {
    const fs::path file = write("huge.png", png_claiming(w, h));
    const auto start = std::chrono::steady_clock::now();
    const std::string what = error_of([&] { read_gray(file); });
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(200));
    EXPECT_EQ(what, fmt::format("{}: {} x {} px is larger than rigcal reads (at most 32768 px a "
                                "side and 100 Mpx)",
                                file.string(), w, h));
  }
}

TEST_F(InputLimits, TinyImagesAreRefused) {
  const fs::path file = write("one.png", encoded(".png", cv::Mat(1, 1, CV_8U, cv::Scalar(7))));
  EXPECT_EQ(error_of([&] { read_gray(file); }),
            file.string() + ": 1 x 1 px is too small to hold a target (at least 16 px a side)");
}

TEST_F(InputLimits, DamagedPngIsAnErrorAndStderrStaysQuiet) {
  const cv::Mat image = pattern(40, 60, CV_8UC1);
  const std::string good = encoded(".png", image);
  EXPECT_EQ(cv::norm(read_gray(write("good.png", good)), image, cv::NORM_INF), 0);

  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;  // inside IDAT
  const fs::path damaged = write("damaged.png", flipped);
  ::testing::internal::CaptureStderr();
  const std::string what = error_of([&] { read_gray(damaged); });
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_NE(what.find(damaged.string() + ": PNG chunk 'IDAT' at byte "), std::string::npos) << what;
  EXPECT_NE(what.find("is damaged (CRC mismatch)"), std::string::npos) << what;

  // The signature alone (libpng printed "Invalid IHDR data" on stderr).
  const fs::path bare = write("bare.png", good.substr(0, 8));
  ::testing::internal::CaptureStderr();
  EXPECT_EQ(error_of([&] { read_gray(bare); }),
            bare.string() + ": PNG truncated at byte 8 (no IEND chunk)");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");

  const fs::path cut = write("cut.png", good.substr(0, good.size() - 20));
  EXPECT_NE(error_of([&] { read_gray(cut); }).find(cut.string() + ": PNG "), std::string::npos);
}

TEST_F(InputLimits, JpegDecodesExactlyAsOpenCvAndDamageIsAnError) {
  // The reader decodes JPEG itself (to keep libjpeg's warnings off stderr): it must give OpenCV's
  // pixels, colour and gray, on synthetic and real files.
  std::vector<fs::path> files{write("c.jpg", encoded(".jpg", pattern(48, 64, CV_8UC3))),
                              write("g.jpg", encoded(".jpg", pattern(48, 64, CV_8UC1)))};
  if (const std::string real = testing::fixture("stereo/opencv_samples/left01.jpg"); !real.empty())
    files.push_back(real);
  for (const fs::path& f : files) {
    cv::Mat expected = cv::imread(f.string(), cv::IMREAD_UNCHANGED);
    if (expected.channels() == 3) cv::cvtColor(expected, expected, cv::COLOR_BGR2GRAY);
    const cv::Mat mine = read_gray(f);
    ASSERT_EQ(mine.size(), expected.size()) << f;
    EXPECT_EQ(cv::norm(mine, expected, cv::NORM_INF), 0) << f;
  }
  const std::string good = encoded(".jpg", pattern(64, 64, CV_8UC1));
  const fs::path cut = write("cut.jpg", good.substr(0, good.size() / 2));
  ::testing::internal::CaptureStderr();
  const std::string what = error_of([&] { read_gray(cut); });
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_EQ(what.rfind(cut.string() + ": the JPEG is damaged (", 0), 0u) << what;
}

TEST_F(InputLimits, OnlyTheFormatsOfACameraRigReachADecoder) {
  // PNG, TIFF, PNM and BMP (8 and 16 bit) give OpenCV's pixels.
  const cv::Mat gray8 = pattern(20, 24, CV_8UC1), color = pattern(20, 24, CV_8UC3);
  cv::Mat random16(20, 24, CV_16UC1);
  cv::randu(random16, 0, 65535);
  const cv::Mat gray16 = random16;
  for (const std::string ext : {".png", ".tif", ".pgm", ".bmp"}) {
    for (const cv::Mat* image : {&gray8, &color, &gray16}) {
      if (image->depth() == CV_16U && (ext == ".bmp" || ext == ".pgm")) continue;
      if (image->channels() == 3 && ext == ".pgm") continue;  // PGM is gray only
      const fs::path f = write("i" + ext, encoded(ext, *image));
      cv::Mat expected = cv::imread(f.string(), cv::IMREAD_UNCHANGED);
      if (expected.depth() == CV_16U) expected.convertTo(expected, CV_8U, 1.0 / 256);
      if (expected.channels() == 3) cv::cvtColor(expected, expected, cv::COLOR_BGR2GRAY);
      const cv::Mat mine = read_gray(f);
      ASSERT_EQ(mine.size(), expected.size()) << ext;
      EXPECT_EQ(cv::norm(mine, expected, cv::NORM_INF), 0) << ext;
    }
  }
  // A TIFF's size is read from its first directory before decoding: width 40000 is refused.
  std::string tiff = encoded(".tif", gray8);
  ASSERT_EQ(tiff.substr(0, 4), std::string("II*\0", 4));
  uint32_t ifd;
  std::memcpy(&ifd, tiff.data() + 4, 4);
  uint16_t entries;
  std::memcpy(&entries, tiff.data() + ifd, 2);
  bool patched = false;
  for (uint16_t k = 0; k < entries; ++k) {
    char* e = tiff.data() + ifd + 2 + 12 * k;
    uint16_t tag, type;
    std::memcpy(&tag, e, 2);
    std::memcpy(&type, e + 2, 2);
    if (tag != 256) continue;
    const uint32_t width = 40000;
    if (type == 3) std::memcpy(e + 8, &width, 2);  // 40000 fits a SHORT
    if (type == 4) std::memcpy(e + 8, &width, 4);
    patched = true;
  }
  ASSERT_TRUE(patched);
  const fs::path wide = write("wide.tif", tiff);
  EXPECT_EQ(error_of([&] { read_gray(wide); }),
            wide.string() +
                ": 40000 x 20 px is larger than rigcal reads (at most 32768 px a side "
                "and 100 Mpx)");
  const fs::path bare = write("bare.tif", tiff.substr(0, 8));
  EXPECT_EQ(error_of([&] { read_gray(bare); }),
            bare.string() + ": TIFF without its width and height in the first directory");
  // Samples wider than the reader keeps are refused from the header.
  const fs::path floats = write("f.tif", encoded(".tif", cv::Mat(20, 24, CV_32FC1, 0.5)));
  EXPECT_EQ(error_of([&] { read_gray(floats); }),
            floats.string() + ": a TIFF of 32-bit samples (rigcal reads 8 or 16 bit)");
  // Formats OpenCV decodes but rigcal does not read are refused before any decoder sees them.
  for (const std::string ext : {".webp", ".jp2", ".hdr", ".ras", ".pfm", ".pam"}) {
    std::vector<uchar> buffer;
    try {
      if (!cv::imencode(ext, ext == ".hdr" || ext == ".pfm" ? cv::Mat(color) : gray8, buffer))
        continue;
    } catch (const cv::Exception&) {
      continue;  // no encoder in this OpenCV: nothing to refuse
    }
    const fs::path f = write("i" + ext, std::string(buffer.begin(), buffer.end()));
    EXPECT_EQ(error_of([&] { read_gray(f); }),
              f.string() + ": not an image rigcal reads (PNG, JPEG, TIFF, PNM or BMP)");
  }
}

TEST_F(InputLimits, PcdPointCountsAreCheckedAgainstTheData) {
  const std::string head =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH {0}\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {0}\nDATA {1}\n";
  const std::string two_points = "1 2 3\n4 5 6\n";
  struct Case {
    std::string points, kind, data, message;
  };
  const std::string binary_two(24, '\x01');
  const std::vector<Case> cases{
      {"4000000000", "binary", binary_two,
       "binary PCD of 24 data bytes does not hold its 4000000000 points of 12 bytes"},
      {"3", "binary", binary_two, "binary PCD of 24 data bytes does not hold its 3 points"},
      {"1", "binary", binary_two, "binary PCD of 24 data bytes does not hold its 1 points"},
      {"4000000000", "ascii", two_points, "2 points, the header's POINTS says 4000000000"},
      {"1", "ascii", two_points, ":12: more points than the header's POINTS 1"},
      {"-5", "ascii", two_points, ":6: WIDTH: -5 is outside 0..4294967295"},
      {"x", "ascii", two_points, ":6: WIDTH: expected an integer, got 'x'"},
  };
  for (const Case& c : cases) {
    const fs::path file =
        write("c.pcd", fmt::format(fmt::runtime(head), c.points, c.kind) + c.data);
    const std::string what = error_of([&] { read_point_cloud(file); });
    EXPECT_EQ(what.rfind(file.string(), 0), 0u) << what;
    EXPECT_NE(what.find(c.message), std::string::npos) << what << "\nexpected: " << c.message;
  }
  const fs::path ok = write("ok.pcd", fmt::format(fmt::runtime(head), 2, "ascii") + two_points);
  EXPECT_EQ(read_point_cloud(ok).size(), 2u);
}

TEST_F(InputLimits, YamlSizeAndAliasExpansionAreBounded) {
  const std::string big(kMaxYamlBytes + 1, '#');
  const fs::path file = write("big.yaml", big);
  EXPECT_EQ(error_of([&] { rig::read_rig_file(file); }),
            fmt::format("{}: {} bytes, over the limit of {} bytes for this kind of file",
                        file.string(), big.size(), kMaxYamlBytes));
  EXPECT_NE(error_of([&] { load_yaml(big, "x.yaml"); }).find("x.yaml: "), std::string::npos);

  // "Billion laughs": nine levels of ten aliases expand to 10^9 nodes from 500 bytes.
  std::string bomb = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i < 9; ++i) {
    bomb += fmt::format("a{}: &a{} [", i, i);
    for (int k = 0; k < 10; ++k) bomb += fmt::format("{}*a{}", k ? ", " : "", i - 1);
    bomb += "]\n";
  }
  const auto start = std::chrono::steady_clock::now();
  const std::string what = error_of([&] { load_yaml(bomb, "bomb.yaml"); });
  EXPECT_EQ(what.rfind("bomb.yaml:", 0), 0u) << what;
  EXPECT_NE(what.find(": more than 1000000 YAML nodes once anchors and aliases are expanded"),
            std::string::npos)
      << what;
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));

  // An alias inside its own anchor is infinitely deep: an error, not a stack overflow.
  EXPECT_EQ(error_of([&] { load_yaml("x: &x [*x]\n", "self.yaml"); }),
            "self.yaml:1: YAML nested deeper than 200 levels (or an alias inside itself)");
  // A sensor name with invalid UTF-8 is refused, its bytes quoted as \xNN.
  const std::string rig = slurp_sample_rig();
  const size_t at = rig.find("\nlidar:");
  ASSERT_NE(at, std::string::npos);
  std::string bad = rig;
  bad.replace(at + 1, 5,
              "li\xFF"
              "ar");
  const std::string name_error = error_of([&] { rig::parse_rig_yaml(bad, "r.yaml"); });
  // Refused as text that is not UTF-8, on the sensor's line, before any key is read.
  EXPECT_NE(name_error.find("r.yaml:30: bytes that are not UTF-8"), std::string::npos)
      << name_error;
  EXPECT_EQ(name_error, printable(name_error, 1000));  // the message itself stays printable
}

TEST_F(InputLimits, TargetsOutsideWhatPeoplePrintAreRefused) {
  const std::string board =
      "target_type: checkerboard\ntargetCols: {}\ntargetRows: 5\nrowSpacingMeters: {}\n"
      "colSpacingMeters: {}\n{}";
  auto message = [&](const std::string& cols, const std::string& square, const std::string& extra) {
    return error_of([&] {
      parse_target_yaml(fmt::format(fmt::runtime(board), cols, square, square, extra), "t.yaml");
    });
  };
  EXPECT_EQ(message("5000", "0.01", ""), "t.yaml:2: key 'targetCols': 5000 is outside 1..200");
  EXPECT_EQ(message("1e8", "0.01", ""), "t.yaml:2: key 'targetCols': 100000000 is outside 1..200");
  EXPECT_EQ(
      message("8", "1e300", ""),
      "t.yaml: target 't': size: the board would be 1.1e+301 x 8e+300 m; at most 10 m a side");
  EXPECT_EQ(message("8", ".nan", ""),
            "t.yaml:4: key 'rowSpacingMeters': expected a finite number, got '.nan'");
  EXPECT_EQ(message("8", "0.04", "margin: -1\n"), "t.yaml:6: key 'margin': must be >= 0 m");
  EXPECT_EQ(message("8", "0.04", "thickness: 3\n"),
            "t.yaml: target 't': thickness: must be in [0, 0.2] m");
  EXPECT_EQ(message("8", "0.04", "name: [a, b]\n"), "t.yaml:6: key 'name': expected a text value");
  EXPECT_NO_THROW(parse_target_yaml(fmt::format(fmt::runtime(board), 8, 0.04, 0.04, ""), "t.yaml"));
}

TEST_F(InputLimits, PipesAreRefusedNotWaitedOn) {
  const fs::path fifo = dir_ / "pipe.yaml";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(error_of([&] { rig::read_rig_file(fifo); }),
            fifo.string() + ": a pipe or socket, expected a file");
}

// Two writers on one output folder: the second is refused while the first holds it, so the
// folder ends with one run's complete output, never a mixture; the claim ends with its holder.
TEST_F(InputLimits, OneRunPerOutputFolder) {
  const fs::path out = dir_ / "out";
  {
    const FolderLock first(out);
    EXPECT_EQ(error_of([&] { FolderLock second(out); }),
              out.string() +
                  ": another rigcal run is writing this folder; wait for it to end or choose "
                  "another output folder");
    // Another process: rigcal calibrate on the held folder stops before reading anything.
    const std::string cmd =
        fmt::format("{} calibrate {} --out {} 2> {}", RIGCAL_CLI, (dir_ / "no_session").string(),
                    out.string(), (dir_ / "err.txt").string());
    EXPECT_EQ(WEXITSTATUS(std::system(cmd.c_str())), 2);
    std::ifstream err(dir_ / "err.txt");
    std::string line;
    std::getline(err, line);
    EXPECT_NE(line.find("another rigcal run is writing this folder"), std::string::npos) << line;
  }
  EXPECT_NO_THROW(FolderLock again(out));
  EXPECT_EQ(std::distance(fs::directory_iterator(out), fs::directory_iterator{}), 0);
}

TEST_F(InputLimits, MetadataJsonLargerThanAnyMessageTypeIsRefusedUnparsed) {
  const fs::path bin = write("ouster_points/data/0000000000.bin", std::string(16 * 1024, '\0'));
  // Valid JSON whose size alone is past the limit: a parser would take it.
  write("ouster_points/.metadata.json",
        "{\"fields\": [], \"pad\": \"" + std::string(kMaxMetadataBytes, 'x') + "\"}");
  const std::string e = error_of([&] { read_point_cloud(bin); });
  EXPECT_NE(e.find(".metadata.json: "), std::string::npos) << e;
  EXPECT_NE(e.find("over the limit of 1048576 bytes"), std::string::npos) << e;
}

TEST_F(InputLimits, TopicStampsOutOfOrderOrRepeatedAreRefusedWithTheLine) {
  for (const char* f : {"a.png", "b.png", "c.png"}) write(fs::path("cam/data") / f, "");
  write("cam/timestamps.txt", "1.0\n2.0\n3.0\n");
  EXPECT_EQ(read_stamped_folder(dir_ / "cam", ".png").stamps.size(), 3u);
  write("cam/timestamps.txt", "1.0\n2.0\n2.0\n");
  std::string e = error_of([&] { read_stamped_folder(dir_ / "cam", ".png"); });
  EXPECT_NE(e.find("timestamps.txt:3: stamp 2.000000000 is not after the previous line's"),
            std::string::npos)
      << e;
  write("cam/timestamps.txt", "1970-01-01T00:00:02\n1970-01-01T00:00:01\n3\n");
  e = error_of([&] { read_stamped_folder(dir_ / "cam", ".png"); });
  EXPECT_NE(e.find("timestamps.txt:2: "), std::string::npos) << e;
  // A stamp past the range read (its difference with another would overflow) names the range.
  write("cam/timestamps.txt", "-4611686018\n0\n9223372036.8\n");
  e = error_of([&] { read_stamped_folder(dir_ / "cam", ".png"); });
  EXPECT_NE(e.find("timestamps.txt:3: "), std::string::npos) << e;
  EXPECT_NE(e.find("146 years"), std::string::npos) << e;
  // A garbage byte in a stamp is quoted escaped.
  write("cam/timestamps.txt", "1\n2\xFF\n3\n");
  e = error_of([&] { read_stamped_folder(dir_ / "cam", ".png"); });
  EXPECT_NE(e.find("'2\\xFF'"), std::string::npos) << e;
}

TEST_F(InputLimits, YamlIsOneDocumentOfStandardTagsWithoutNulOrRepeatedKeys) {
  EXPECT_NE(error_of([] {
              load_yaml("a: 1\n---\nb: 2\n", "x.yaml");
            }).find("x.yaml:3: a second YAML document"),
            std::string::npos);
  EXPECT_NO_THROW(load_yaml("a: 1\n---\n", "x.yaml"));  // an empty second document
  EXPECT_NE(error_of([] {
              load_yaml("---\na: 1\n...\n---\n# c\n...\nb: 2\n", "x.yaml");
            }).find("x.yaml:7: a second YAML document"),
            std::string::npos);
  // A lone ',' makes yaml-cpp 0.7's parser return empty documents without end (YAML::LoadAll
  // then fills memory): read as one empty document, in bounded time.
  for (const char* comma : {",", "\n,\n", "a: 1\n---\n,\n"})
    EXPECT_NO_THROW(load_yaml(comma, "x.yaml")) << comma;
  EXPECT_NE(error_of([] {
              load_yaml("a: 1\nb: !!binary aGVsbG8=\n", "x.yaml");
            }).find("x.yaml:2: YAML tag 'tag:yaml.org,2002:binary'"),
            std::string::npos);
  EXPECT_NO_THROW(load_yaml("a: !!str 1\nb: !!float 2\n", "x.yaml"));
  EXPECT_NO_THROW(load_yaml("name: caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80\n", "x.yaml"));
  for (const char* bad : {"a: 1\nname: x\xFF\n", "a: 1\nname: \xC0\xAF\n",
                          "a: 1\nname: \xED\xA0\x80\n", "a: 1\nname: \xE2\x82\n"}) {
    EXPECT_NE(
        error_of([&] { load_yaml(bad, "x.yaml"); }).find("x.yaml:2: bytes that are not UTF-8"),
        std::string::npos)
        << bad;
  }
  EXPECT_NE(error_of([] {
              load_yaml(std::string("a: 1\n# x\0y\n", 11), "x.yaml");
            }).find("x.yaml:2: a NUL byte"),
            std::string::npos);
  // Repeated keys in a target and a simulator config (the calibration YAML has its own words).
  const std::string target =
      "target_type: checkerboard\ntargetCols: 8\ntargetRows: 5\nrowSpacingMeters: 0.04\n"
      "colSpacingMeters: 0.04\n";
  EXPECT_NO_THROW(parse_target_yaml(target, "t.yaml"));
  EXPECT_NE(error_of([&] {
              parse_target_yaml(target + "targetCols: 9\n", "t.yaml");
            }).find("t.yaml:6: key 'targetCols': given twice"),
            std::string::npos);
  sim::SimConfig config;
  EXPECT_NE(error_of([&] {
              apply_sim_config("seed: 1\nimu: {rate_hz: 100, rate_hz: 200}\n", "s.yaml", config);
            }).find("s.yaml:2: key 'rate_hz': given twice"),
            std::string::npos);
}

TEST_F(InputLimits, PositionsAndHeightsBeyondAnyRigAreRefused) {
  const std::string e =
      error_of([] { parse_trajectory("0 0 0 0 0 0 0 1\n1 1e308 0 0 0 0 0 1\n", "t.tum", {}); });
  EXPECT_NE(e.find("t.tum:2: position (1e+308, 0, 0) m lies beyond 1e+09 m"), std::string::npos)
      << e;
  const std::string f = error_of([] {
    parse_gnss_fixes("time,lat,lon,height,roll,pitch,yaw\n0,41.9,12.5,-1e7,0,0,0\n", "f.csv",
                     Attitude::enu);
  });
  EXPECT_NE(f.find("f.csv:2: height -10000000 m outside -12 km to 100 km"), std::string::npos) << f;
}

TEST_F(InputLimits, ReplacingAFolderNeverRemovesAnInput) {
  const fs::path in = write("out/config.yaml", "seed: 1\n");
  EXPECT_NE(error_of([&] {
              refuse_replacing_inputs(dir_ / "out", {{"--config", in}});
            }).find("holds an input (--config"),
            std::string::npos);
  EXPECT_NO_THROW(refuse_replacing_inputs(dir_ / "other", {{"--config", in}}));
  EXPECT_NE(error_of([] {
              refuse_replacing_inputs(fs::current_path().parent_path(), {});
            }).find("holds the current folder"),
            std::string::npos);
  // An input behind a link loop cannot be resolved: compared as written, never "equal" to an
  // unrelated output (the check said ": is an input" of an empty output before).
  fs::create_symlink(dir_ / "b", dir_ / "a");
  fs::create_symlink(dir_ / "a", dir_ / "b");
  EXPECT_NO_THROW(
      refuse_outputs_over_inputs({{dir_ / "x.yaml", ""}, {"", ""}}, {{"--lidar", dir_ / "a"}}));
  EXPECT_THROW(refuse_outputs_over_inputs({{dir_ / "a", ""}}, {{"--lidar", dir_ / "a"}}), Error);
}

TEST(ReportJson, InvalidUtf8InNamesIsReplacedNotThrown) {
  nlohmann::json j;
  j["method"] = "m1\xFF";  // a name quoted from a damaged file
  const std::string text = report::json_text(j);
  EXPECT_NE(text.find("m1\xEF\xBF\xBD"), std::string::npos) << text;  // U+FFFD
  EXPECT_EQ(text.back(), '\n');
}

TEST(Printable, InvalidBytesAndLineBreaksAreEscapedAndLongTextCut) {
  EXPECT_EQ(printable("caf\xC3\xA9"), "caf\xC3\xA9");  // valid UTF-8 kept
  EXPECT_EQ(printable("a\xFF"), "a\\xFF");
  EXPECT_EQ(printable("a\xC3"), "a\\xC3");                  // a sequence cut at the end
  EXPECT_EQ(printable("\xED\xA0\x80"), "\\xED\\xA0\\x80");  // a surrogate
  EXPECT_EQ(printable("one\ntwo\r"), "one\\x0Atwo\\x0D");
  EXPECT_EQ(printable(std::string(100, 'x'), 10), "xxxxxxxxxx...");
  try {
    parse_double("1.5\xFE", "gain");
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "gain: expected a number, got '1.5\\xFE'");
  }
}

}  // namespace
}  // namespace rigcal::io
