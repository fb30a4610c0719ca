#!/usr/bin/env python3
"""Writes the hand-made seeds of tests/fuzz/corpus/ (small valid inputs of each format, the binary
ones included). Run from anywhere: python3 tests/fuzz/make_seeds.py. The real files (data/,
targets/, the shared fixtures) are added at run time by run_fuzz.sh, not copied here. The bag and
ROS message seeds are written by make_bag_seeds.py (Debian's Python with python3-rosbag)."""
import os
import struct

here = os.path.dirname(os.path.abspath(__file__))


def seed(target, name, content):
    d = os.path.join(here, "corpus", target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(content if isinstance(content, bytes) else content.encode())


seed("sim_config", "every_section.yaml", """seed: 7
base_start_s: 1000.0
stereo: {views: 4, min_fill: 0.3, max_fill: 0.8, max_tilt_deg: 40, max_roll_deg: 20, margin_px: 10, frame_period_s: 0.5}
image: {supersample: 2, blur_sigma_px: 0.6, black_dn: 8, white_dn: 230, background_dn: 90, gain_dn_per_e: 0.05, read_noise_dn: 1.5, vignetting: 0.2, bayer: false}
lidar: {model: os1-64, range_noise_m: 0.01}
lidar_camera: {pairs: 3, camera: cam_l, clutter: false}
imu: {rate_hz: 200, jitter_s: 0.0001, drift_ppm: 20, gaps: [[10, 11], [20, 20.5]]}
os_imu: {rate_hz: 100}
imu_duration_s: 30
imu_motion: car
trajectories:
  duration_s: 60
  motion: handheld
  odometry: {trans_sigma_m: 0.01, rot_sigma_deg: 0.1, scale_error: 0.01}
  gnss: {rate_hz: 10, horizontal_sigma_m: 0.02, vertical_sigma_m: 0.05, rot_sigma_deg: 0.2, outages: [[5, 8]], outlier_probability: 0.01, outlier_jump_m: 2}
scans: {count: 2}
""")

seed("trajectory_kitti", "poses_and_times.txt",
     "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0.8 0 1 0 0 0 0 1 0.01\n1 0 0 1.6 0 1 0 0.1 0 0 1 0.02\n"
     "--times--\n0.0\n0.103\n0.2066\n")
seed("trajectory_euroc", "euroc.csv",
     "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n"
     "1403715523912143104,-1.0,0.4,1.3,0.6,-0.0,-0.8,0.0\n"
     "1403715523917143040,-1.0,0.4,1.3,0.6,-0.0,-0.8,0.0\n")
seed("trajectory_tum", "tum_header.txt",
     "#timestamp tx ty tz qx qy qz qw\n366.63 0 0 0 0 0 0 1\n366.68 0.1 0 0 0 0 0.01 0.99995\n")

header = ("acc_x,acc_y,acc_z,gyr_x,gyr_y,gyr_z,quat_w,quat_x,quat_y,quat_z,"
          "cov_acc_xx,cov_acc_xy,cov_acc_xz,cov_acc_yx,cov_acc_yy,cov_acc_zz,"
          "cov_acc_zx,cov_acc_zy,cov_acc_zz,cov_gyr_xx,cov_gyr_xy,cov_gyr_xz,"
          "cov_gyr_xx,cov_gyr_xy,cov_gyr_xz,cov_gyr_yx,cov_gyr_yy,cov_gyr_zz,"
          "cov_rot_zx,cov_rot_zy,cov_rot_zz,cov_rot_yx,cov_rot_yy,cov_rot_zz,"
          "cov_rot_zx,cov_rot_zy,cov_rot_zz")
rows, stamps = [], []
for k in range(6):
    stamps.append("1970-01-01T00:16:40.%09d" % (5000000 * k))
    rows.append(",".join(["0.1", "-0.2", "9.81", "0.01", "%.3f" % (0.02 * k), "-0.03", "1", "0", "0", "0"]
                         + ["-1"] + ["0"] * 26))
seed("rates_vbr", "devkit_imu.txt", "\n".join(stamps) + "\n--imu.txt--\n" + header + "\n" + "\n".join(rows) + "\n")
seed("rates_table", "table7.txt", "# t wx wy wz ax ay az\n" + "".join(
    "%.3f 0.01 0.02 %.3f 0.1 0.2 9.8\n" % (0.01 * k, 0.001 * k) for k in range(8)))
seed("rates_table", "tum_poses.txt", "".join(
    "%.2f 0 0 0 0 0 %.6f %.6f\n" % (0.1 * k, 0.01 * k, (1 - (0.01 * k) ** 2) ** 0.5) for k in range(8)))

seed("gnss_fixes", "fixes.csv", "time,lat,lon,height,roll,pitch,yaw,std_east,std_north,std_up\n" + "".join(
    "%.1f,41.8902,%.7f,50.0,0.5,-0.2,%.1f,0.02,0.02,0.05\n" % (100 + 0.1 * k, 12.4922 + 1e-6 * k, 10.0 * k)
    for k in range(5)))
seed("gnss_fixes", "iso_stamps.csv", "timestamp,latitude,longitude,altitude,roll,pitch,heading\n"
     "2024-03-20T10:00:00.000Z,41.9,12.5,40,0,0,90\n2024-03-20T10:00:00.100Z,41.9000001,12.5,40,0,0,91\n")
seed("gnss_fixes", "fix_types.csv", "time,latitude,longitude,height,std_east,std_north,std_up,status,fix_type\n"
     "1000.000000000,41.8902100000,12.4922310000,69.0000,0.0100,0.0100,0.0200,2,fixed\n"
     "1000.010000000,41.8902100900,12.4922310000,69.0010,0.2000,0.2000,0.4000,2,float\n"
     "1000.020000000,41.8902101800,12.4922310000,69.0020,1.5000,1.5000,3.0000,0,single\n")
seed("gnss_fixes", "navsat_covariance.csv",
     "time,latitude,longitude,height,status,service,covariance_type,std_east,std_north,std_up,cov_en,cov_eu,cov_nu\n"
     "1.0,41.9,12.5,50,2,1,3,0.02,0.03,0.05,0.0003,0.0001,-0.0002\n2.0,41.9000001,12.5,50,2,1,3,0.02,0.03,0.05,0.0003,0.0001,-0.0002\n")
seed("gnss_fixes", "rtklib_q.csv", "time,lat,lon,height,Q\n1,41.9,12.5,50,1\n2,41.9,12.5,50,2\n3,41.9,12.5,50,5\n")

seed("marker_survey", "positions.csv", "# a total station\nid,x,y,z\nM1,7.5692,-2.1187,-0.9299\n"
     "M2 15.4002 -4.4094 -0.2299\nM3,26.7303,-4.1680,0.4701\n")
seed("marker_survey", "distances.csv", "a,b,distance\nM1,M2,8.1891\nM2,M3,11.3543\nM1,M3,19.3212\n")

pts = [(1.0 + 0.1 * k, -2.0 + 0.05 * k, 0.5, 10.0 * k) for k in range(6)] + [(0.0, 0.0, 0.0, 0.0)]
hdr = ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity\n"
       "SIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH %d\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
       "POINTS %d\nDATA " % (len(pts), len(pts)))
