// Reads a rig with the installed library and prints T_cam_l_lidar's translation.
#include <rigcal/rig/rig_yaml.h>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 2) return 2;
  const rigcal::rig::Rig rig = rigcal::rig::read_rig_file(argv[1]);
  const rigcal::SE3 T_cam_l_lidar = rigcal::rig::T_a_b(rig, "cam_l", "lidar");
  std::printf("sensors %zu t %.4f %.4f %.4f\n", rig.sensors.size(), T_cam_l_lidar.t.x(),
              T_cam_l_lidar.t.y(), T_cam_l_lidar.t.z());
  return 0;
}
