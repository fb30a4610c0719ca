#pragma once
// vbr-devkit's files as its `convert kitti` writes them (python/vbr_devkit/datasets/kitti.py),
// for tests that build recordings exactly so.
#include <fmt/format.h>

#include <string>

namespace rigcal::testing {

// <topic>/.metadata.json of a PointCloud2 topic from the Ouster driver: its point record, 48 bytes
// as vbr-devkit stores it with --no-reduce-pcloud (x y z at 0, intensity 16, t 20, reflectivity
// 24, ring 26, ambient 28, range 32).
inline std::string ouster_metadata_json(const std::string& topic, size_t messages) {
  return fmt::format(R"({{"topic": "{}", "num_messages": {},
 "msg_type": "PointCloudXf", "fields": [
 {{"name": "x", "offset": 0, "datatype": 7, "count": 1}},
 {{"name": "y", "offset": 4, "datatype": 7, "count": 1}},
 {{"name": "z", "offset": 8, "datatype": 7, "count": 1}},
 {{"name": "intensity", "offset": 16, "datatype": 7, "count": 1}},
 {{"name": "t", "offset": 20, "datatype": 6, "count": 1}},
 {{"name": "reflectivity", "offset": 24, "datatype": 4, "count": 1}},
 {{"name": "ring", "offset": 26, "datatype": 4, "count": 1}},
 {{"name": "ambient", "offset": 28, "datatype": 4, "count": 1}},
 {{"name": "range", "offset": 32, "datatype": 6, "count": 1}}]}})",
                     topic, messages);
}

// IMU_CSV_HEADER of data/imu.txt, its repeated names included.
inline constexpr const char* kDevkitImuHeader =
    "acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,quat_w,quat_x,quat_y,quat_z,"
    "cov_acc_xx,cov_acc_xy,cov_acc_xz,cov_acc_yx,cov_acc_yy,cov_acc_zz,"
    "cov_acc_zx,cov_acc_zy,cov_acc_zz,cov_gyr_xx,cov_gyr_xy,cov_gyr_xz,"
    "cov_gyr_xx,cov_gyr_xy,cov_gyr_xz,cov_gyr_yx,cov_gyr_yy,cov_gyr_zz,"
    "cov_rot_zx,cov_rot_zy,cov_rot_zz,cov_rot_yx,cov_rot_yy,cov_rot_zz,"
    "cov_rot_zx,cov_rot_zy,cov_rot_zz";

}  // namespace rigcal::testing