seed("point_cloud_pcd", "ascii.pcd", hdr + "ascii\n" + "".join("%g %g %g %g\n" % p for p in pts))
seed("point_cloud_pcd", "binary.pcd", (hdr + "binary\n").encode() + b"".join(struct.pack("<4f", *p) for p in pts))
hdr_d = ("VERSION 0.7\nFIELDS x y z ring\nSIZE 8 8 8 2\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 3\nHEIGHT 1\n"
         "POINTS 3\nDATA binary\n")
seed("point_cloud_pcd", "double_ring.pcd", hdr_d.encode() + b"".join(
    struct.pack("<3dH", 1.0 * k + 1, 2.0, 3.0, k) for k in range(3)))

seed("point_cloud_bin", "kitti.bin", b"".join(struct.pack("<4f", *p) for p in pts))
meta = ('{"topic": "/ouster/points", "num_messages": 1, "msg_type": "PointCloudXf", "fields": [\n'
        '{"name": "x", "offset": 0, "datatype": 7, "count": 1},\n'
        '{"name": "y", "offset": 4, "datatype": 7, "count": 1},\n'
        '{"name": "z", "offset": 8, "datatype": 7, "count": 1},\n'
        '{"name": "intensity", "offset": 16, "datatype": 7, "count": 1},\n'
        '{"name": "t", "offset": 20, "datatype": 6, "count": 1},\n'
        '{"name": "reflectivity", "offset": 24, "datatype": 4, "count": 1},\n'
        '{"name": "ring", "offset": 26, "datatype": 4, "count": 1},\n'
        '{"name": "ambient", "offset": 28, "datatype": 4, "count": 1},\n'
        '{"name": "range", "offset": 32, "datatype": 6, "count": 1}]}')
