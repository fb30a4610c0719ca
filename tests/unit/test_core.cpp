// Core types: SE3 algebra and conversions, exact time parsing, strict number parsing.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <random>

#include "rigcal/core/error.h"
#include "rigcal/core/se3.h"
#include "rigcal/core/text.h"
#include "rigcal/core/time.h"

namespace rigcal {
namespace {

SE3 random_se3(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return SE3::from_rotation_vector(Eigen::Vector3d(n(rng), n(rng), n(rng)),
                                   Eigen::Vector3d(n(rng), n(rng), n(rng)));
}

TEST(SE3, ComposesAndInvertsWithFramesInTheRightOrder) {
  // T_a_b: a rotated 90 deg about z from b, b's origin at (1, 0, 0) in a.
  SE3 T_a_b;
  T_a_b.R = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_a_b.t = Eigen::Vector3d(1, 0, 0);
  const Eigen::Vector3d p_b(1, 0, 0);
  EXPECT_TRUE((T_a_b * p_b).isApprox(Eigen::Vector3d(1, 1, 0), 1e-15));
  EXPECT_TRUE((T_a_b.inverse() * (T_a_b * p_b)).isApprox(p_b, 1e-15));

  std::mt19937 rng(7);
  const SE3 T_b_c = random_se3(rng);
  const Eigen::Vector3d p_c(0.3, -2.0, 5.0);
  EXPECT_TRUE(((T_a_b * T_b_c) * p_c).isApprox(T_a_b * (T_b_c * p_c), 1e-14));
  EXPECT_TRUE((T_a_b.matrix() * T_b_c.matrix()).isApprox((T_a_b * T_b_c).matrix(), 1e-14));
}

TEST(SE3, RotationVectorRoundTripsIncludingSmallAndNearPiAngles) {
  for (double angle : {0.0, 1e-14, 1e-9, 1e-3, 0.5, 3.0, M_PI - 1e-9}) {
    const Eigen::Vector3d phi = angle * Eigen::Vector3d(1, -2, 0.5).normalized();
    const Eigen::Matrix3d R = rotation_from_vector(phi);
    EXPECT_LT((rotation_vector(R) - phi).norm(), 1e-12 + 1e-8 * (angle > 3.1)) << angle;
    EXPECT_NEAR(rotation_angle(R), angle, 1e-12 + 1e-8 * (angle > 3.1)) << angle;
  }
}

TEST(SE3, RollPitchYawFollowZYXOrder) {
  const Eigen::Matrix3d R = from_roll_pitch_yaw(0.1, -0.2, 0.3);
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  EXPECT_TRUE(R.isApprox(expected, 1e-15));
  EXPECT_TRUE(roll_pitch_yaw(R).isApprox(Eigen::Vector3d(0.1, -0.2, 0.3), 1e-14));
}

TEST(SE3, QuaternionAndTextConversions) {
  std::mt19937 rng(3);
  const SE3 T = random_se3(rng);
  const SE3 back = se3_from_text(to_text(T));
  EXPECT_LT((back.R - T.R).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(back.t, T.t);
  EXPECT_GE(T.quaternion().w(), 0.0);
  EXPECT_THROW(se3_from_text("1 2 3 0 0 0"), Error);
  EXPECT_THROW(se3_from_text("1 2 3 0 0 0 0"), Error);
}

TEST(SE3, NearestRotationAndOrthonormalityError) {
  Eigen::Matrix3d M = from_roll_pitch_yaw(0.3, 0.2, 0.1);
  M(0, 1) += 1e-3;
  EXPECT_GT(orthonormality_error(M), 5e-4);
  const Eigen::Matrix3d R = nearest_rotation(M);
  EXPECT_LT(orthonormality_error(R), 1e-15);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-15);
}

// Newton-Schulz steps give the SVD's nearest rotation for rotations written with 7 to 10 digits
// (KITTI rows) and with errors up to 1e-3; farther, or reflected, the SVD itself.
TEST(SE3, NearestRotationOfANearMatrixIsTheSvds) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  for (double size : {1e-10, 1e-7, 1e-4, 3e-4}) {
    for (int trial = 0; trial < 50; ++trial) {
      Eigen::Matrix3d M = from_roll_pitch_yaw(3 * noise(rng), noise(rng), 3 * noise(rng));
      for (int i = 0; i < 9; ++i) M(i / 3, i % 3) += size * noise(rng);
      const Eigen::Matrix3d R = nearest_rotation_near(M);
      EXPECT_LT((R - nearest_rotation(M)).cwiseAbs().maxCoeff(), 2e-15) << size;
      EXPECT_LE(orthonormality_error(R), 4e-15) << size;  // the rounding floor of R'R
    }
  }
  Eigen::Matrix3d far = from_roll_pitch_yaw(0.3, 0.2, 0.1);
  far(0, 1) += 0.1;
  EXPECT_EQ(nearest_rotation_near(far), nearest_rotation(far));
  const Eigen::Matrix3d reflection = Eigen::Vector3d(1, 1, -1).asDiagonal();
  EXPECT_EQ(nearest_rotation_near(reflection), nearest_rotation(reflection));
}

// parse_double's fast path for short decimals gives from_chars' double to the bit, on numbers
// printed as trajectory files print them (KITTI's %.9e, %.6f, shortest round trip, integers,
// leading and trailing zeros, signs, exponents near the path's limits).
TEST(Text, ParseDoubleEqualsFromCharsToTheBit) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> power(-30, 30);
  std::vector<std::string> texts = {"0",
                                    "-0",
                                    "0.0",
                                    "1.",
                                    ".5",
                                    "-.25",
                                    "1e22",
                                    "1e23",
                                    "9e-22",
                                    "1.000000000e+00",
                                    "-0.000000000e+00",
                                    "007.50",
                                    "1E5",
                                    "9007199254740993",
                                    "9007199254740992",
                                    "123456789012345678",
                                    "0.1000000000000000055511151231257827"};
  for (int k = 0; k < 20000; ++k) {
    const double v = unit(rng) * std::pow(10.0, power(rng));
    for (const char* format : {"{:.9e}", "{:.6f}", "{}", "{:.3f}", "{:.15g}", "{:.0f}"})
      texts.push_back(fmt::format(fmt::runtime(format), v));
  }
  for (const std::string& text : texts) {
    double want = 0;
    std::from_chars(text.data(), text.data() + text.size(), want);
    const double got = parse_double(text, "x");
    EXPECT_EQ(std::bit_cast<uint64_t>(got), std::bit_cast<uint64_t>(want)) << text;
  }
}

