#pragma once
// GNSS/INS fixes as CSV (doc/hand-eye.md, "GNSS fixes"): a header line naming the columns, then
// one fix a line. Required columns (any order, case-insensitive): time (or t, timestamp: seconds
// or ISO-8601 UTC), latitude (lat), longitude (lon), height (alt, altitude: ellipsoidal, m), roll,
// pitch, yaw (or heading), in degrees; read for positions only (no attitude convention given),
// the attitude columns are not needed. Optional: the standard deviations std_east, std_north,
// std_up (m), status (sensor_msgs/NavSatFix's: -1 no fix, 0 fix, 1 SBAS, 2 GBAS/RTK; what
// `rigcal convert` writes to navsat.csv), the covariance's off-diagonal terms cov_en, cov_eu,
// cov_nu (m^2, with the three standard deviations: NavSatFix's full covariance, as navsat.csv
// has it), and fix_type (or q, quality: the solution's type, which
// NavSatFix's status cannot tell, RTK fixed from float: RTKLIB's Q codes 1 fixed, 2 float,
// 5 single, and 3 SBAS and 4 DGPS read as single, 6 PPP as float; or the words fixed, float,
// single; anything else is an error). Converted with GeographicLib to a local ENU frame at the
// first fix (or a given origin): T_enu_gnss, the body frame being the one the attitude convention
// defines.
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/core/trajectory.h"

namespace rigcal::io {

enum class Attitude {
  // R_enu_body = Rz(yaw) Ry(pitch) Rx(roll); yaw counter-clockwise from east; the body frame is
  // whatever the INS reports attitude for (typically x right, y forward, z up in ENU-style INS).
  enu,
  // The aviation / NovAtel-SBG convention: heading clockwise from north, body x forward, y right,
  // z down: R_ned_body = Rz(yaw) Ry(pitch) Rx(roll), then R_enu_ned.
  ned,
};
Attitude attitude_from_string(std::string_view name);  // enu | ned

struct GeodeticOrigin {
  double latitude_deg = 0, longitude_deg = 0, height_m = 0;
};
// "LAT,LON,HEIGHT" (degrees, degrees, ellipsoidal m); throws rigcal::Error naming `what` on
// anything else (three numbers, latitude within +-90, longitude within +-180, height within
// -12 km to 100 km).
GeodeticOrigin parse_geodetic_origin(std::string_view text, std::string_view what);

// The type of a fix's solution (the fixes' optional fix_type column).
enum class FixType { rtk_fixed, rtk_float, single };
std::string_view to_string(FixType type);  // fixed | float | single

struct GnssFixes {
  Trajectory T_enu_gnss;  // without attitude (has_attitude false) every rotation is the identity
  bool has_attitude = true;
  std::vector<Eigen::Vector3d> std_enu_m;  // one a fix when the file gives them, else empty
  // One a fix when the file gives the off-diagonal terms with the standard deviations, else
  // empty: the whole ENU covariance (m^2).
  std::vector<Eigen::Matrix3d> covariance_enu_m2;
  std::vector<int> status;        // one a fix when the file gives it, else empty
  std::vector<FixType> fix_type;  // one a fix when the file gives it, else empty
  GeodeticOrigin origin;          // of the ENU frame
  std::optional<double> median_horizontal_std_m, median_vertical_std_m;  // when given
};

// True when the file's first non-comment line is a header naming a latitude column.
bool is_gnss_fixes_file(const std::filesystem::path& path);

// Throws rigcal::Error naming file, line and column on a missing column, a bad number, a
// latitude outside [-90, 90], stamps that do not increase.
// `attitude` none: positions only.
GnssFixes parse_gnss_fixes(std::string_view text, std::string_view file_name,
                           std::optional<Attitude> attitude,
                           const std::optional<GeodeticOrigin>& origin = std::nullopt);
GnssFixes read_gnss_fixes(const std::filesystem::path& path, std::optional<Attitude> attitude,
                          const std::optional<GeodeticOrigin>& origin = std::nullopt);

// Fixes as this reader reads them, positions only: time (s), latitude, longitude (10 decimals:
// 11 um), height, std_east, std_north, std_up (one a fix), status (NavSatFix's: 2 for RTK fixed
// and float, 0 for single) and fix_type (fixed, float, single; one a fix); the positions
// (T_enu_gnss's) taken from the ENU frame at `origin`.
std::string gnss_fixes_csv(const Trajectory& T_enu_gnss,
                           const std::vector<Eigen::Vector3d>& std_enu_m,
                           const std::vector<FixType>& fix_type, const GeodeticOrigin& origin);

}  // namespace rigcal::io