rec = b""
for k in range(1024):
    r = bytearray(48)
    struct.pack_into("<3f", r, 0, 1.0 + 0.01 * k, -2.0 + 0.003 * k, 0.5)
    struct.pack_into("<fIHHHxxI", r, 16, 100.0, 48828 * (k // 128), 40, k % 128, 7, 3000 + k)
    rec += bytes(r)
seed("point_cloud_bin", "full_field.bin", (meta + "\n--bin--\n").encode() + rec)

lines = ["# rigcal corners of target checkerboard_9x6_25mm (checkerboard 9 x 6)", "# filename x y level"]
for p in range(54):
    lines.append("left01.jpg %.3f %.3f 0" % (100 + 20 * (p % 9), 80 + 20 * (p // 9)))
lines.append("left02.jpg - - -")
seed("corners_vnl", "two_images.vnl", "\n".join(lines) + "\n")

seed("session", "every_key.yaml", "cameras: stereo\nlidar_camera: lidar_camera\nmotion: motion\n"
     "target: target.yaml\nrig: rig.yaml\nodometry: motion/gnss/poses.tum\ngnss: motion/gnss/poses.tum\n")
seed("session", "defaults.yaml", "# every purpose found by default\n")

import zlib


def png(width, height, bit_depth, color_type, channels, palette=None):
    """A valid PNG of a gradient (filter 0 rows), written with zlib."""
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    bpp = channels * bit_depth // 8
    raw = b""
    for y in range(height):
        row = bytearray()
        for x in range(width):
            v = (x * 16 + y * 3) % 256
            row += bytes([v] * bpp)
        raw += b"\x00" + bytes(row)
    ihdr = struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, 0)
    body = chunk(b"IHDR", ihdr)
    if palette is not None:
        body += chunk(b"PLTE", palette)
    return b"\x89PNG\r\n\x1a\n" + body + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


seed("image", "gray8_16x16.png", png(16, 16, 8, 0, 1))
seed("image", "gray16_20x16.png", png(20, 16, 16, 0, 1))
seed("image", "rgb8_16x18.png", png(16, 18, 8, 2, 3))
seed("image", "rgba8_16x16.png", png(16, 16, 8, 6, 4))
seed("image", "palette_16x16.png", png(16, 16, 8, 3, 1, bytes(range(256)) * 3))
seed("image", "pgm_16x16.pgm", b"P5\n16 16\n255\n" + bytes((x * 16) % 256 for x in range(256)))

seed("timestamps", "iso.txt", "".join("1970-01-01T00:16:40.%09d\n" % (33333333 * k) for k in range(3)))
seed("timestamps", "seconds.txt", "1403715529.112143517\n1403715529.145476850\n1403715529.178810183\n")
seed("timestamps", "edges.txt", "-4611686018.427387903\n0\n4611686018.427387903\n")

# Ouster: a tiny sensor (4 beams, 32 columns, 2 packets a frame) as metadata JSON, `--pcap--`, pcap.
import json


def ouster_meta(profile):
    return json.dumps({
        "prod_line": "OS-1-16", "prod_sn": "122", "initialization_id": 5, "lidar_mode": "32x10",
        "image_rev": "ousteros-image-prod-aries-v2.3.0", "udp_port_lidar": 7502, "udp_port_imu": 7503,
        "beam_altitude_angles": [15.0, 5.0, -5.0, -15.0], "beam_azimuth_angles": [3.0, 1.0, -1.0, -3.0],
        "lidar_origin_to_beam_origin_mm": 15.806,
        "data_format": {"pixels_per_column": 4, "columns_per_frame": 32, "columns_per_packet": 16,
                        "column_window": [0, 31], "pixel_shift_by_row": [3, 1, -1, -3],
                        "udp_profile_lidar": profile, "udp_profile_imu": "LEGACY"}})


def ouster_lidar_packet(profile, frame_id, first_column):
    cols = b""
    for c in range(16):
        ts = 1_000_000_000 + frame_id * 100_000_000 + (first_column + c) * 3_125_000
        if profile == "LEGACY":
            blocks = b"".join(struct.pack("<IHHHH", 5000 + 100 * u, 30, 200, 50, 0) for u in range(4))
            cols += struct.pack("<QHHI", ts, first_column + c, frame_id, 0) + blocks + b"\xff\xff\xff\xff"
        else:  # RNG15_RFL8_NIR8: range in 8 mm units, flags, reflectivity, near-IR / 16
            blocks = b"".join(struct.pack("<I", (625 + 10 * u) | (40 << 16) | (3 << 24)) for u in range(4))
            cols += struct.pack("<QHH", ts, first_column + c, 1) + blocks
    if profile == "LEGACY":
        return cols
    header = struct.pack("<HHI", 1, frame_id, 5 | ((122 & 0xFF) << 24)) + struct.pack("<I", 122 >> 8)
    return header + bytes(32 - len(header)) + cols + bytes(32)


def ouster_imu_packet(t):
    return struct.pack("<QQQffffff", t, t, t, 0.01, -0.02, 1.0, 0.5, -0.3, 0.1)


def pcap(datagrams):
    out = struct.pack("<IHHiIII", 0xA1B2C3D4, 2, 4, 0, 0, 65535, 1)
    for k, (port, payload, fragments) in enumerate(datagrams):
        udp = struct.pack(">HHHH", 7502, port, 8 + len(payload), 0) + payload
        pieces = [udp] if fragments == 1 else [udp[:(len(udp) // 2) & ~7], udp[(len(udp) // 2) & ~7:]]
        at = 0
        for i, piece in enumerate(pieces):
            more = 0x2000 if i + 1 < len(pieces) else 0
            ip = struct.pack(">BBHHHBBH4s4s", 0x45, 0, 20 + len(piece), 100 + k, more | (at // 8), 64, 17,
                             0, bytes([10, 5, 5, 87]), bytes([10, 5, 5, 1]))
            frame = bytes(6) + bytes([0, 1, 2, 3, 4, 5]) + b"\x08\x00" + ip + piece
            out += struct.pack("<IIII", 1000, 1000 * (k + 1), len(frame), len(frame)) + frame
            at += len(piece)
    return out


for profile in ("RNG15_RFL8_NIR8", "LEGACY"):
    grams = []
    for frame_id in (7, 8):
        for first in (0, 16):
            grams.append((7502, ouster_lidar_packet(profile, frame_id, first), 2 if first == 16 else 1))
        grams.append((7503, ouster_imu_packet(1_000_000_000 + frame_id * 100_000_000), 1))
    grams.append((7502, ouster_lidar_packet(profile, 6, 0), 1))  # stale: before the last frame
    seed("ouster", "tiny_%s.txt" % profile.lower(),
         ouster_meta(profile).encode() + b"\n--pcap--\n" + pcap(grams))
