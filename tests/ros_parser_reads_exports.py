#!/usr/bin/python3
"""ROS reads camera_info files with camera_calibration_parsers (Debian package
python3-camera-calibration-parsers). Export the sample rig (and the same rig with equidistant
lenses) with `rigcal rig convert --to ros`, read each file through ROS's own parser, and check
size, K, D, R and P against the rig: K and D as in the rig, R and P a stereo rectification of the
rig's extrinsic (both rectified frames one orientation, the baseline along x, Tx = -f' B).
Usage: ros_parser_reads_exports.py RIGCAL SAMPLE WORKDIR"""
import math, os, shutil, subprocess, sys

import yaml
from camera_calibration_parsers import readCalibration

rigcal, sample, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(len(b))) for j in range(len(b[0]))]
            for i in range(len(a))]


def transpose(a):
    return [list(r) for r in zip(*a)]


def close(a, b, tol, what):
    assert len(a) == len(b), (what, a, b)
    for x, y in zip(a, b):
        assert abs(x - y) <= tol, (what, list(a), list(b))


def check(rig_file, tag):
    rig = yaml.safe_load(open(rig_file))
    out = os.path.join(work, tag)
    shutil.rmtree(out, ignore_errors=True)
    subprocess.run([rigcal, "rig", "convert", rig_file, "--to", "ros", "--out", out], check=True,
                   stdout=subprocess.DEVNULL)
    info = {}
    for cam in ("cam_l", "cam_r"):
        got = readCalibration(os.path.join(out, cam + ".yaml"))
        assert got is not None, (tag, cam, "camera_calibration_parsers could not read it")
        name, ci = got
        assert name == cam, (tag, name)
        src = rig[cam]
        fx, fy, cx, cy = src["intrinsics"]
        assert [ci.width, ci.height] == src["resolution"], (tag, cam, ci.width, ci.height)
        assert list(ci.K) == [fx, 0, cx, 0, fy, cy, 0, 0, 1], (tag, cam, ci.K)
        d = [float(v) for v in src["distortion_coeffs"]]
        if src["distortion_model"] == "radtan":
            assert ci.distortion_model == "plumb_bob", (tag, cam, ci.distortion_model)
            d += [0.0] * (5 - len(d))  # plumb_bob is k1 k2 p1 p2 k3
        else:
            assert ci.distortion_model == "equidistant", (tag, cam, ci.distortion_model)
        assert list(ci.D) == d, (tag, cam, ci.D, d)
        R = [list(ci.R[3 * i:3 * i + 3]) for i in range(3)]
        close(sum(matmul(R, transpose(R)), []), [1, 0, 0, 0, 1, 0, 0, 0, 1], 1e-12, (tag, cam))
        info[cam] = (R, list(ci.P), src)
    # The rig's extrinsic cam_l -> cam_r: p_r = R_rl p_l + t_rl, from the T_b (p_base = T_b p).
    Tl, Tr = info["cam_l"][2]["T_b"], info["cam_r"][2]["T_b"]
    Rl, Rr = [r[:3] for r in Tl[:3]], [r[:3] for r in Tr[:3]]
    tl, tr = [r[3] for r in Tl[:3]], [r[3] for r in Tr[:3]]
    R_rl = matmul(transpose(Rr), Rl)
    t_rl = [v[0] for v in matmul(transpose(Rr), [[a - b] for a, b in zip(tl, tr)])]
    baseline = math.sqrt(sum(v * v for v in t_rl))
    (R1, P1, _), (R2, P2, _) = info["cam_l"], info["cam_r"]
    # Both rectified frames have one orientation: R2 R_rl R1^T = I.
    close(sum(matmul(matmul(R2, R_rl), transpose(R1)), []), [1, 0, 0, 0, 1, 0, 0, 0, 1], 1e-9,
          (tag, "R2 R_rl R1^T"))
    # The baseline in the rectified frame lies along x: R2 t_rl = (-B, 0, 0) for cam_r right of cam_l.
    close([v[0] for v in matmul(R2, [[v] for v in t_rl])], [-baseline, 0, 0], 1e-9,
          (tag, "R2 t_rl"))
    # One rectified camera: P1 = [f' 0 cx' 0; 0 f' cy' 0; 0 0 1 0], P2 the same with Tx = -f' B.
    f = P1[0]
    assert f > 0 and P1[5] == f and P2[0] == f and P2[5] == f, (tag, P1, P2)
    close([P1[1], P1[3], P1[4], P1[7], P1[8], P1[9], P1[10], P1[11]], [0, 0, 0, 0, 0, 0, 1, 0],
          0, (tag, "P1"))
    close(P2[4:12], P1[4:12], 0, (tag, "P2 rows 2-3"))
    close([P2[1], P2[2]], [P1[1], P1[2]], 0, (tag, "P2 row 1"))
    close([P2[3]], [-f * baseline], 1e-9 * f, (tag, "P2 Tx"))
    print(tag, "ok: camera_calibration_parsers read cam_l and cam_r; f' = %.3f px, B = %.4f m"
          % (f, baseline))


check(sample, "sample")
# The same rig with equidistant lenses (distortion coefficients kept: any four numbers do).
text = open(sample).read().replace("distortion_model: radtan", "distortion_model: equidistant")
fisheye = os.path.join(work, "fisheye_rig.yaml")
open(fisheye, "w").write(text)
check(fisheye, "equidistant")