TEST(Time, ParsesDecimalSecondsExactly) {
  EXPECT_EQ(parse_seconds("1403715529.112143517").ns, 1403715529112143517LL);
  EXPECT_EQ(parse_seconds("1.403715529112143517e+09").ns, 1403715529112143517LL);
  EXPECT_EQ(parse_seconds("366.660458140").ns, 366660458140LL);
  EXPECT_EQ(parse_seconds("-0.5").ns, -500000000LL);
  EXPECT_EQ(parse_seconds("+2").ns, 2000000000LL);
  EXPECT_EQ(parse_seconds(".25").ns, 250000000LL);
  EXPECT_EQ(parse_seconds("1e-9").ns, 1);
  // Digits beyond the nanosecond round half away from zero.
  EXPECT_EQ(parse_seconds("0.0000000015").ns, 2);
  EXPECT_EQ(parse_seconds("0.0000000014999").ns, 1);
  EXPECT_EQ(parse_seconds("-0.0000000015").ns, -2);
  EXPECT_EQ(parse_seconds("0.0000000004").ns, 0);
  // The range read: below 2^62 ns, so that the difference of any two read times is
  // representable.
  EXPECT_EQ(parse_seconds("4611686018.427387903").ns, kMaxReadNs);
  EXPECT_EQ(parse_seconds("-4611686018.427387903").ns, -kMaxReadNs);
  for (const char* bad : {"", "abc", "1.2.3", "1e", "12s", "nan", "4611686018.427387904",
                          "-4611686018.4273879035", "9223372036.854775807", "1e30"}) {
    EXPECT_THROW(parse_seconds(bad), Error) << bad;
  }
  EXPECT_EQ(parse_nanoseconds("4611686018427387903").ns, kMaxReadNs);
  EXPECT_THROW(parse_nanoseconds("4611686018427387904"), Error);
  EXPECT_THROW(parse_nanoseconds("-9223372036854775808"), Error);
  EXPECT_NO_THROW(parse_iso8601("2116-01-01T00:00:00"));
  EXPECT_THROW(parse_iso8601("2117-01-01T00:00:00"), Error);
  EXPECT_THROW(parse_iso8601("1823-01-01T00:00:00"), Error);
  EXPECT_THROW(Time::from_seconds(4.7e9), Error);
  const Time latest = parse_seconds("4611686018.427387903");
  const Time earliest = parse_seconds("-4611686018.427387903");
  EXPECT_EQ((latest - earliest).ns, INT64_MAX - 1);  // 2^63 - 2, no overflow
}

