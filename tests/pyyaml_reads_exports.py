#!/usr/bin/python3
"""Python VBR loaders read the calibration with PyYAML (YAML 1.1). Check that PyYAML reads the
files rigcal writes with every number a float (1.0, 1.0e-05: YAML 1.1 needs the '.'), the same
numbers as the sample rig, and that T_cam_lidar = inv(cam.T_b) * lidar.T_b can be formed.
Usage: pyyaml_reads_exports.py RIGCAL SAMPLE WORKDIR"""
import subprocess, sys, os, yaml

rigcal, sample, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
src = yaml.safe_load(open(sample))
for fmt in ("rigcal", "vbr"):
    out = os.path.join(work, fmt + ".yaml")
    subprocess.run([rigcal, "rig", "convert", sample, "--to", fmt, "--out", out], check=True,
                   stdout=subprocess.DEVNULL)
    got = yaml.safe_load(open(out))
    for cam in ("cam_l", "cam_r"):
        for key in ("intrinsics", "distortion_coeffs"):
            assert all(type(v) is float for v in got[cam][key]), (fmt, cam, key, got[cam][key])
            assert got[cam][key] == [float(v) for v in src[cam][key]], (fmt, cam, key)
        assert got[cam]["resolution"] == src[cam]["resolution"]
    for name in ("cam_l", "cam_r", "lidar", "imu", "os_imu"):
        T = got[name]["T_b"]
        assert len(T) == 4 and all(len(r) == 4 for r in T), (fmt, name)
        assert all(type(v) is float for r in T for v in r), (fmt, name, T)
        assert T == [[float(v) for v in r] for r in src[name]["T_b"]], (fmt, name)
    for key in ("gyroscope_noise_density", "accelerometer_random_walk", "update_rate"):
        assert type(got["imu"][key]) is float and got["imu"][key] == float(src["imu"][key]), key
    # inv(cam.T_b) * lidar.T_b with lidar.T_b = I: R^T, -R^T t.
    T = got["cam_l"]["T_b"]
    R = [r[:3] for r in T[:3]]
    t = [r[3] for r in T[:3]]
    t_cam_lidar = [-sum(R[k][i] * t[k] for k in range(3)) for i in range(3)]
    print(fmt, "ok; cam_l t_cam_lidar =", ["%.4f" % v for v in t_cam_lidar])