TEST(Time, ParsesIso8601AndPrintsBack) {
  const Time t = parse_iso8601("1970-01-01T00:06:06.660458140");
  EXPECT_EQ(t.ns, 366660458140LL);
  EXPECT_EQ(to_iso8601(t), "1970-01-01T00:06:06.660458140");
  EXPECT_EQ(parse_time("2024-03-20T12:00:00Z").ns, 1710936000LL * 1000000000LL);
  EXPECT_EQ(parse_time("2024-03-20T13:30:00+01:30").ns, 1710936000LL * 1000000000LL);
  EXPECT_EQ(parse_time("2024-03-20 12:00:00.5").ns, 1710936000500000000LL);
  EXPECT_EQ(to_iso8601(Time{-1}), "1969-12-31T23:59:59.999999999");
  EXPECT_EQ(parse_iso8601(to_iso8601(Time{-1})).ns, -1);
  for (const char* bad :
       {"2024-02-30T00:00:00", "2024-03-20T25:00:00", "2024-03-20", "2024-03-20T1:00:00"}) {
    EXPECT_THROW(parse_iso8601(bad), Error) << bad;
  }
}

TEST(Time, SecondsTextIsLossless) {
  EXPECT_EQ(to_seconds_text(Time{366660458140LL}), "366.660458140");
  EXPECT_EQ(to_seconds_text(Time{-1}), "-0.000000001");
  EXPECT_EQ(to_seconds_text(Time{INT64_MIN}), "-9223372036.854775808");
  std::mt19937_64 rng(11);
  for (int i = 0; i < 1000; ++i) {
    const Time t{static_cast<int64_t>(rng()) / 2};  // the range read: below 2^62 ns
    EXPECT_EQ(parse_seconds(to_seconds_text(t)), t);
  }
  EXPECT_EQ(Time::from_seconds(1.5).ns, 1500000000LL);
  EXPECT_EQ(parse_nanoseconds("1403715529112143517").ns, 1403715529112143517LL);
  EXPECT_THROW(parse_nanoseconds("14037.5"), Error);
}

TEST(Text, NumbersParseStrictlyAndFormatLosslessly) {
  EXPECT_DOUBLE_EQ(parse_double(" 1.5 ", "x"), 1.5);
  EXPECT_THROW(parse_double("1.5x", "x"), Error);
  EXPECT_THROW(parse_double("nan", "x"), Error);
  EXPECT_THROW(parse_double("inf", "x"), Error);
  EXPECT_THROW(parse_double("1e999", "x"), Error);
  EXPECT_EQ(format_double(0.1), "0.1");
  EXPECT_EQ(format_double(1.0, true), "1.0");
  EXPECT_EQ(format_double(1e-5, true), "1.0e-05");
  EXPECT_EQ(format_double(-2.5e-7, true), "-2.5e-07");
  std::mt19937_64 rng(5);
  for (int i = 0; i < 10000; ++i) {
    uint64_t bits = rng();
    double v;
    std::memcpy(&v, &bits, sizeof v);
    if (!std::isfinite(v)) continue;
    EXPECT_EQ(parse_double(format_double(v, true), "x"), v);
  }
  const auto f = split_fields("1.0, 2.0\t 3.0  4\r");
  ASSERT_EQ(f.size(), 4u);
  EXPECT_EQ(f[3], "4");
}

}  // namespace
}  // namespace rigcal
