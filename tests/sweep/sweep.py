#!/usr/bin/env python3
"""rigcal bad-input sweep (stdlib only).

  sweep.py RIGCAL SOURCE_DIR WORK_DIR [--quick] [--seed N] [--jobs 2] [--timeout 20]
           [--only SUBSTRING] [--fixtures DIR]

Runs rigcal on bad inputs of every kind (missing, empty, directories, unreadable files, link loops,
garbage, truncations, bit flips, byte insertions and deletions, BOM, CRLF, invalid UTF-8, NaN/Inf,
huge counts, YAML bombs, huge files, bad option values, outputs naming inputs, concurrent writers)
and checks rigcal's promise on each: exit 0, 2 (bad input: one stderr line naming the file) or 3
(the data do not determine the answer, where documented); never 1, a signal, a hang or a memory
blow-up; no input changed; no temporary file left; nothing half-written on failure.

Writes WORK_DIR/sweep.json (every case) and WORK_DIR/summary.txt; exits 1 when any case violates
the promise. The same seed gives the same cases and the same mutated bytes.
"""
import argparse
import hashlib
import json
import os
import random
import re
import resource
import shutil
import signal
import stat
import struct
import subprocess
import sys
import threading
import time
import zlib

MEM_LIMIT = 4 << 30          # RLIMIT_AS of every rigcal run
RSS_LIMIT_KB = 2 << 20       # peak RSS above 2 GB is a violation
NOBODY = 65534

SEVERITY = ["signal", "hang", "memory", "exit-1", "unexpected-exit", "input-changed",
            "half-written", "temp-left", "no-message", "multi-line-stderr",
            "message-invalid-utf8", "message-not-naming-file", "accepted-invalid", "concurrency"]


def crc(s):
    return zlib.crc32(s.encode())


def sha256_file(p):
    h = hashlib.sha256()
    with open(p, "rb") as f:
        for b in iter(lambda: f.read(1 << 20), b""):
            h.update(b)
    return h.hexdigest()


# ------------------------------------------------------------------------------------------
# File-tree snapshots: content of every file (sha256), links, directories.

_hash_cache = {}
_hash_lock = threading.Lock()


def file_digest(p, st):
    key = (st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns)
    with _hash_lock:
        if key in _hash_cache:
            return _hash_cache[key]
    try:
        d = sha256_file(p)
    except OSError as e:
        d = "unreadable:" + e.__class__.__name__
    with _hash_lock:
        _hash_cache[key] = d
    return d


def snapshot(root):
    """{relative path: descriptor} of everything under root (root itself may be a file)."""
    out = {}
    if not os.path.lexists(root):
        return out

    def one(p, rel):
        try:
            st = os.lstat(p)
        except OSError:
            return
        if stat.S_ISLNK(st.st_mode):
            out[rel] = "link:" + os.readlink(p)
        elif stat.S_ISDIR(st.st_mode):
            out[rel] = "dir"
            try:
                names = sorted(os.listdir(p))
            except OSError:
                names = []
            for n in names:
                one(os.path.join(p, n), os.path.join(rel, n) if rel else n)
        elif stat.S_ISREG(st.st_mode):
            out[rel] = "file:" + file_digest(p, st)
        else:
            out[rel] = "other"
    one(root, "")
    return out


TEMP_RE = re.compile(r"(\.tmp|\.partial|\.part$|~$|^\.#|\.swp$|^tmp[A-Za-z0-9_]{4,}$|\.new$|\.lock$)")


def looks_temp(name):
    return bool(TEMP_RE.search(name)) or (name.startswith(".") and name != ".metadata.json")


# ------------------------------------------------------------------------------------------
# Mutations

NUM_RE = re.compile(rb"-?\d+(\.\d+)?([eE][-+]?\d+)?")
BAD_NUMBERS = [b"nan", b"NaN", b"inf", b"-inf", b"1e308", b"-1e308", b"1e309", b"1e-320", b"-1",
               b"0", b"4000000000", b"99999999999999999999999", b"-9223372036854775809", b"",
               b"abc", b"0x10", b"1,5", b".", b"1e", b"+-1", b"\xff\xfe"]


def mutate_text(data, rng):
    """One random mutation of a text file; returns (bytes, description)."""
    lines = data.split(b"\n")
    op = rng.choice(["trunc", "bitflip", "insert", "delete", "delline", "dupline", "swaplines",
                     "number", "number", "number", "longtoken", "utf8", "indent", "misspell",
                     "emptyline", "sep"])
    n = len(data)
    if op == "trunc" or n < 4:
        k = rng.randrange(0, max(1, n))
        return data[:k], f"truncated at byte {k} of {n}"
    if op == "bitflip":
        b = bytearray(data)
        desc = []
        for _ in range(rng.randint(1, 3)):
            i = rng.randrange(n)
            bit = rng.randrange(8)
            b[i] ^= 1 << bit
            desc.append(f"byte {i} bit {bit}")
        return bytes(b), "bit flip " + ", ".join(desc)
    if op == "insert":
        i = rng.randrange(n)
        ins = bytes(rng.randrange(256) for _ in range(rng.randint(1, 4)))
        return data[:i] + ins + data[i:], f"inserted {ins.hex()} at byte {i}"
    if op == "delete":
        i = rng.randrange(n)
        k = rng.randint(1, 8)
        return data[:i] + data[i + k:], f"deleted {k} bytes at byte {i}"
    if op == "delline" and len(lines) > 1:
        i = rng.randrange(len(lines))
        return b"\n".join(lines[:i] + lines[i + 1:]), f"deleted line {i + 1}"
    if op == "dupline" and len(lines) > 1:
        i = rng.randrange(len(lines))
        return b"\n".join(lines[:i + 1] + lines[i:]), f"duplicated line {i + 1}"
    if op == "swaplines" and len(lines) > 2:
        i, j = sorted(rng.sample(range(len(lines)), 2))
        l2 = list(lines)
        l2[i], l2[j] = l2[j], l2[i]
        return b"\n".join(l2), f"swapped lines {i + 1} and {j + 1}"
    if op in ("number", "longtoken", "utf8", "sep"):
        ms = list(NUM_RE.finditer(data[:2_000_000]))
        if ms:
            m = ms[rng.randrange(len(ms))]
            line = data.count(b"\n", 0, m.start()) + 1
            if op == "number":
                rep = rng.choice(BAD_NUMBERS)
            elif op == "longtoken":
                rep = b"9" * rng.choice([400, 5000, 200000])
            elif op == "utf8":
                rep = m.group(0) + rng.choice([b"\xff", b"\xc3\x28", b"\xe2\x82", b"\xed\xa0\x80"])
            else:
                rep = m.group(0) + rng.choice([b";", b"\t\t", b"  ,", b"\x00", b"\r"])
            return (data[:m.start()] + rep + data[m.end():],
                    f"line {line}: number '{m.group(0).decode(errors='replace')}' -> {rep[:40]!r}"
                    + (f" (x{len(rep)})" if len(rep) > 40 else ""))
    if op == "indent" and len(lines) > 1:
        i = rng.randrange(len(lines))
        l2 = list(lines)
        l2[i] = rng.choice([b" ", b"   ", b"\t", b""]) + l2[i].lstrip(b" ")
        return b"\n".join(l2), f"re-indented line {i + 1}"
    if op == "misspell":
        keys = list(re.finditer(rb"(?m)^\s*([A-Za-z_][A-Za-z0-9_]{2,}):", data))
        if keys:
            m = keys[rng.randrange(len(keys))]
            k = bytearray(m.group(1))
            i = rng.randrange(len(k) - 1)
            k[i], k[i + 1] = k[i + 1], k[i]
            line = data.count(b"\n", 0, m.start()) + 1
            return (data[:m.start(1)] + bytes(k) + data[m.end(1):],
                    f"line {line}: key '{m.group(1).decode()}' -> '{k.decode()}'")
    if op == "emptyline" and len(lines) > 1:
        i = rng.randrange(len(lines))
        l2 = list(lines)
        l2[i] = b""
        return b"\n".join(l2), f"emptied line {i + 1}"
    k = rng.randrange(0, max(1, n))
    return data[:k], f"truncated at byte {k} of {n}"


def mutate_binary(data, rng, header=64):
    op = rng.choice(["trunc", "bitflip", "bitflip_head", "insert", "delete", "zero", "append",
                     "overwrite_head"])
    n = len(data)
    if op == "trunc":
        k = rng.randrange(0, n)
        return data[:k], f"truncated at byte {k} of {n}"
    if op in ("bitflip", "bitflip_head"):
        b = bytearray(data)
        lim = min(n, header) if op == "bitflip_head" else n
        desc = []
        for _ in range(rng.randint(1, 4)):
            i = rng.randrange(lim)
            bit = rng.randrange(8)
            b[i] ^= 1 << bit
            desc.append(f"{i}.{bit}")
        return bytes(b), "bit flip (byte.bit) " + " ".join(desc)
    if op == "insert":
        i = rng.randrange(n)
        k = rng.choice([1, 2, 3, 4, 7, 16])
        return data[:i] + bytes(rng.randrange(256) for _ in range(k)) + data[i:], f"inserted {k} bytes at {i}"
    if op == "delete":
        i = rng.randrange(n)
        k = rng.choice([1, 2, 3, 4, 7, 16])
        return data[:i] + data[i + k:], f"deleted {k} bytes at {i}"
    if op == "zero":
        i = rng.randrange(n)
        k = rng.randint(1, 4096)
        return data[:i] + bytes(min(k, n - i)) + data[i + k:], f"zeroed {k} bytes at {i}"
    if op == "append":
        k = rng.choice([1, 3, 15, 17, 1000])
        return data + bytes(rng.randrange(256) for _ in range(k)), f"appended {k} random bytes"
    i = rng.randrange(min(n, header))
    k = rng.randint(1, 8)
    return data[:i] + bytes(rng.randrange(256) for _ in range(k)) + data[i + k:], f"overwrote {k} header bytes at {i}"


def png_chunk(t, payload):
    return struct.pack(">I", len(payload)) + t + payload + struct.pack(">I", zlib.crc32(t + payload))


def png_image(w, h, rows=None, depth=8, ctype=0):
    if rows is None:
        rows = b"".join(b"\x00" + bytes(w) for _ in range(h))
    return (b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, ctype, 0, 0, 0))
            + png_chunk(b"IDAT", zlib.compress(rows)) + png_chunk(b"IEND", b""))


def png_with_size(data, w, h):
    """The PNG with its IHDR claiming w x h (CRC fixed)."""
    assert data[12:16] == b"IHDR"
    ihdr = bytearray(data[16:29])
    ihdr[0:8] = struct.pack(">II", w, h)
    return data[:8] + png_chunk(b"IHDR", bytes(ihdr)) + data[33:]


# ------------------------------------------------------------------------------------------
# The sweep

class Case:
    __slots__ = ("id", "group", "kind", "cmd", "cwd", "desc", "invalid", "names", "outs",
                 "reports", "inputs", "allow3", "as_nobody", "cost", "setup", "tokens_line",
                 "result", "post")

    def __init__(self, **kw):
        self.invalid = False
        self.names = []
        self.outs = []
        self.reports = []
        self.inputs = []
        self.allow3 = False
        self.as_nobody = False
        self.cost = 1.0
        self.setup = None
        self.tokens_line = False
        self.result = None
        self.post = None
        for k, v in kw.items():
            setattr(self, k, v)


class Sweep:
    def __init__(self, a):
        self.a = a
        self.work = os.path.abspath(a.work)
        self.src = os.path.abspath(a.source)
        self.fix = os.path.abspath(a.fixtures) if a.fixtures else os.path.join(os.path.dirname(self.src), "shared", "fixtures")
        if not os.path.isdir(self.fix):
            self.fix = "/work/shared/fixtures"
        self.base = os.path.join(self.work, "base")
        self.cases_dir = os.path.join(self.work, "cases")
        self.bin = os.path.join(self.work, "bin", "rigcal")
        self.rng = random.Random(a.seed)
        self.cases = []
        self.n = 0

    # ---- base inputs -------------------------------------------------------------------
    def rig(self, args, cwd, timeout=300):
        p = subprocess.run([self.bin] + args, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                           timeout=timeout)
        if p.returncode != 0:
            raise SystemExit(f"base setup failed: rigcal {' '.join(args)} (cwd {cwd}): exit {p.returncode}\n"
                             + p.stderr.decode(errors="replace")[-2000:])
        return p

    def prepare(self):
        os.makedirs(os.path.dirname(self.bin), exist_ok=True)
        for i in range(10):
            if os.path.isfile(self.a.rigcal):
                break
            print(f"waiting for {self.a.rigcal} ...", flush=True)
            time.sleep(60)
        shutil.copy2(self.a.rigcal, self.bin + ".copy")
        os.replace(self.bin + ".copy", self.bin)
        if os.path.exists(self.cases_dir):
            subprocess.run(["chmod", "-R", "u+rwx", self.cases_dir])
            shutil.rmtree(self.cases_dir)
        os.makedirs(self.cases_dir)
        b = self.base
        stamp = os.path.join(b, ".ready-" + hashlib.sha256(open(self.bin, "rb").read()).hexdigest()[:16])
        if os.path.exists(stamp):
            return
        if os.path.exists(b):
            shutil.rmtree(b)
        os.makedirs(b)
        S, F = self.src, self.fix
        shutil.copy(os.path.join(S, "data/sample_rig.yaml"), os.path.join(b, "rig.yaml"))
        shutil.copy(os.path.join(S, "data/sample_prior_rig.yaml"), os.path.join(b, "prior.yaml"))
        for t in os.listdir(os.path.join(S, "targets")):
            if t.endswith(".yaml"):
                shutil.copy(os.path.join(S, "targets", t), os.path.join(b, t))
        os.makedirs(os.path.join(b, "bench"))
        for f in ("drive_gt.txt", "drive_es.txt"):
            shutil.copy(os.path.join(S, "data/sample_bench", f), os.path.join(b, "bench", f))
        # bench leaderboard
        for d in ("board/G", "board/E/m1", "board/E/m2"):
            os.makedirs(os.path.join(b, d))
        for seq in ("s1", "s2"):
            shutil.copy(os.path.join(S, "data/sample_bench/drive_gt.txt"), os.path.join(b, f"board/G/{seq}_gt.txt"))
            for m in ("m1", "m2"):
                shutil.copy(os.path.join(S, "data/sample_bench/drive_es.txt"), os.path.join(b, f"board/E/{m}/{seq}_es.txt"))
        # fixtures (copied: never read in place)
        fx = os.path.join(b, "fx")
        os.makedirs(fx)
        for rel in ("trajectories/evo/KITTI_00_gt.txt", "trajectories/evo/KITTI_00_ORB.txt",
                    "trajectories/evo/KITTI_00_gt_times.txt", "trajectories/evo/V102_groundtruth.csv",
                    "trajectories/evo/V102.txt", "trajectories/evo/freiburg1_xyz-groundtruth.txt",
                    "trajectories/evo/freiburg1_xyz-rgbdslam.txt",
                    "imu/lidar_imu_timeoffset/0_odom.txt", "imu/lidar_imu_timeoffset/0_omega.txt",
                    "hand_eye/opencalib/top_center_lidar-pose.txt",
                    "hand_eye/opencalib/NovAtel-pose-lidar-time.txt",
                    "lidar_camera/acfr/2022-11-09_00-54-42/pcd/pose1_target.pcd",
                    "lidar/kitti00_pcd/000000.pcd", "lidar/kitti00_bin/000000.bin"):
            src = os.path.join(F, rel)
            if os.path.exists(src):
                shutil.copy(src, os.path.join(fx, os.path.basename(rel)))
        jp = os.path.join(b, "jpg")
        os.makedirs(jp)
        od = os.path.join(F, "stereo/opencv_samples")
        if os.path.isdir(od):
            for n in sorted(os.listdir(od)):
                if n.endswith(".jpg"):
                    shutil.copy(os.path.join(od, n), os.path.join(jp, n))
        # a small simulated session
        with open(os.path.join(b, "sim.yaml"), "w") as f:
            f.write("stereo:\n  views: 8\nimage:\n  supersample: 2\nlidar_camera:\n  pairs: 6\n"
                    "imu_duration_s: 40\ntrajectories:\n  duration_s: 60\nscans:\n  count: 1\n")
        with open(os.path.join(b, "tiny.yaml"), "w") as f:
            f.write("# tiny simulator settings for the sweep\nseed: 3\nbase_start_s: 1000\nstereo:\n  views: 4\n"
                    "  min_fill: 0.1\n  max_fill: 0.8\n  margin_px: 8\nimage:\n  supersample: 2\n"
                    "  blur_sigma_px: 0.6\n  bayer: false\nlidar:\n  model: os0-128\n  range_noise_m: 0.01\n"
                    "lidar_camera:\n  pairs: 2\n  camera: cam_r\nimu_duration_s: 3\nimu_motion: handheld\n"
                    "trajectories:\n  duration_s: 3\n  motion: car\n  gnss:\n    rate_hz: 100\n"
                    "    outages: [[1.0, 1.5]]\n    outlier_probability: 0.001\nscans:\n  count: 1\n")
        self.rig(["simulate", "--out", "sim", "--config", "sim.yaml", "--seed", "1"], b)
        if not self.a.quick:
            self.rig(["simulate", "--out", "sim2", "--config", "sim.yaml", "--seed", "2"], b)
        # calibrated (warm cache) output
        self.rig(["calibrate", "sim", "--rig", "prior.yaml", "--out", "cal"], b)
        # stereo subset (5 pairs) for cameras, with its report (corners.vnl to reuse)
        for s in ("camera_left", "camera_right"):
            os.makedirs(os.path.join(b, "st4", s, "data"))
            with open(os.path.join(b, "sim/stereo", s, "timestamps.txt")) as f:
                ts = f.read().splitlines()[:5]
            with open(os.path.join(b, "st4", s, "timestamps.txt"), "w") as f:
                f.write("\n".join(ts) + "\n")
            for i in range(5):
                shutil.copy(os.path.join(b, "sim/stereo", s, "data", f"{i:010d}.png"),
                            os.path.join(b, "st4", s, "data", f"{i:010d}.png"))
        shutil.copy(os.path.join(b, "sim/target.yaml"), os.path.join(b, "target.yaml"))
        self.rig(["cameras", "--target", "target.yaml", "--session", "st4", "--out", "st4.yaml",
                  "--report", "st4rep"], b)
        # LiDAR-camera: 3 pairs, KITTI .bin and PCD ascii/binary copies, and vbr-devkit full records
        lc = os.path.join(b, "lc3")
        for d in ("images", "scans", "pcda", "pcdb", "dev/camera_right/data", "dev/ouster_points/data"):
            os.makedirs(os.path.join(lc, d))
        with open(os.path.join(b, "sim/lidar_camera/camera_right/timestamps.txt")) as f:
            cts = f.read().splitlines()
        with open(os.path.join(b, "sim/lidar_camera/ouster_points/timestamps.txt")) as f:
            lts = f.read().splitlines()
        for i in range(3):
            n = f"{i:010d}"
            shutil.copy(os.path.join(b, f"sim/lidar_camera/camera_right/data/{n}.png"), os.path.join(lc, f"images/{n}.png"))
            shutil.copy(os.path.join(b, f"sim/lidar_camera/camera_right/data/{n}.png"), os.path.join(lc, f"dev/camera_right/data/{n}.png"))
            raw = open(os.path.join(b, f"sim/lidar_camera/ouster_points/data/{n}.bin"), "rb").read()
            fld = open(os.path.join(b, f"sim/lidar_camera/ouster_points/fields/{n}.bin"), "rb").read()
            shutil.copy(os.path.join(b, f"sim/lidar_camera/ouster_points/data/{n}.bin"), os.path.join(lc, f"scans/{n}.bin"))
            pts = [struct.unpack_from("<4f", raw, 16 * k) for k in range(len(raw) // 16)]
            hdr = ("# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z intensity\n"
                   "SIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH {n}\nHEIGHT 1\n"
                   "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA {d}\n")
            with open(os.path.join(lc, f"pcda/{n}.pcd"), "w") as f:
                f.write(hdr.format(n=len(pts), d="ascii"))
                f.write("".join("%.6g %.6g %.6g %.6g\n" % p for p in pts))
            with open(os.path.join(lc, f"pcdb/{n}.pcd"), "wb") as f:
                f.write(hdr.format(n=len(pts), d="binary").encode() + raw)
            rec = bytearray()
            for k, p in enumerate(pts):
                t, ring = struct.unpack_from("<IH", fld, 8 * k)
                rng_mm = int((p[0] ** 2 + p[1] ** 2 + p[2] ** 2) ** 0.5 * 1000)
                rec += struct.pack("<3f4xfIHHH2xI12x", p[0], p[1], p[2], p[3], t, 100, ring, 50, rng_mm)
            with open(os.path.join(lc, f"dev/ouster_points/data/{n}.bin"), "wb") as f:
                f.write(rec)
        with open(os.path.join(lc, "dev/camera_right/timestamps.txt"), "w") as f:
            f.write("\n".join(cts[:3]) + "\n")
        with open(os.path.join(lc, "dev/ouster_points/timestamps.txt"), "w") as f:
            f.write("\n".join(lts[:3]) + "\n")
        fields = [("x", 0, 7), ("y", 4, 7), ("z", 8, 7), ("intensity", 16, 7), ("t", 20, 6),
                  ("reflectivity", 24, 4), ("ring", 26, 4), ("ambient", 28, 4), ("range", 32, 6)]
        with open(os.path.join(lc, "dev/ouster_points/.metadata.json"), "w") as f:
            json.dump({"topic": "/ouster/points", "num_messages": 3, "msg_type": "PointCloudXf",
                       "fields": [{"name": a, "offset": o, "datatype": d, "count": 1} for a, o, d in fields]}, f, indent=1)
        # IMU session (both IMUs of the simulation)
        for d in ("imu", "ouster_imu"):
            shutil.copytree(os.path.join(b, "sim", d), os.path.join(b, "imus", d))
        # GNSS fixes CSV from the simulated GNSS/INS poses
        import math
        rows = ["time,latitude,longitude,height,roll,pitch,yaw"]
        for ln in open(os.path.join(b, "sim/trajectories/gnss_ins.tum")):
            v = ln.split()
            if len(v) != 8 or ln.startswith("#"):
                continue
            t, x, y, z, qx, qy, qz, qw = v[0], *map(float, v[1:])
            lat = 41.9 + math.degrees(y / 6378137.0)
            lon = 12.5 + math.degrees(x / (6378137.0 * math.cos(math.radians(41.9))))
            roll = math.degrees(math.atan2(2 * (qw * qx + qy * qz), 1 - 2 * (qx * qx + qy * qy)))
            pitch = math.degrees(math.asin(max(-1, min(1, 2 * (qw * qy - qz * qx)))))
            yaw = math.degrees(math.atan2(2 * (qw * qz + qx * qy), 1 - 2 * (qy * qy + qz * qz)))
            rows.append(f"{t},{lat:.10f},{lon:.10f},{z + 50:.4f},{roll:.5f},{pitch:.5f},{yaw:.5f}")
        with open(os.path.join(b, "fixes.csv"), "w") as f:
            f.write("\n".join(rows) + "\n")
        # a published sequence
        os.makedirs(os.path.join(b, "pub/seq"))
        self.rig(["publish", "cal/calib.yaml", "pub/seq", "--formats", "vbr,kalibr"], b)
        for p, _, fs in os.walk(b):
            for n in fs:
                os.chmod(os.path.join(p, n), 0o644)
            os.chmod(p, 0o755)
        open(stamp, "w").close()

    # ---- case construction ----------------------------------------------------------------
    def new_dir(self, group):
        self.n += 1
        cid = f"{self.n:05d}-{group}"
        d = os.path.join(self.cases_dir, cid)
        return cid, d

    def clone(self, rel, dst_root):
        """Hard-link base/rel (file or tree) into dst_root/rel."""
        src = os.path.join(self.base, rel)
        dst = os.path.join(dst_root, rel)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        if os.path.isdir(src):
            for p, ds, fs in os.walk(src):
                q = os.path.join(dst, os.path.relpath(p, src))
                os.makedirs(q, exist_ok=True)
                for n in fs:
                    os.link(os.path.join(p, n), os.path.join(q, n))
        else:
            os.link(src, dst)

    def copy(self, rel, dst_root):
        src = os.path.join(self.base, rel)
        dst = os.path.join(dst_root, rel)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        if os.path.isdir(src):
            shutil.copytree(src, dst)
        else:
            shutil.copy2(src, dst)


# Scenarios: a command on base inputs, with slots (files that may be replaced).
# Each: name, clone list (hard-linked, read-only use), copy list (real copies: outputs rigcal may
# update), argv (relative to the case folder), outs (files/folders written: on failure absent or
# unchanged), reports (folders written: checked on exit 2 where the command says nothing is
# written), slots {name: (path, kind, invalid_if_broken)}, cost (seconds), allow3.
def scenarios():
    S = {}

    def sc(name, argv, clone=(), copy=(), outs=(), reports=(), slots=None, cost=0.3, allow3=False,
           prev=(), report_on_2=False):
        S[name] = dict(name=name, argv=argv, clone=list(clone), copy=list(copy), outs=list(outs),
                       reports=list(reports), slots=slots or {}, cost=cost, allow3=allow3,
                       prev=list(prev), report_on_2=report_on_2)

    Y, T = "yaml", "text"
    sc("rig-validate", ["rig", "validate", "rig.yaml"], clone=["rig.yaml"], slots={"rig": ("rig.yaml", Y, True)})
    sc("rig-validate-cal", ["rig", "validate", "cal/calib.yaml"], clone=["cal/calib.yaml"],
       slots={"calib": ("cal/calib.yaml", Y, True)})
    sc("rig-show", ["rig", "show", "rig.yaml"], clone=["rig.yaml"], slots={"rig": ("rig.yaml", Y, True)})
    for fmt in ("rigcal", "vbr", "kalibr", "opencv"):
        sc(f"rig-convert-{fmt}", ["rig", "convert", "rig.yaml", "--to", fmt, "--out", "out/x.yaml"],
           clone=["rig.yaml"], outs=["out/x.yaml"], prev=["out/x.yaml"], slots={"rig": ("rig.yaml", Y, True)})
    for fmt in ("ros", "mrcal"):
        sc(f"rig-convert-{fmt}", ["rig", "convert", "rig.yaml", "--to", fmt, "--out", "out/d"],
           clone=["rig.yaml"], outs=["out/d"], slots={"rig": ("rig.yaml", Y, True)})
    sc("target-print", ["target", "print", "a3_checkerboard_8x5_40mm.yaml", "--out", "out/t.pdf"],
       clone=["a3_checkerboard_8x5_40mm.yaml"], outs=["out/t.pdf"], prev=["out/t.pdf"],
       slots={"target": ("a3_checkerboard_8x5_40mm.yaml", Y, True)})
    sc("target-print-april", ["target", "print", "aprilgrid_6x6_88mm.yaml", "--out", "out/t.pdf"],
       clone=["aprilgrid_6x6_88mm.yaml"], outs=["out/t.pdf"], slots={"target": ("aprilgrid_6x6_88mm.yaml", Y, True)})
    sc("simulate", ["simulate", "--out", "out/sim", "--config", "tiny.yaml", "--what", "imu,trajectories",
                    "--rig", "rig.yaml", "--target", "target.yaml"],
       clone=["tiny.yaml", "rig.yaml", "target.yaml"], outs=["out/sim"], cost=0.5,
       slots={"config": ("tiny.yaml", Y, True), "rig": ("rig.yaml", Y, True), "target": ("target.yaml", Y, True)})
    sc("cameras", ["cameras", "--target", "target.yaml", "--session", "st4", "--out", "out/cam.yaml",
                   "--report", "out/rep"],
       clone=["target.yaml", "st4"], outs=["out/cam.yaml"], prev=["out/cam.yaml"], reports=["out/rep"], cost=2.5,
       slots={"target": ("target.yaml", Y, True), "image": ("st4/camera_left/data/0000000002.png", "png", True),
              "timestamps": ("st4/camera_right/timestamps.txt", T, True)})
    sc("cameras-rig", ["cameras", "--target", "target.yaml", "--session", "st4", "--rig", "rig.yaml",
                       "--out", "out/cam.yaml", "--report", "out/rep"],
       clone=["target.yaml", "st4", "rig.yaml"], outs=["out/cam.yaml"], reports=["out/rep"], cost=2.5,
       slots={"rig": ("rig.yaml", Y, True)})
    sc("cameras-vnl", ["cameras", "--target", "target.yaml", "--session", "st4", "--out", "out/cam.yaml",
                       "--report", "st4rep"],
       clone=["target.yaml", "st4"], copy=["st4rep/corners.vnl"], outs=["out/cam.yaml"], reports=["st4rep"], cost=2.5,
       slots={"vnl": ("st4rep/corners.vnl", T, False)})
    sc("cameras-jpg", ["cameras", "--target", "checkerboard_9x6_25mm.yaml", "--camera", "cam_l=jpg/left*.jpg",
                       "--camera", "cam_r=jpg/right*.jpg", "--out", "out/cam.yaml", "--report", "out/rep"],
       clone=["checkerboard_9x6_25mm.yaml", "jpg"], outs=["out/cam.yaml"], reports=["out/rep"], cost=1.0,
       slots={"image": ("jpg/left03.jpg", "jpg", True)})
    lc = ["lidar-camera", "--target", "target.yaml", "--rig", "rig.yaml", "--out", "out/lc.yaml", "--report", "out/rep"]
    sc("lidar-camera-bin", lc + ["--images", "lc3/images/*.png", "--scans", "lc3/scans/*.bin"],
       clone=["target.yaml", "lc3/images", "lc3/scans"], copy=[("sim/truth.yaml", "rig.yaml")],
       outs=["out/lc.yaml"], reports=["out/rep"], cost=3.0, report_on_2=True,
       slots={"target": ("target.yaml", Y, True), "rig": ("rig.yaml", Y, True),
              "scan": ("lc3/scans/0000000001.bin", "bin", True), "image": ("lc3/images/0000000001.png", "png", True)})
    sc("lidar-camera-pcda", lc + ["--images", "lc3/images/*.png", "--scans", "lc3/pcda/*.pcd"],
       clone=["target.yaml", "lc3/images", "lc3/pcda"], copy=[("sim/truth.yaml", "rig.yaml")],
       outs=["out/lc.yaml"], reports=["out/rep"], cost=3.0, report_on_2=True,
       slots={"scan": ("lc3/pcda/0000000001.pcd", "pcda", True)})
    sc("lidar-camera-pcdb", lc + ["--images", "lc3/images/*.png", "--scans", "lc3/pcdb/*.pcd"],
       clone=["target.yaml", "lc3/images", "lc3/pcdb"], copy=[("sim/truth.yaml", "rig.yaml")],
       outs=["out/lc.yaml"], reports=["out/rep"], cost=3.0, report_on_2=True,
       slots={"scan": ("lc3/pcdb/0000000001.pcd", "pcdb", True)})
    sc("lidar-camera-devkit", lc + ["--session", "lc3/dev"],
       clone=["target.yaml", "lc3/dev"], copy=[("sim/truth.yaml", "rig.yaml")],
       outs=["out/lc.yaml"], reports=["out/rep"], cost=3.0, report_on_2=True,
       slots={"metadata": ("lc3/dev/ouster_points/.metadata.json", "json", True),
              "scan": ("lc3/dev/ouster_points/data/0000000001.bin", "devbin", True),
              "timestamps": ("lc3/dev/ouster_points/timestamps.txt", T, True),
              "cam-timestamps": ("lc3/dev/camera_right/timestamps.txt", T, True)})
    sc("odometry-devkit", ["odometry", "lc3/dev", "--out", "out/odom.tum", "--report", "out/rep"],
       clone=["lc3/dev"], outs=["out/odom.tum", "out/odom_covariances.txt"], reports=["out/rep"], cost=2.0,
       slots={"metadata": ("lc3/dev/ouster_points/.metadata.json", "json", True),
              "scan": ("lc3/dev/ouster_points/data/0000000001.bin", "devbin", True),
              "timestamps": ("lc3/dev/ouster_points/timestamps.txt", T, True)})
    sc("time-offset", ["time-offset", "--session", "imus", "--rig", "rig.yaml", "--sensor", "imu",
                       "--reference-sensor", "os_imu", "--out", "out/to.yaml", "--report", "out/rep"],
       clone=["imus"], copy=[("sim/truth.yaml", "rig.yaml")], outs=["out/to.yaml"], prev=["out/to.yaml"],
       reports=["out/rep"], allow3=True, report_on_2=True, cost=0.4,
       slots={"imu": ("imus/imu/data/imu.txt", "csv", True), "stamps": ("imus/imu/timestamps.txt", T, True),
              "os_imu": ("imus/ouster_imu/data/imu.txt", "csv", True), "rig": ("rig.yaml", Y, True)})
    sc("time-offset-table", ["time-offset", "--reference", "fx/0_odom.txt", "--other", "fx/0_omega.txt",
                             "--report", "out/rep"],
       clone=["fx/0_odom.txt", "fx/0_omega.txt"], reports=["out/rep"], allow3=True, report_on_2=True,
       slots={"trajectory": ("fx/0_odom.txt", T, True), "table": ("fx/0_omega.txt", T, True)})
    sc("hand-eye", ["hand-eye", "--lidar", "sim/trajectories/lidar_odometry.tum", "--gnss",
                    "sim/trajectories/gnss_ins.tum", "--rig", "rig.yaml", "--out", "out/he.yaml", "--report", "out/rep"],
       clone=["sim/trajectories/lidar_odometry.tum", "sim/trajectories/gnss_ins.tum"],
       copy=[("sim/truth.yaml", "rig.yaml")], outs=["out/he.yaml"], prev=["out/he.yaml"], reports=["out/rep"],
       allow3=True, report_on_2=True, cost=0.5,
       slots={"lidar": ("sim/trajectories/lidar_odometry.tum", T, True),
              "gnss": ("sim/trajectories/gnss_ins.tum", T, True), "rig": ("rig.yaml", Y, True)})
    sc("hand-eye-fixes", ["hand-eye", "--lidar", "sim/trajectories/lidar_odometry.tum", "--gnss", "fixes.csv",
                          "--attitude", "enu", "--rig", "rig.yaml", "--out", "out/he.yaml", "--report", "out/rep"],
       clone=["sim/trajectories/lidar_odometry.tum", "fixes.csv"], copy=[("sim/truth.yaml", "rig.yaml")],
       outs=["out/he.yaml"], reports=["out/rep"], allow3=True, report_on_2=True, cost=0.5,
       slots={"fixes": ("fixes.csv", "csv", True)})
    sc("hand-eye-opencalib", ["hand-eye", "--lidar", "fx/top_center_lidar-pose.txt", "--gnss",
                              "fx/NovAtel-pose-lidar-time.txt", "--fix", "z=0", "--report", "out/rep"],
       clone=["fx/top_center_lidar-pose.txt", "fx/NovAtel-pose-lidar-time.txt"], reports=["out/rep"],
       allow3=True, report_on_2=True, cost=0.5,
       slots={"lidar": ("fx/top_center_lidar-pose.txt", T, True), "gnss": ("fx/NovAtel-pose-lidar-time.txt", T, True)})
    sc("bench-tum", ["bench", "--gt", "bench/drive_gt.txt", "--est", "bench/drive_es.txt", "--report", "out/rep"],
       clone=["bench"], reports=["out/rep"],
       slots={"gt": ("bench/drive_gt.txt", T, True), "est": ("bench/drive_es.txt", T, True)})
    sc("bench-kitti", ["bench", "--gt", "fx/KITTI_00_gt.txt", "--est", "fx/KITTI_00_ORB.txt", "--gt-times",
                       "fx/KITTI_00_gt_times.txt", "--est-times", "fx/KITTI_00_gt_times.txt"],
       clone=["fx/KITTI_00_gt.txt", "fx/KITTI_00_ORB.txt", "fx/KITTI_00_gt_times.txt"],
       slots={"gt": ("fx/KITTI_00_gt.txt", T, True), "est": ("fx/KITTI_00_ORB.txt", T, True),
              "times": ("fx/KITTI_00_gt_times.txt", T, True)})
    sc("bench-euroc", ["bench", "--gt", "fx/V102_groundtruth.csv", "--est", "fx/V102.txt",
                       "--duplicate-stamps", "drop", "--report", "out/rep"],
       clone=["fx/V102_groundtruth.csv", "fx/V102.txt"], reports=["out/rep"],
       slots={"gt": ("fx/V102_groundtruth.csv", "csv", True)})
    sc("bench-tum-header", ["bench", "--gt", "fx/freiburg1_xyz-groundtruth.txt", "--est",
                            "fx/freiburg1_xyz-rgbdslam.txt", "--convention", "evo"],
       clone=["fx/freiburg1_xyz-groundtruth.txt", "fx/freiburg1_xyz-rgbdslam.txt"],
       slots={"gt": ("fx/freiburg1_xyz-groundtruth.txt", T, True)})
    sc("bench-board", ["bench", "--gt-dir", "board/G", "--est-dir", "board/E", "--methods", "m1,m2",
                       "--report", "out/rep"],
       clone=["board"], reports=["out/rep"],
       slots={"gt": ("board/G/s1_gt.txt", T, True), "est": ("board/E/m1/s1_es.txt", T, False)})
    cal = ["calibrate", "sim", "--rig", "prior.yaml", "--out", "out"]
    sc("calibrate", cal, clone=["sim", "prior.yaml"],
       copy=[("cal/calib.yaml", "out/calib.yaml"), ("cal/cache", "out/cache"),
             ("cal/reports/cameras/corners.vnl", "out/reports/cameras/corners.vnl")],
       outs=["out/calib.yaml"], reports=["out/cache", "out/reports"], allow3=True, cost=1.5,
       slots={"session": ("sim/session.yaml", Y, True), "prior": ("prior.yaml", Y, True),
              "target": ("sim/target.yaml", Y, True), "odometry": ("sim/trajectories/lidar_odometry.tum", T, True),
              "gnss": ("sim/trajectories/gnss_ins.tum", T, True), "imu": ("sim/imu/data/imu.txt", "csv", True),
              "image": ("sim/stereo/camera_right/data/0000000003.png", "png", True),
              "lc-scan": ("sim/lidar_camera/ouster_points/data/0000000002.bin", "bin", True),
              "cache": ("out/cache/time_sync.json", "json", False),
              "cache-cameras": ("out/cache/cameras.json", "json", False)})
    sc("publish", ["publish", "cal/calib.yaml", "out/place/seq", "--formats", "vbr,kalibr,ros,opencv,mrcal,rigcal"],
       clone=["cal/calib.yaml"], outs=["out/place/seq"], cost=0.4,
       slots={"calib": ("cal/calib.yaml", Y, True)})
    sc("publish-existing", ["publish", "cal/calib.yaml", "pub/seq", "--formats", "vbr,kalibr,opencv"],
       clone=["cal/calib.yaml"], copy=["pub/seq"], outs=["pub/seq"], cost=0.4,
       slots={"published": ("pub/seq/vbr_calib.yaml", Y, False)})
    return S


TEXT_KINDS = ("yaml", "text", "csv", "json", "pcda")
BIN_KINDS = ("png", "jpg", "bin", "devbin", "pcdb")


def fault_content(kind, data, fault, rng):
    """Bytes for a content fault, or None when it does not apply to this kind."""
    if fault == "empty":
        return b""
    if fault == "garbage":
        return bytes(rng.randrange(256) for _ in range(4096))
    if fault == "half":
        return data[:len(data) // 2]
    if fault == "header-only":
        return data[:min(len(data), 40)]
    if kind not in TEXT_KINDS:
        return None
    if fault == "bom":
        return b"\xef\xbb\xbf" + data
    if fault == "crlf":
        return data.replace(b"\n", b"\r\n")
    if fault == "cr-only":
        return data.replace(b"\n", b"\r")
    if fault == "utf8":
        pos = 0
        for ln in data.split(b"\n"):
            if ln.strip() and not ln.lstrip().startswith(b"#"):
                break
            pos += len(ln) + 1
        # At the start of the first data line: its first field (a stamp, a key), which every
        # reader reads, not a trailing column a reader may rightly skip.
        return data[:pos] + b"\xff\xfe\xc3(" + data[pos:]
    if fault == "nul":
        return data[:len(data) // 3] + b"\x00" + data[len(data) // 3:]
    if fault == "longline":
        i = data.find(b"\n") + 1
        pad = (b"# " if kind == "yaml" else b"") + b"9" * (1 << 20) + b"\n"
        return data[:i] + pad + data[i:]
    if fault == "no-final-newline":
        return data.rstrip(b"\n")
    return None


FILE_FAULTS = ["missing", "empty", "dir", "unreadable", "loop", "dangling", "garbage", "half",
               "header-only", "bom", "crlf", "cr-only", "utf8", "nul", "longline", "no-final-newline"]
# Faults whose input is plainly not the file asked for: exit 0 on them is flagged.
PLAINLY_INVALID = {"missing", "empty", "dir", "unreadable", "loop", "dangling", "garbage",
                   "header-only", "fifo", "devzero", "utf8", "nul"}


def build_cases(sw, quick):
    S = scenarios()
    rng = sw.rng
    cases = []

    def make(scn, group, kind, desc, invalid=False, names=None, mutate=None, extra=(), argv=None,
             as_nobody=False, q=False, post=None, allow3=None, cost=None):
        s = S[scn]
        cases.append(dict(scn=scn, group=group, kind=kind, desc=desc, invalid=invalid, names=names,
                          mutate=mutate, extra=list(extra), argv=argv, as_nobody=as_nobody, q=q,
                          post=post, allow3=s["allow3"] if allow3 is None else allow3,
                          cost=s["cost"] if cost is None else cost))

    # 1. file faults on every slot
    for scn, s in S.items():
        for slot, (rel, kind, inv) in s["slots"].items():
            for fault in FILE_FAULTS:
                if s["cost"] >= 1.5 and fault in ("cr-only", "nul", "no-final-newline", "loop", "header-only"):
                    continue
                if fault in ("bom", "crlf", "cr-only", "utf8", "nul", "longline", "no-final-newline") and kind not in TEXT_KINDS:
                    continue
                if fault == "header-only" and kind in TEXT_KINDS:
                    continue
                invalid = inv and fault in PLAINLY_INVALID
                if fault == "missing" and kind in ("png", "jpg", "bin", "devbin", "pcda", "pcdb"):
                    invalid = False      # a frame missing from a glob or a folder is allowed
                if scn in ("cameras", "cameras-jpg") and kind in ("png", "jpg"):
                    invalid = False      # an image without the board is skipped, said so
                if slot in ("cache", "cache-cameras", "vnl", "published"):
                    invalid = False
                if slot == "config" and fault == "empty":
                    invalid = False      # an empty simulator config means every default
                if scn == "bench-board" and fault == "missing":
                    invalid = False      # a sequence without its GT file is not a sequence
                names = [os.path.basename(rel)]
                if kind in ("png", "jpg", "bin", "devbin", "pcda", "pcdb"):
                    names += [rel.split("/")[-3] if rel.count("/") >= 2 else os.path.dirname(rel), "timestamps.txt"]
                make(scn, "file-fault", fault, f"{scn} {slot} {rel}: {fault}", invalid=invalid, names=names,
                     mutate=(rel, kind, "fault", fault), as_nobody=(fault == "unreadable"),
                     q=(fault, scn) in (("missing", "rig-validate"), ("unreadable", "bench-tum"), ("dir", "hand-eye"),
                                        ("garbage", "rig-convert-opencv"), ("utf8", "rig-validate"), ("loop", "target-print"),
                                        ("half", "time-offset-table"), ("crlf", "bench-kitti"), ("bom", "hand-eye-fixes"),
                                        ("empty", "simulate"), ("dangling", "publish"), ("longline", "bench-euroc")))
    for scn, rel in (("rig-validate", "rig.yaml"), ("bench-tum", "bench/drive_gt.txt"),
                     ("target-print", "a3_checkerboard_8x5_40mm.yaml"), ("time-offset-table", "fx/0_omega.txt")):
        for fault in ("fifo", "devzero"):
            make(scn, "file-fault", fault, f"{scn} {rel}: {fault}", invalid=True, names=[os.path.basename(rel)],
                 mutate=(rel, "special", "fault", fault), q=False, cost=5)

    # 2. random mutations of every format
    counts = {"yaml": 50, "text": 40, "csv": 40, "json": 25, "pcda": 40, "pcdb": 40, "png": 30, "jpg": 30,
              "bin": 30, "devbin": 30}
    heavy = {"cameras", "cameras-rig", "cameras-vnl", "cameras-jpg", "lidar-camera-bin", "lidar-camera-pcda",
             "lidar-camera-pcdb", "lidar-camera-devkit", "calibrate"}
    for scn, s in S.items():
        for slot, (rel, kind, inv) in s["slots"].items():
            n = counts.get(kind, 20)
            if scn in heavy:
                n = 8
            if scn.startswith("rig-convert") or scn in ("rig-show", "target-print-april", "rig-validate-cal",
                                                       "bench-tum-header", "publish-existing"):
                n = 15
            if scn == "rig-validate":
                n = 200
            if scn == "target-print":
                n = 100
            if scn == "simulate" and slot == "config":
                n = 80
            if scn in ("bench-tum", "bench-kitti"):
                n = 50
            for i in range(n):
                seed = crc(f"{sw.a.seed}:{scn}:{slot}:{i}")
                make(scn, "mutation", kind, f"{scn} {slot} {rel}: mutation #{i}", names=[os.path.basename(rel)]
                     + ([rel.split("/")[-3], "timestamps.txt"] if kind in BIN_KINDS and rel.count("/") >= 2 else []),
                     mutate=(rel, kind, "mutate", seed),
                     q=(i == 0 and (scn, slot) in (("rig-validate", "rig"), ("target-print", "target"), ("simulate", "config"),
                                                    ("bench-tum", "gt"), ("bench-kitti", "times"), ("bench-euroc", "gt"),
                                                    ("time-offset", "imu"), ("hand-eye-fixes", "fixes"),
                                                    ("hand-eye-opencalib", "gnss"), ("publish", "calib"))))

    # 3. crafted contents
    rig0 = open(os.path.join(sw.base, "rig.yaml"), "rb").read()

    def rigsub(old, new, count=1):
        assert old in rig0, old
        return rig0.replace(old, new, count)

    tb_row = b"[0.014108030323707207, 0.020842394582703788, 0.9996832288622453, 0.0824]"
    bomb = b"a: &a [\"lol\",\"lol\",\"lol\",\"lol\",\"lol\",\"lol\",\"lol\",\"lol\",\"lol\"]\n"
    prev = "a"
    for k in "bcdefghi":
        bomb += f"{k}: &{k} [*{prev},*{prev},*{prev},*{prev},*{prev},*{prev},*{prev},*{prev},*{prev}]\n".encode()
        prev = k
    crafted_rig = {
        "nan-in-T_b": rigsub(tb_row, tb_row.replace(b"0.0824", b".nan")),
        "NaN-word-in-T_b": rigsub(tb_row, tb_row.replace(b"0.0824", b"NaN")),
        "inf-in-T_b": rigsub(tb_row, tb_row.replace(b"0.0824", b".inf")),
        "1e308-translation": rigsub(tb_row, tb_row.replace(b"0.0824", b"1e308")),
        "1e400-translation": rigsub(tb_row, tb_row.replace(b"0.0824", b"1e400")),
        "nan-focal": rigsub(b"[1085.3,", b"[.nan,"),
        "1e308-focal": rigsub(b"[1085.3,", b"[1e308,"),
        "negative-focal": rigsub(b"[1085.3,", b"[-1085.3,"),
        "zero-focal": rigsub(b"[1085.3,", b"[0,"),
        "inf-distortion": rigsub(b"[-0.0921,", b"[.inf,"),
        "negative-resolution": rigsub(b"resolution: [1388, 700]", b"resolution: [-1388, 700]"),
        "huge-resolution": rigsub(b"resolution: [1388, 700]", b"resolution: [4000000000, 700]"),
        "fraction-resolution": rigsub(b"resolution: [1388, 700]", b"resolution: [1388.5, 700]"),
        "resolution-1e400": rigsub(b"resolution: [1388, 700]", b"resolution: [1e400, 700]"),
        "duplicate-sensor": rig0 + b"\n" + rig0[rig0.find(b"cam_l:"):rig0.find(b"cam_r:")],
        "duplicate-key-in-sensor": rigsub(b"  time_offset: 0.0\ncam_r:", b"  time_offset: 0.0\n  time_offset: 1.0\ncam_r:"),
        "misspelt-key": rigsub(b"distortion_coeffs", b"distortion_coefs"),
        "misspelt-time_offsett": rigsub(b"  time_offset: 0.0\ncam_r:", b"  time_offsett: 0.0\ncam_r:"),
        "unknown-key": rigsub(b"cam_r:", b"  frobnicate: 3\ncam_r:"),
        "unknown-sensor-type": rigsub(b"sensor_type: camera", b"sensor_type: sonar"),
        "unknown-distortion-model": rigsub(b"distortion_model: radtan", b"distortion_model: fancy"),
        "T_b-3-rows": rigsub(b"    - [0.0, 0.0, 0.0, 1.0]\n  time_offset: 0.0\ncam_r", b"  time_offset: 0.0\ncam_r"),
        "T_b-det-minus-1": rigsub(tb_row, b"[-0.014108030323707207, -0.020842394582703788, -0.9996832288622453, 0.0824]"),
        "T_b-scalar": rigsub(b"  T_b:\n    - " + tb_row, b"  T_b: 7\n  T_bx:\n    - " + tb_row),
        "billion-laughs": bomb + rig0,
        "billion-laughs-in-sensor": rigsub(b"cam_r:", b"  junk: " + b"[*i]\n".join([b""]) + b"cam_r:").replace(b"cam_l:", bomb.replace(b"\n", b"\n  ").rstrip() .replace(b"a: &a", b"cam_l:\n  a: &a", 1), 1) if False else bomb.replace(b"i: &i", b"i: &i") + rig0.replace(b"  time_offset: 0.0\ncam_r:", b"  time_offset: 0.0\n  extra: *i\ncam_r:", 1),
        "alias-undefined": rigsub(b"  time_offset: 0.0\ncam_r:", b"  time_offset: *nowhere\ncam_r:"),
        "anchor-recursive": b"x: &x [*x]\n" + rig0,
        "deep-nesting-lists": b"deep: " + b"[" * 100000 + b"]" * 100000 + b"\n" + rig0,
        "deep-nesting-maps": b"deep: " + b"{a: " * 20000 + b"1" + b"}" * 20000 + b"\n" + rig0,
        "long-scalar-10MB": rigsub(b"model: OS0-128", b"model: " + b"O" * (10 << 20)),
        "long-key-1MB": rig0 + b"k" * (1 << 20) + b": 1\n",
        "yaml-50MB-comment": rig0 + (b"# " + b"x" * 98 + b"\n") * (50 << 20 // 100) if False else rig0 + (b"#" + b"x" * 99 + b"\n") * ((50 << 20) // 100),
        "yaml-50MB-list": rig0 + b"padding: [" + b"0," * ((50 << 20) // 2) + b"0]\n",
        "two-documents": rig0 + b"---\n" + rig0,
        "top-level-list": b"- 1\n- 2\n",
        "top-level-scalar": b"hello\n",
        "only-comment": b"# nothing\n",
        "tab-indent": rig0.replace(b"  sensor_type", b"\tsensor_type", 1),
        "binary-tag": rigsub(b"model: OS0-128", b"model: !!binary aGVsbG8="),
        "flow-map-unclosed": rig0 + b"x: {a: 1\n",
        "sensor-null": rigsub(b"cam_r:\n", b"cam_x:\ncam_r:\n"),
        "intrinsics-string": rigsub(b"[1085.3, 1084.7, 701.2, 349.6]", b"fast"),
        "intrinsics-3": rigsub(b"[1085.3, 1084.7, 701.2, 349.6]", b"[1085.3, 1084.7, 701.2]"),
        "intrinsics-1000": rigsub(b"[1085.3, 1084.7, 701.2, 349.6]", b"[" + b"1.0, " * 1000 + b"1.0]"),
        "distortion-100000": rigsub(b"[-0.0921, 0.0874, 0.00031, -0.00027]", b"[" + b"0.0, " * 100000 + b"0.0]"),
        "invalid-utf8-key": rigsub(b"cam_r:", b"cam_\xff\xfe:"),
        "invalid-utf8-value": rigsub(b"model: OS0-128", b"model: OS0\xc3\x28"),
        "invalid-utf8-end-of-key": rigsub(b"  time_offset: 0.0\ncam_r:", b"  time_offset\xe2\x82: 0.0\ncam_r:"),
        "overlong-utf8": rigsub(b"model: OS0-128", b"model: \xc0\xaf"),
        "time_offset-1e300": rigsub(b"  time_offset: 0.0\ncam_r:", b"  time_offset: 1e300\ncam_r:"),
        "update_rate-negative": rigsub(b"update_rate: 10.0", b"update_rate: -10.0"),
        "update_rate-nan": rigsub(b"update_rate: 10.0", b"update_rate: .nan"),
        "flat-T_b-15": rigsub(b"  T_b:\n    - " + tb_row, b"  T_b: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0]\n  T_bx:\n    - " + tb_row),
        "nul-byte": rigsub(b"model: OS0-128", b"model: OS0\x00128"),
    }
    for name, data in crafted_rig.items():
        valid_ok = name in ("misspelt-key", "unknown-key", "two-documents", "tab-indent", "yaml-50MB-comment",
                            "long-key-1MB", "long-scalar-10MB", "intrinsics-1000") and False
        inv = name not in ("unknown-key",)
        for scn in ("rig-validate", "rig-convert-kalibr"):
            make(scn, "crafted-rig", name, f"{scn} rig.yaml: {name}", invalid=inv, names=["rig.yaml"],
                 mutate=("rig.yaml", "yaml", "data", data), q=(scn == "rig-validate" and name in (
                     "nan-in-T_b", "invalid-utf8-key", "duplicate-key-in-sensor", "1e308-focal", "anchor-recursive")),
                 cost=2 if "50MB" in name else None)
    # a calibration with sensors the steps need missing, through the commands that read rigs
    for scn, rel in (("simulate", "rig.yaml"), ("lidar-camera-bin", "rig.yaml"), ("time-offset", "rig.yaml"),
                     ("hand-eye", "rig.yaml"), ("calibrate", "prior.yaml"), ("cameras-rig", "rig.yaml"),
                     ("publish", "cal/calib.yaml")):
        for name in ("nan-in-T_b", "billion-laughs", "deep-nesting-lists", "yaml-50MB-list", "invalid-utf8-key",
                     "1e308-focal", "huge-resolution", "duplicate-sensor"):
            make(scn, "crafted-rig", name, f"{scn} {rel}: {name}", invalid=True, names=[os.path.basename(rel)],
                 mutate=(rel, "yaml", "data", crafted_rig[name]), cost=S[scn]["cost"] + (2 if "50MB" in name else 0))

    tg0 = open(os.path.join(sw.base, "a3_checkerboard_8x5_40mm.yaml"), "rb").read()
    ag0 = open(os.path.join(sw.base, "aprilgrid_6x6_88mm.yaml"), "rb").read()
    crafted_target = {
        "5000x5000-squares": tg0.replace(b"targetCols: 8", b"targetCols: 5000").replace(b"targetRows: 5", b"targetRows: 5000"),
        "targetCols-1e8": tg0.replace(b"targetCols: 8", b"targetCols: 100000000"),
        "targetCols-1e8-float": tg0.replace(b"targetCols: 8", b"targetCols: 1e8"),
        "targetCols-4e9": tg0.replace(b"targetCols: 8", b"targetCols: 4000000000"),
        "targetCols-negative": tg0.replace(b"targetCols: 8", b"targetCols: -3"),
        "targetCols-zero": tg0.replace(b"targetCols: 8", b"targetCols: 0"),
        "targetCols-1": tg0.replace(b"targetCols: 8", b"targetCols: 1"),
        "targetCols-nan": tg0.replace(b"targetCols: 8", b"targetCols: .nan"),
        "spacing-1e300": tg0.replace(b"rowSpacingMeters: 0.040", b"rowSpacingMeters: 1e300").replace(b"colSpacingMeters: 0.040", b"colSpacingMeters: 1e300"),
        "spacing-1e-300": tg0.replace(b"rowSpacingMeters: 0.040", b"rowSpacingMeters: 1e-300"),
        "spacing-nan": tg0.replace(b"rowSpacingMeters: 0.040", b"rowSpacingMeters: .nan"),
        "spacing-inf": tg0.replace(b"colSpacingMeters: 0.040", b"colSpacingMeters: .inf"),
        "spacing-negative": tg0.replace(b"rowSpacingMeters: 0.040", b"rowSpacingMeters: -0.04"),
        "margin-minus-1": tg0.replace(b"margin: 0.028", b"margin: -1"),
        "margin-1e300": tg0.replace(b"margin: 0.028", b"margin: 1e300"),
        "margin-nan": tg0.replace(b"margin: 0.028", b"margin: .nan"),
        "thickness-negative": tg0.replace(b"thickness: 0.005", b"thickness: -1"),
        "unknown-type": tg0.replace(b"target_type: checkerboard", b"target_type: circlegrid"),
        "misspelt-key": tg0.replace(b"targetRows", b"targetRow"),
        "duplicate-key": tg0 + b"targetCols: 9\n",
        "name-invalid-utf8": tg0.replace(b"name: a3", b"name: a3\xff"),
        "name-10MB": tg0.replace(b"name: a3_checkerboard_8x5_40mm", b"name: " + b"n" * (10 << 20)),
        "name-with-pdf-parens": tg0.replace(b"name: a3_checkerboard_8x5_40mm", b"name: \"a) (b \\\\ %%EOF\""),
        "billion-laughs": bomb + tg0,
        "yaml-50MB-list": tg0 + b"padding: [" + b"0," * ((50 << 20) // 2) + b"0]\n",
    }
    crafted_april = {
        "tagCols-100000": ag0.replace(b"tagCols: 6", b"tagCols: 100000"),
        "tagCols-5000-rows-5000": ag0.replace(b"tagCols: 6", b"tagCols: 5000").replace(b"tagRows: 6", b"tagRows: 5000"),
        "tagSize-zero": ag0.replace(b"tagSize: 0.088", b"tagSize: 0"),
        "tagSize-1e300": ag0.replace(b"tagSize: 0.088", b"tagSize: 1e300"),
        "tagSpacing-nan": ag0.replace(b"tagSpacing: 0.3", b"tagSpacing: .nan"),
        "tagSpacing-negative": ag0.replace(b"tagSpacing: 0.3", b"tagSpacing: -0.5"),
        "tagSpacing-1e6": ag0.replace(b"tagSpacing: 0.3", b"tagSpacing: 1e6"),
    }
    for name, data in crafted_target.items():
        inv = name not in ("targetCols-1",)
        make("target-print", "crafted-target", name, f"target print: {name}", invalid=inv and name != "name-with-pdf-parens",
             names=["a3_checkerboard_8x5_40mm.yaml"], mutate=("a3_checkerboard_8x5_40mm.yaml", "yaml", "data", data),
             q=name in ("targetCols-1e8", "spacing-1e300", "margin-minus-1"),
             cost=2 if "50MB" in name else None)
    for name in ("5000x5000-squares", "targetCols-1e8", "spacing-1e300", "margin-minus-1", "spacing-nan", "targetCols-zero"):
        for scn in ("cameras", "lidar-camera-bin", "simulate"):
            make(scn, "crafted-target", name, f"{scn} target.yaml: {name}", invalid=True, names=["target.yaml"],
                 mutate=("target.yaml", "yaml", "data", crafted_target[name]))
        make("calibrate", "crafted-target", name, f"calibrate sim/target.yaml: {name}", invalid=True,
             names=["target.yaml"], mutate=("sim/target.yaml", "yaml", "data", crafted_target[name]))
    for name, data in crafted_april.items():
        make("target-print-april", "crafted-target", name, f"target print aprilgrid: {name}", invalid=True,
             names=["aprilgrid_6x6_88mm.yaml"], mutate=("aprilgrid_6x6_88mm.yaml", "yaml", "data", data))

    tiny = open(os.path.join(sw.base, "tiny.yaml"), "rb").read()
    crafted_sim = {
        "views-1e8": tiny.replace(b"views: 4", b"views: 100000000"),
        "views-negative": tiny.replace(b"views: 4", b"views: -1"),
        "supersample-1e6": tiny.replace(b"supersample: 2", b"supersample: 1000000"),
        "supersample-0": tiny.replace(b"supersample: 2", b"supersample: 0"),
        "imu_duration-1e12": tiny.replace(b"imu_duration_s: 3", b"imu_duration_s: 1e12"),
        "imu_duration-nan": tiny.replace(b"imu_duration_s: 3", b"imu_duration_s: .nan"),
        "imu_duration-negative": tiny.replace(b"imu_duration_s: 3", b"imu_duration_s: -3"),
        "duration-inf": tiny.replace(b"  duration_s: 3", b"  duration_s: .inf"),
        "duration-1e9": tiny.replace(b"  duration_s: 3", b"  duration_s: 1e9"),
        "scans-4e9": tiny.replace(b"count: 1", b"count: 4000000000"),
        "pairs-negative": tiny.replace(b"pairs: 2", b"pairs: -1"),
        "gnss-rate-1e9": tiny.replace(b"rate_hz: 100", b"rate_hz: 1e9"),
        "gnss-rate-0": tiny.replace(b"rate_hz: 100", b"rate_hz: 0"),
        "outages-nan": tiny.replace(b"[[1.0, 1.5]]", b"[[.nan, 1.5]]"),
        "outages-inverted": tiny.replace(b"[[1.0, 1.5]]", b"[[1.5, 1.0]]"),
        "outages-all": tiny.replace(b"[[1.0, 1.5]]", b"[[-1e9, 1e9]]"),
        "outlier-probability-2": tiny.replace(b"outlier_probability: 0.001", b"outlier_probability: 2"),
        "seed-negative": tiny.replace(b"seed: 3", b"seed: -1"),
        "seed-huge": tiny.replace(b"seed: 3", b"seed: 99999999999999999999999"),
        "base_start-1e300": tiny.replace(b"base_start_s: 1000", b"base_start_s: 1e300"),
        "base_start-negative": tiny.replace(b"base_start_s: 1000", b"base_start_s: -1000"),
        "lidar-model-unknown": tiny.replace(b"model: os0-128", b"model: hdl-64"),
        "motion-unknown": tiny.replace(b"motion: car", b"motion: boat"),
        "target-missing-file": tiny + b"target: nowhere.yaml\n",
        "target-a-directory": tiny + b"target: .\n",
        "replay-missing": tiny.replace(b"  motion: car", b"  motion: car\n  replay: nowhere.tum"),
        "replay-dev-zero": tiny.replace(b"  motion: car", b"  motion: car\n  replay: /dev/zero"),
        "replay-itself": tiny.replace(b"  motion: car", b"  motion: car\n  replay: tiny.yaml"),
        "unknown-key": tiny + b"frobnicate: 1\n",
        "duplicate-key": tiny + b"imu_duration_s: 4\n",
        "billion-laughs": bomb + tiny,
        "range-noise-1e300": tiny.replace(b"range_noise_m: 0.01", b"range_noise_m: 1e300"),
        "blur-nan": tiny.replace(b"blur_sigma_px: 0.6", b"blur_sigma_px: .nan"),
        "bayer-string": tiny.replace(b"bayer: false", b"bayer: maybe"),
    }
    for name, data in crafted_sim.items():
        make("simulate", "crafted-sim-config", name, f"simulate tiny.yaml: {name}",
             invalid=name not in ("outages-all",), names=["tiny.yaml"],
             mutate=("tiny.yaml", "yaml", "data", data), q=name in ("views-1e8", "imu_duration-1e12", "scans-4e9"))
    # full simulate (every part) on the absurd values that only matter when the part runs
    for name in ("views-1e8", "supersample-1e6", "scans-4e9", "pairs-negative", "imu_duration-1e12", "duration-1e9"):
        make("simulate", "crafted-sim-config", name + "-all-parts", f"simulate --what all, tiny.yaml: {name}",
             invalid=True, names=["tiny.yaml"], mutate=("tiny.yaml", "yaml", "data", crafted_sim[name]),
             argv=["simulate", "--out", "out/sim", "--config", "tiny.yaml", "--rig", "rig.yaml", "--target", "target.yaml"],
             cost=5)

    ses0 = open(os.path.join(sw.base, "sim/session.yaml"), "rb").read()
    crafted_session = {
        "unknown-key": ses0 + b"frobnicate: x\n",
        "misspelt-key": ses0.replace(b"odometry:", b"odometyr:"),
        "duplicate-key": ses0 + b"motion: .\n",
        "path-missing": ses0.replace(b"cameras: stereo", b"cameras: nowhere"),
        "path-absolute-root": ses0.replace(b"cameras: stereo", b"cameras: /"),
        "path-dotdot": ses0.replace(b"cameras: stereo", b"cameras: ../.."),
        "motion-a-file": ses0.replace(b"motion: .", b"motion: session.yaml"),
        "target-a-dir": ses0.replace(b"target: target.yaml", b"target: stereo"),
        "odometry-dev-zero": ses0.replace(b"odometry: trajectories/lidar_odometry.tum", b"odometry: /dev/zero"),
        "gnss-is-session": ses0.replace(b"gnss: trajectories/gnss_ins.tum", b"gnss: session.yaml"),
        "rig-itself": ses0 + b"rig: session.yaml\n",
        "list-value": ses0.replace(b"cameras: stereo", b"cameras: [stereo, stereo]"),
        "billion-laughs": bomb + ses0,
        "invalid-utf8-path": ses0.replace(b"cameras: stereo", b"cameras: ster\xffeo"),
        "nul-in-path": ses0.replace(b"cameras: stereo", b"cameras: \"ster\\0eo\""),
        "long-path": ses0.replace(b"cameras: stereo", b"cameras: " + b"a/" * 5000),
    }
    for name, data in crafted_session.items():
        make("calibrate", "crafted-session", name, f"calibrate sim/session.yaml: {name}", invalid=True,
             names=["session.yaml"], mutate=("sim/session.yaml", "yaml", "data", data), q=name in ("unknown-key", "billion-laughs"))

    # trajectories
    tum0 = open(os.path.join(sw.base, "bench/drive_gt.txt"), "rb").read()
    tl = tum0.split(b"\n")
    hdr = [l for l in tl if l.startswith(b"#")]
    body = [l for l in tl if l and not l.startswith(b"#")]

    def tum_with(i, col, val):
        b2 = list(body)
        f = b2[i].split()
        f[col] = val
        b2[i] = b" ".join(f)
        return b"\n".join(hdr + b2) + b"\n"
    crafted_tum = {
        "nan-position": tum_with(5, 1, b"nan"), "inf-position": tum_with(5, 2, b"inf"),
        "1e308-position": tum_with(5, 3, b"1e308"), "nan-quaternion": tum_with(5, 7, b"nan"),
        "zero-quaternion": b"\n".join(hdr + body[:5] + [b" ".join(body[5].split()[:4] + [b"0", b"0", b"0", b"0"])] + body[6:]) + b"\n",
        "unnormalised-quaternion-x1000": b"\n".join(hdr + body[:5] + [b" ".join(body[5].split()[:4] + [b"1000", b"0", b"0", b"0"])] + body[6:]) + b"\n",
        "nan-stamp": tum_with(5, 0, b"nan"), "inf-stamp": tum_with(5, 0, b"inf"),
        "stamp-1e308": tum_with(len(body) - 1, 0, b"1e308"), "stamp-1e999": tum_with(5, 0, b"1e999"),
        "stamp-negative": tum_with(0, 0, b"-1e12"), "stamp-huge-digits": tum_with(5, 0, b"1" * 400),
        "stamps-decreasing": b"\n".join(hdr + body[::-1]) + b"\n",
        "duplicate-stamp": b"\n".join(hdr + body[:5] + [body[4]] + body[5:]) + b"\n",
        "one-pose": b"\n".join(hdr + body[:1]) + b"\n", "two-poses": b"\n".join(hdr + body[:2]) + b"\n",
        "seven-fields": b"\n".join(hdr + body[:5] + [b" ".join(body[5].split()[:7])] + body[6:]) + b"\n",
        "nine-fields": b"\n".join(hdr + body[:5] + [body[5] + b" 1"] + body[6:]) + b"\n",
        "header-only": b"\n".join(hdr) + b"\n# only comments\n",
        "all-identical-poses": b"\n".join(b" ".join([str(1000 + k).encode()] + body[0].split()[1:]) for k in range(len(body))) + b"\n",
    }
    for name, data in crafted_tum.items():
        for scn, rel in (("bench-tum", "bench/drive_gt.txt"), ("bench-tum", "bench/drive_es.txt"),
                         ("hand-eye", "sim/trajectories/lidar_odometry.tum")):
            if scn == "hand-eye":
                t0 = open(os.path.join(sw.base, rel), "rb").read().split(b"\n")
                b_ = [l for l in t0 if l and not l.startswith(b"#")]
                if name in ("stamps-decreasing", "all-identical-poses", "header-only", "one-pose", "two-poses"):
                    continue
                ff = b_[5].split()
                col = {"nan-position": 1, "inf-position": 2, "1e308-position": 3, "nan-quaternion": 7, "nan-stamp": 0,
                       "inf-stamp": 0, "stamp-1e308": 0, "stamp-1e999": 0, "stamp-negative": 0, "stamp-huge-digits": 0}.get(name)
                if col is None:
                    continue
                ff[col] = {"nan-position": b"nan", "inf-position": b"inf", "1e308-position": b"1e308", "nan-quaternion": b"nan",
                           "nan-stamp": b"nan", "inf-stamp": b"inf", "stamp-1e308": b"1e308", "stamp-1e999": b"1e999",
                           "stamp-negative": b"-1e12", "stamp-huge-digits": b"1" * 400}[name]
                b_[5] = b" ".join(ff)
                data2 = b"\n".join(b_) + b"\n"
            else:
                data2 = data
            make(scn, "crafted-trajectory", name, f"{scn} {rel}: {name}",
                 invalid=name not in ("two-poses", "all-identical-poses", "unnormalised-quaternion-x1000"),
                 names=[os.path.basename(rel)], mutate=(rel, "text", "data", data2),
                 q=(scn == "bench-tum" and rel.endswith("gt.txt") and name in ("nan-position", "zero-quaternion", "one-pose")))
    kit0 = open(os.path.join(sw.base, "fx/KITTI_00_gt.txt"), "rb").read().split(b"\n")
    times0 = open(os.path.join(sw.base, "fx/KITTI_00_gt_times.txt"), "rb").read().split(b"\n")
    crafted_kitti = {
        ("gt", "eleven-numbers"): b"\n".join(kit0[:10] + [b" ".join(kit0[10].split()[:11])] + kit0[11:]),
        ("gt", "nan"): b"\n".join(kit0[:10] + [kit0[10].replace(kit0[10].split()[3], b"nan", 1)] + kit0[11:]),
        ("gt", "rotation-garbage"): b"\n".join(kit0[:10] + [b"9 9 9 0 9 9 9 0 9 9 9 0"] + kit0[11:]),
        ("gt", "zero-rotation"): b"\n".join(kit0[:10] + [b"0 0 0 0 0 0 0 0 0 0 0 0"] + kit0[11:]),
        ("times", "fewer-lines"): b"\n".join(times0[:100]) + b"\n",
        ("times", "more-lines"): b"\n".join(times0 + times0[-50:]) + b"\n",
        ("times", "unsorted"): b"\n".join(times0[:10] + [times0[20]] + times0[11:]),
        ("times", "nan"): b"\n".join(times0[:10] + [b"nan"] + times0[11:]),
        ("times", "negative"): b"\n".join([b"-5"] + times0[1:]),
    }
    for (slot, name), data in crafted_kitti.items():
        rel = S["bench-kitti"]["slots"][slot][0]
        make("bench-kitti", "crafted-trajectory", "kitti-" + name, f"bench-kitti {rel}: {name}",
             invalid=name != "rotation-garbage" or True, names=[os.path.basename(rel)], mutate=(rel, "text", "data", data))

    # IMU tables
    imu0 = open(os.path.join(sw.base, "imus/imu/data/imu.txt"), "rb").read().split(b"\n")
    ts0 = open(os.path.join(sw.base, "imus/imu/timestamps.txt"), "rb").read().split(b"\n")

    def imu_row(i, col, val):
        r = list(imu0)
        f = r[i].split(b",")
        f[col] = val
        r[i] = b",".join(f)
        return b"\n".join(r)
    crafted_imu = {
        ("imu", "header-only"): imu0[0] + b"\n", ("imu", "nan-gyro"): imu_row(100, 3, b"nan"),
        ("imu", "inf-gyro"): imu_row(100, 4, b"inf"), ("imu", "1e308-gyro"): imu_row(100, 5, b"1e308"),
        ("imu", "missing-column"): imu_row(100, 5, b"").replace(b",,", b",", 1),
        ("imu", "no-header"): b"\n".join(imu0[1:]), ("imu", "header-unknown-names"): b"a,b,c\n" + b"\n".join(imu0[1:]),
        ("imu", "one-sample"): b"\n".join(imu0[:2]) + b"\n",
        ("stamps", "fewer-stamps"): b"\n".join(ts0[:100]) + b"\n", ("stamps", "more-stamps"): b"\n".join(ts0 + ts0[-10:]),
        ("stamps", "unsorted"): b"\n".join(ts0[:50] + [ts0[80]] + ts0[51:]),
        ("stamps", "duplicate"): b"\n".join(ts0[:50] + [ts0[49]] + ts0[51:]),
        ("stamps", "bad-date"): b"\n".join(ts0[:50] + [b"1970-13-45T99:99:99.000000000"] + ts0[51:]),
        ("stamps", "year-99999"): b"\n".join(ts0[:50] + [b"99999-01-01T00:00:00.000000000"] + ts0[51:]),
        ("stamps", "float-seconds"): b"\n".join(b"%.9f" % (1000 + k * 0.01) for k in range(len(ts0) - 1)) + b"\n",
        ("stamps", "empty-line-in-middle"): b"\n".join(ts0[:50] + [b""] + ts0[51:]),
    }
    for (slot, name), data in crafted_imu.items():
        rel = S["time-offset"]["slots"][slot][0]
        make("time-offset", "crafted-imu", name, f"time-offset {rel}: {name}", invalid=name != "float-seconds",
             names=[os.path.basename(rel)], mutate=(rel, "csv", "data", data), q=name in ("nan-gyro", "fewer-stamps"))
    om0 = open(os.path.join(sw.base, "fx/0_omega.txt"), "rb").read().split(b"\n")
    for name, data in {"nan": b"\n".join(om0[:20] + [b"1578481475.3 nan 0 0"] + om0[21:]),
                       "three-columns": b"\n".join(om0[:20] + [b"1578481475.3 0 0"] + om0[21:]),
                       "stamps-backwards": b"\n".join(om0[:1] + om0[1:][::-1]),
                       "all-zero-rate": b"\n".join(om0[:1] + [l.split()[0] + b" 0 0 0" for l in om0[1:] if l]) + b"\n"}.items():
        make("time-offset-table", "crafted-imu", "table-" + name, f"time-offset-table fx/0_omega.txt: {name}",
             invalid=name != "all-zero-rate", names=["0_omega.txt"], mutate=("fx/0_omega.txt", "text", "data", data))
    for cols in ("wx,wy", "t,t,t,t", "t,wx,wy,wz,-,-,-,-,-,-,-,-,-,-,-,-,-,-,-,-", "bogus", "", "t,wx,wy,wx"):
        make("time-offset-table", "option", "columns", f"time-offset --other-columns '{cols}'", invalid=True,
             names=["other-columns", "columns"], extra=["--other-columns", cols])

    # GNSS fixes
    fx0 = open(os.path.join(sw.base, "fixes.csv"), "rb").read().split(b"\n")

    def fixrow(i, col, val):
        r = list(fx0)
        f = r[i].split(b",")
        f[col] = val
        r[i] = b",".join(f)
        return b"\n".join(r)
    crafted_fix = {"lat-91": fixrow(50, 1, b"91"), "lat-nan": fixrow(50, 1, b"nan"), "lon-1e308": fixrow(50, 2, b"1e308"),
                   "height-minus-1e7": fixrow(50, 3, b"-1e7"), "yaw-inf": fixrow(50, 6, b"inf"),
                   "time-unsorted": b"\n".join(fx0[:50] + [fx0[80]] + fx0[51:]), "no-header": b"\n".join(fx0[1:]),
                   "header-missing-latitude": fx0[0].replace(b"latitude", b"lattitude") + b"\n" + b"\n".join(fx0[1:]),
                   "header-only": fx0[0] + b"\n", "time-iso-bad": fixrow(50, 0, b"2024-02-30T25:61:00Z"),
                   "duplicate-column": fx0[0].replace(b"pitch", b"roll") + b"\n" + b"\n".join(fx0[1:])}
    for name, data in crafted_fix.items():
        make("hand-eye-fixes", "crafted-gnss", name, f"hand-eye fixes.csv: {name}", invalid=True,
             names=["fixes.csv"], mutate=("fixes.csv", "csv", "data", data), q=name == "lat-nan")

    # point clouds
    pa0 = open(os.path.join(sw.base, "lc3/pcda/0000000001.pcd"), "rb").read()
    pb0 = open(os.path.join(sw.base, "lc3/pcdb/0000000001.pcd"), "rb").read()

    def hsub(d, old, new):
        i = d.find(b"DATA")
        return d[:i].replace(old, new) + d[i:]
    npts = int(re.search(rb"POINTS (\d+)", pa0).group(1))
    crafted_pcd = {}
    for tag, d0 in (("a", pa0), ("b", pb0)):
        np_ = str(npts).encode()
        crafted_pcd.update({
            (tag, "POINTS-4000000000"): hsub(d0, b"POINTS " + np_, b"POINTS 4000000000").replace(b"WIDTH " + np_, b"WIDTH 4000000000"),
            (tag, "POINTS-only-4000000000"): hsub(d0, b"POINTS " + np_, b"POINTS 4000000000"),
            (tag, "POINTS-18446744073709551615"): hsub(d0, b"POINTS " + np_, b"POINTS 18446744073709551615").replace(b"WIDTH " + np_, b"WIDTH 18446744073709551615"),
            (tag, "POINTS-negative"): hsub(d0, b"POINTS " + np_, b"POINTS -1").replace(b"WIDTH " + np_, b"WIDTH -1"),
            (tag, "POINTS-zero"): hsub(d0, b"POINTS " + np_, b"POINTS 0").replace(b"WIDTH " + np_, b"WIDTH 0"),
            (tag, "POINTS-double"): hsub(d0, b"POINTS " + np_, b"POINTS " + str(2 * npts).encode()).replace(b"WIDTH " + np_, b"WIDTH " + str(2 * npts).encode()),
            (tag, "HEIGHT-0"): hsub(d0, b"HEIGHT 1", b"HEIGHT 0"),
            (tag, "WIDTH-HEIGHT-overflow"): hsub(d0, b"HEIGHT 1", b"HEIGHT 4294967296").replace(b"POINTS " + np_, b"POINTS 0"),
            (tag, "SIZE-8-type-F"): hsub(d0, b"SIZE 4 4 4 4", b"SIZE 8 4 4 4"),
            (tag, "SIZE-0"): hsub(d0, b"SIZE 4 4 4 4", b"SIZE 0 0 0 0"),
            (tag, "SIZE-huge"): hsub(d0, b"SIZE 4 4 4 4", b"SIZE 4 4 4 2147483647"),
            (tag, "COUNT-1000000"): hsub(d0, b"COUNT 1 1 1 1", b"COUNT 1 1 1 1000000"),
            (tag, "COUNT-0"): hsub(d0, b"COUNT 1 1 1 1", b"COUNT 1 1 1 0"),
            (tag, "no-x-field"): hsub(d0, b"FIELDS x y z", b"FIELDS a y z"),
            (tag, "fields-count-mismatch"): hsub(d0, b"FIELDS x y z intensity", b"FIELDS x y z intensity ring"),
            (tag, "type-unknown"): hsub(d0, b"TYPE F F F F", b"TYPE Q F F F"),
            (tag, "type-U1-x"): hsub(hsub(d0, b"TYPE F F F F", b"TYPE U F F F"), b"SIZE 4 4 4 4", b"SIZE 1 4 4 4"),
            (tag, "binary-compressed"): d0.replace(b"DATA ascii" if tag == "a" else b"DATA binary", b"DATA binary_compressed", 1),
            (tag, "data-unknown"): d0.replace(b"DATA ascii" if tag == "a" else b"DATA binary", b"DATA hex", 1),
            (tag, "header-only"): d0[:d0.find(b"\n", d0.find(b"DATA")) + 1],
            (tag, "no-DATA-line"): d0[:d0.find(b"DATA")],
            (tag, "version-0.5"): d0.replace(b"VERSION 0.7", b"VERSION 0.5"),
            (tag, "viewpoint-garbage"): hsub(d0, b"VIEWPOINT 0 0 0 1 0 0 0", b"VIEWPOINT nan x"),
            (tag, "fields-10000"): hsub(hsub(hsub(d0, b"FIELDS x y z intensity", b"FIELDS x y z intensity" + b" f" * 10000),
                                          b"SIZE 4 4 4 4", b"SIZE 4 4 4 4" + b" 4" * 10000),
                                     b"TYPE F F F F", b"TYPE F F F F" + b" F" * 10000).replace(b"COUNT 1 1 1 1", b"COUNT 1 1 1 1" + b" 1" * 10000),
        })
    crafted_pcd[("a", "nan-points")] = pa0[:pa0.find(b"\n", pa0.find(b"DATA")) + 1] + b"nan nan nan nan\n" * npts
    crafted_pcd[("a", "inf-points")] = pa0[:pa0.find(b"\n", pa0.find(b"DATA")) + 1] + b"inf -inf 1e39 0\n" * npts
    crafted_pcd[("a", "too-few-fields-on-line")] = pa0.replace(b"\n", b" \n", 1)[:len(pa0) // 2] + b"1 2\n" + pa0[len(pa0) // 2:]
    crafted_pcd[("b", "nan-points")] = pb0[:pb0.find(b"\n", pb0.find(b"DATA")) + 1] + struct.pack("<4f", *[float("nan")] * 4) * npts
    crafted_pcd[("b", "1e38-points")] = pb0[:pb0.find(b"\n", pb0.find(b"DATA")) + 1] + struct.pack("<4f", 3e38, -3e38, 3e38, 0) * npts
    for (tag, name), data in crafted_pcd.items():
        scn = "lidar-camera-pcd" + tag
        rel = S[scn]["slots"]["scan"][0]
        make(scn, "crafted-pcd", name, f"{scn} {rel}: {name}", invalid=name not in ("version-0.5",),
             names=["0000000001.pcd"], mutate=(rel, "pcd" + tag, "data", data),
             q=(tag == "b" and name in ("POINTS-4000000000", "fields-10000")) or (tag == "a" and name == "POINTS-18446744073709551615"))
    bin0 = open(os.path.join(sw.base, "lc3/scans/0000000001.bin"), "rb").read()
    crafted_bin = {"size-not-multiple-of-16": bin0[:-5], "nan-points": struct.pack("<4f", *[float("nan")] * 4) * (len(bin0) // 16),
                   "inf-points": struct.pack("<4f", float("inf"), 0, 0, 0) * (len(bin0) // 16),
                   "1e38-points": struct.pack("<4f", 3e38, 3e38, -3e38, 1) * (len(bin0) // 16),
                   "all-zero": bytes(len(bin0)), "one-point": bin0[:16], "16-bytes-of-nan": struct.pack("<4f", *[float("nan")] * 4)}
    for name, data in crafted_bin.items():
        make("lidar-camera-bin", "crafted-bin", name, f"lidar-camera lc3/scans/0000000001.bin: {name}",
             invalid=name in ("size-not-multiple-of-16",), names=["0000000001.bin", "scans"],
             mutate=("lc3/scans/0000000001.bin", "bin", "data", data))
    meta0 = json.load(open(os.path.join(sw.base, "lc3/dev/ouster_points/.metadata.json")))

    def meta(f):
        m = json.loads(json.dumps(meta0))
        f(m)
        return json.dumps(m).encode()
    crafted_meta = {
        "offset-huge": meta(lambda m: m["fields"][0].update(offset=4000000000)),
        "offset-negative": meta(lambda m: m["fields"][1].update(offset=-4)),
        "datatype-99": meta(lambda m: m["fields"][2].update(datatype=99)),
        "count-1e9": meta(lambda m: m["fields"][3].update(count=1000000000)),
        "count-zero": meta(lambda m: m["fields"][0].update(count=0)),
        "no-fields": meta(lambda m: m.pop("fields")),
        "fields-empty": meta(lambda m: m.update(fields=[])),
        "no-x": meta(lambda m: m["fields"].pop(0)),
        "point_step-1": meta(lambda m: m.update(point_step=1)),
        "point_step-huge": meta(lambda m: m.update(point_step=2 ** 40)),
        "point_step-nan": b'{"fields": [], "point_step": NaN}',
        "offset-string": meta(lambda m: m["fields"][0].update(offset="zero")),
        "deep-json": b"[" * 100000 + b"]" * 100000,
        "json-50MB": meta(lambda m: m.update(pad="x" * (50 << 20))),
        "duplicate-fields": meta(lambda m: m["fields"].append(dict(m["fields"][0]))),
        "x-overlapping-end": meta(lambda m: m["fields"][0].update(offset=46)),
    }
    for name, data in crafted_meta.items():
        make("lidar-camera-devkit", "crafted-metadata", name, f"lidar-camera lc3/dev/ouster_points/.metadata.json: {name}",
             invalid=True, names=[".metadata.json"], mutate=("lc3/dev/ouster_points/.metadata.json", "json", "data", data),
             q=name == "count-1e9")

    # images
    png0 = open(os.path.join(sw.base, "st4/camera_left/data/0000000002.png"), "rb").read()
    jpg0 = open(os.path.join(sw.base, "jpg/left03.jpg"), "rb").read() if os.path.exists(os.path.join(sw.base, "jpg/left03.jpg")) else None
    crafted_png = {
        "ihdr-100000x100000": png_with_size(png0, 100000, 100000),
        "ihdr-2^31x2^31": png_with_size(png0, 2 ** 31 - 1, 2 ** 31 - 1),
        "ihdr-0x0": png_with_size(png0, 0, 0),
        "1x1": png_image(1, 1), "1x100000": png_image(1, 100000), "20000x20000-zeros-bomb": png_image(20000, 20000),
        "16-bit": png_image(64, 64, rows=b"".join(b"\x00" + bytes(128) for _ in range(64)), depth=16),
        "palette-without-PLTE": png_image(8, 8, depth=8, ctype=3),
        "other-size-64x64": png_image(64, 64),
        "wrong-crc": png0[:29] + b"\x00\x00\x00\x00" + png0[33:],
        "png-signature-only": png0[:8],
    }
    for name, data in crafted_png.items():
        for scn, rel in (("cameras", "st4/camera_left/data/0000000002.png"), ("lidar-camera-bin", "lc3/images/0000000001.png")):
            make(scn, "crafted-image", name, f"{scn} {rel}: {name}", invalid=False,
                 names=[os.path.basename(rel), "camera_left", "images"], mutate=(rel, "png", "data", data),
                 q=(scn == "cameras" and name in ("ihdr-100000x100000", "1x1")), cost=4)
    if jpg0:
        i = jpg0.find(b"\xff\xc0")
        if i < 0:
            i = jpg0.find(b"\xff\xc2")
        if i > 0:
            for name, (h, w) in {"sof-65535x65535": (65535, 65535), "sof-0x0": (0, 0), "sof-1x1": (1, 1)}.items():
                data = jpg0[:i + 5] + struct.pack(">HH", h, w) + jpg0[i + 9:]
                make("cameras-jpg", "crafted-image", name, f"cameras jpg/left03.jpg: {name}", invalid=False,
                     names=["left03.jpg"], mutate=("jpg/left03.jpg", "jpg", "data", data))

    # 4. options
    NUMS = ["nan", "inf", "-inf", "-1", "0", "1e308", "1e-320", "abc", ""]
    numeric = [
        ("cameras", "--outlier-sigma"), ("lidar-camera-devkit", "--max-dt"), ("lidar-camera-bin", "--corner-sigma"),
        ("time-offset", "--max-offset"), ("time-offset", "--min-overlap"), ("time-offset", "--window"),
        ("time-offset", "--min-excitation"), ("hand-eye", "--spacing"), ("hand-eye", "--stride"),
        ("hand-eye", "--gnss-smoothing"), ("hand-eye", "--min-rotation"), ("hand-eye", "--rotation-sigma"),
        ("hand-eye", "--translation-sigma"), ("hand-eye", "--max-sigma"), ("bench-tum", "--max-diff"),
        ("bench-tum", "--max-gap"), ("bench-tum", "--delta"), ("bench-tum", "--align-first"),
        ("bench-board", "--ate-max"), ("bench-board", "--rpe-max"), ("simulate", "--seed"),
    ]
    for scn, opt in numeric:
        vals = NUMS + (["1e20", "-0"] if opt in ("--align-first", "--seed", "--spacing") else []) \
            + (["1e9"] if opt in ("--max-offset", "--window", "--delta", "--spacing", "--stride") else [])
        for v in vals:
            ex = [opt, v]
            if scn == "bench-tum" and opt in ("--max-diff",):
                ex += ["--association", "nearest"]
            if scn == "bench-tum" and opt == "--delta":
                ex2 = [ex, ex + ["--delta-unit", "m"]]
            else:
                ex2 = [ex]
            for e in ex2:
                make(scn, "option", opt.lstrip("-") + "=" + v, f"{scn} {' '.join(e)}",
                     invalid=v in ("nan", "inf", "-inf", "abc", "") and opt != "--max-offset" or (v == "-1" and opt not in ("--seed",)),
                     names=[opt.lstrip("-")], extra=e, q=(v == "nan" and scn in ("bench-tum", "hand-eye") and opt in ("--delta", "--stride")),
                     cost=S[scn]["cost"] * (3 if v in ("1e-320", "0", "1e9", "1e308") else 1))
    for scn, opt, vals in [
        ("lidar-camera-bin", "--board-size", ["nan,1", "0,0", "-1,2", "1e308,1e308", "1", "a,b", "1,2,3", "0.001,0.001"]),
        ("lidar-camera-bin", "--roi", ["nan,0,0,1,1,1", "1,1,1,0,0,0", "0,0,0", "-inf,-inf,-inf,inf,inf,inf", "a,b,c,d,e,f", "0,0,0,0,0,0"]),
        ("hand-eye", "--fix", ["z=nan", "z=inf", "q=1", "z=", "=1", "z=1e308", "zz=1", "z"]),
        ("hand-eye", "--prior", ["z=1,0", "z=1,-1", "z=1,nan", "z=nan,1", "z=1", "z=1,1,1", "z=1,1e-320"]),
        ("hand-eye", "--duplicate-stamps", ["bogus", ""]), ("hand-eye", "--sensor", ["nosuch", ""]),
        ("hand-eye", "--lidar-sensor", ["nosuch", "gnss"]), ("hand-eye-fixes", "--attitude", ["bogus", "NED"]),
        ("bench-tum", "--format", ["bogus", "kitti", "euroc"]), ("bench-tum", "--convention", ["bogus", ""]),
        ("bench-tum", "--align", ["bogus", "sim3"]), ("bench-tum", "--association", ["bogus", "index"]),
        ("bench-tum", "--delta-unit", ["bogus", "km"]), ("bench-tum", "--duplicate-stamps", ["bogus"]),
        ("bench-tum", "--gt-format", ["bogus"]), ("bench-board", "--methods", ["", ",", "m1,m1", "nosuch", "../..", "m1,nosuch"]),
        ("simulate", "--what", ["bogus", "", "stereo,stereo", ","]), ("cameras", "--model", ["bogus", ""]),
        ("cameras", "--bayer", ["bogus", "RGGB"]), ("cameras-jpg", "--camera", ["noequals", "cam_l=nomatch/*.png", "=jpg/left*.jpg", "cam_l=jpg/left*.jpg"]),
        ("rig-convert-kalibr", "--imu", ["nosuch", "cam_l", ""]), ("publish", "--formats", ["bogus", "", "vbr,vbr", "ros,ros,mrcal"]),
        ("time-offset", "--reference-format", ["bogus", "table"]), ("time-offset", "--sensor", ["nosuch", "os_imu"]),
        ("time-offset", "--reference-sensor", ["nosuch", "imu"]), ("time-offset", "--max-offset", ["all", "ALL", "1,2"]),
        ("calibrate", "--from", ["bogus", "cameras", "hand_eye"]), ("calibrate", "--only", ["bogus", "time_sync"]),
        ("calibrate", "--model", ["bogus"]), ("calibrate", "--bayer", ["bogus"]), ("calibrate", "--lidar-camera", ["cam_x", "lidar"]),
        ("calibrate", "--fix", ["z=nan", "q=1"]), ("calibrate", "--attitude", ["bogus"]),
        ("lidar-camera-bin", "--camera", ["nosuch", "lidar"]), ("lidar-camera-bin", "--lidar", ["nosuch", "cam_r"]),
        ("lidar-camera-bin", "--bayer", ["bogus"]),
    ]:
        for v in vals:
            make(scn, "option", opt.lstrip("-") + "=" + v, f"{scn} {opt} '{v}'", invalid=False,
                 names=[opt.lstrip("-"), v] if v else [opt.lstrip("-")], extra=[opt, v],
                 q=(scn, opt, v) in (("hand-eye", "--prior", "z=1,0"), ("bench-tum", "--convention", "bogus")))
    if True:  # the option given twice, an unknown option, a stray positional
        for scn in ("rig-validate", "bench-tum", "hand-eye", "target-print"):
            make(scn, "option", "unknown-option", f"{scn} --frobnicate", names=["frobnicate"], extra=["--frobnicate"])
            make(scn, "option", "stray-positional", f"{scn} extra positional", names=["stray"], extra=["stray"])
    # 5. outputs naming inputs, odd output places
    outc = [
        ("rig-convert-rigcal", ["rig", "convert", "rig.yaml", "--to", "rigcal", "--out", "rig.yaml"], "out=input"),
        ("rig-convert-rigcal", ["rig", "convert", "rig.yaml", "--to", "rigcal", "--out", "./sub/../rig.yaml"], "out=input-via-dotdot"),
        ("rig-convert-rigcal", ["rig", "convert", "rig.yaml", "--to", "rigcal", "--out", "link.yaml"], "out=symlink-to-input"),
        ("rig-convert-rigcal", ["rig", "convert", "link.yaml", "--to", "rigcal", "--out", "rig.yaml"], "in=symlink out=its-target"),
        ("rig-convert-rigcal", ["rig", "convert", "rig.yaml", "--to", "rigcal", "--out", "hard.yaml"], "out=hardlink-of-input"),
        ("rig-convert-ros", ["rig", "convert", "rig.yaml", "--to", "ros", "--out", "."], "out-folder=the-input's-folder"),
        ("rig-convert-opencv", ["rig", "convert", "rig.yaml", "--to", "opencv", "--out", "nodir/a/b/x.yaml"], "out-in-missing-folder"),
        ("rig-convert-opencv", ["rig", "convert", "rig.yaml", "--to", "opencv", "--out", "ro/x.yaml"], "out-in-read-only-folder"),
        ("rig-convert-opencv", ["rig", "convert", "rig.yaml", "--to", "opencv", "--out", "out"], "out-is-a-folder"),
        ("rig-convert-opencv", ["rig", "convert", "rig.yaml", "--to", "opencv", "--out", "/dev/full"], "out=/dev/full"),
        ("rig-convert-opencv", ["rig", "convert", "rig.yaml", "--to", "opencv", "--out", ""], "out-empty"),
        ("target-print", ["target", "print", "a3_checkerboard_8x5_40mm.yaml", "--out", "a3_checkerboard_8x5_40mm.yaml"], "out=input"),
        ("target-print", ["target", "print", "a3_checkerboard_8x5_40mm.yaml", "--out", "ro/t.pdf"], "out-in-read-only-folder"),
        ("cameras", ["cameras", "--target", "target.yaml", "--session", "st4", "--out", "target.yaml", "--report", "out/rep"], "out=target"),
        ("cameras", ["cameras", "--target", "target.yaml", "--session", "st4", "--out", "st4/camera_left/data/0000000000.png", "--report", "out/rep"], "out=an-image"),
        ("cameras", ["cameras", "--target", "target.yaml", "--session", "st4", "--out", "out/cam.yaml", "--report", "st4/camera_left/data"], "report=the-image-folder"),
        ("cameras", ["cameras", "--target", "target.yaml", "--session", "st4", "--out", "out/cam.yaml", "--report", "target.yaml"], "report=a-file"),
        ("cameras", ["cameras", "--target", "target.yaml", "--session", "st4", "--out", "ro/cam.yaml", "--report", "out/rep"], "out-in-read-only-folder"),
        ("lidar-camera-bin", ["lidar-camera", "--target", "target.yaml", "--rig", "rig.yaml", "--out", "target.yaml", "--images", "lc3/images/*.png", "--scans", "lc3/scans/*.bin"], "out=target"),
        ("lidar-camera-bin", ["lidar-camera", "--target", "target.yaml", "--rig", "rig.yaml", "--out", "lc3/scans/0000000000.bin", "--images", "lc3/images/*.png", "--scans", "lc3/scans/*.bin"], "out=a-scan"),
        ("time-offset", ["time-offset", "--session", "imus", "--rig", "rig.yaml", "--sensor", "imu", "--reference-sensor", "os_imu", "--out", "imus/imu/data/imu.txt"], "out=imu-log"),
        ("time-offset", ["time-offset", "--session", "imus", "--rig", "rig.yaml", "--sensor", "imu", "--reference-sensor", "os_imu", "--out", "out/to.yaml", "--report", "imus/imu/data"], "report=input-folder"),
        ("hand-eye", ["hand-eye", "--lidar", "sim/trajectories/lidar_odometry.tum", "--gnss", "sim/trajectories/gnss_ins.tum", "--rig", "rig.yaml", "--out", "sim/trajectories/gnss_ins.tum"], "out=gnss-input"),
        ("hand-eye", ["hand-eye", "--lidar", "sim/trajectories/lidar_odometry.tum", "--gnss", "sim/trajectories/lidar_odometry.tum", "--rig", "rig.yaml", "--out", "out/he.yaml"], "lidar=gnss-same-file"),
        ("bench-tum", ["bench", "--gt", "bench/drive_gt.txt", "--est", "bench/drive_es.txt", "--report", "bench"], "report=input-folder"),
        ("bench-tum", ["bench", "--gt", "bench/drive_gt.txt", "--est", "bench/drive_gt.txt"], "gt=est"),
        ("bench-board", ["bench", "--gt-dir", "board/G", "--est-dir", "board/E", "--methods", "m1,m2", "--report", "board/G"], "report=gt-dir"),
        ("bench-board", ["bench", "--gt-dir", "board/G", "--est-dir", "board/G", "--report", "out/rep"], "est-dir=gt-dir"),
        ("calibrate", ["calibrate", "sim", "--rig", "prior.yaml", "--out", "sim"], "out=the-session"),
        ("calibrate", ["calibrate", "sim", "--rig", "prior.yaml", "--out", "sim/stereo"], "out=a-recording"),
        ("calibrate", ["calibrate", "sim", "--rig", "sim/session.yaml", "--out", "out"], "rig=session.yaml"),
        ("calibrate", ["calibrate", "sim", "--rig", "prior.yaml", "--out", "prior.yaml"], "out=the-prior-rig-file"),
        ("calibrate", ["calibrate", "nosuch", "--rig", "prior.yaml", "--out", "out"], "missing-session"),
        ("calibrate", ["calibrate", "prior.yaml", "--rig", "prior.yaml", "--out", "out"], "session-is-a-file"),
        ("calibrate", ["calibrate", "sim", "--rig", "prior.yaml", "--out", "ro/out"], "out-in-read-only-folder"),
        ("publish", ["publish", "cal/calib.yaml", "cal"], "sequence=the-calibration's-folder"),
        ("publish", ["publish", "cal/calib.yaml", "out/place/seq", "out/place/seq"], "same-sequence-twice"),
        ("publish", ["publish", "cal/calib.yaml", "linkseq", "--force"], "sequence-vbr_calib-links-to-input"),
        ("publish", ["publish", "cal/calib.yaml", "ro/seq"], "sequence-read-only"),
        ("publish", ["publish", "cal/calib.yaml", "nosuch/seq"], "sequence-missing"),
        ("simulate", ["simulate", "--out", "out/sim", "--config", "tiny.yaml", "--what", "imu", "--rig", "out/sim/rig.yaml", "--force"], "force-out-holds-the-rig"),
        ("simulate", ["simulate", "--out", ".", "--config", "tiny.yaml", "--what", "imu", "--force"], "force-out=cwd-holding-inputs"),
        ("simulate", ["simulate", "--out", "tiny.yaml", "--config", "tiny.yaml", "--what", "imu"], "out=config-file"),
        ("simulate", ["simulate", "--out", "ro/sim", "--config", "tiny.yaml", "--what", "imu"], "out-in-read-only-folder"),
    ]
    for scn, argv, name in outc:
        make(scn, "output-path", name, f"{' '.join(argv)} ({name})", invalid=False,
             names=["out", "report", "rig", "session", "sequence", "seq", "yaml", "ro", "prior", "sim", "input"],
             argv=argv, as_nobody="read-only" in name, q=name in ("out=input", "out=symlink-to-input"),
             post=name, allow3=True)
    return cases


# ------------------------------------------------------------------------------------------
# Materialising, running and judging one case

def setup_case(sw, spec, cid, d):
    S = scenarios()
    s = S[spec["scn"]]
    os.makedirs(d)
    real = spec["post"] is not None or spec["as_nobody"]
    for rel in s["clone"]:
        (sw.copy if real else sw.clone)(rel, d)
    for item in s["copy"]:
        src, dst = item if isinstance(item, tuple) else (item, item)
        p = os.path.join(sw.base, src)
        q = os.path.join(d, dst)
        os.makedirs(os.path.dirname(q), exist_ok=True)
        if os.path.isdir(p):
            shutil.copytree(p, q)
        else:
            shutil.copy2(p, q)
    for rel in s["prev"]:
        q = os.path.join(d, rel)
        os.makedirs(os.path.dirname(q), exist_ok=True)
        with open(q, "w") as f:
            f.write("# a previous complete output of an earlier run\nprevious: true\n")
    for rel in s["outs"] + s["reports"]:
        os.makedirs(os.path.dirname(os.path.join(d, rel)) or d, exist_ok=True)
    desc_extra = ""
    if spec["mutate"]:
        rel, kind, how, arg = spec["mutate"]
        p = os.path.join(d, rel)
        data = open(p, "rb").read() if os.path.isfile(p) else b""
        if os.path.lexists(p):
            os.unlink(p)              # never write through a hard link to the base
        if how == "fault":
            fault = arg
            rng = random.Random(crc(f"{sw.a.seed}:{cid.split('-', 1)[1]}:{rel}:{fault}"))
            if fault == "missing":
                pass
            elif fault == "dir":
                os.makedirs(p)
            elif fault == "loop":
                os.symlink(os.path.basename(p), p)
            elif fault == "dangling":
                os.symlink("does-not-exist-" + os.path.basename(p), p)
            elif fault == "unreadable":
                with open(p, "wb") as f:
                    f.write(data)
                os.chmod(p, 0)
            elif fault == "fifo":
                os.mkfifo(p)
            elif fault == "devzero":
                os.symlink("/dev/zero", p)
            else:
                new = fault_content(kind, data, fault, rng)
                with open(p, "wb") as f:
                    f.write(new)
        elif how == "mutate":
            rng = random.Random(arg)
            if kind in TEXT_KINDS:
                new, desc_extra = mutate_text(data, rng)
            else:
                new, desc_extra = mutate_binary(data, rng, header=1200 if kind in ("pcdb",) else 64)
            with open(p, "wb") as f:
                f.write(new)
        else:
            with open(p, "wb") as f:
                f.write(arg)
    post = spec["post"]
    if post:
        if "read-only" in post:
            os.makedirs(os.path.join(d, "ro", "seq") if post == "sequence-read-only" else os.path.join(d, "ro"), exist_ok=True)
        if post in ("out=symlink-to-input", "in=symlink out=its-target"):
            os.symlink("rig.yaml", os.path.join(d, "link.yaml"))
        if post == "out=hardlink-of-input":
            os.link(os.path.join(d, "rig.yaml"), os.path.join(d, "hard.yaml"))
        if post == "out=input-via-dotdot":
            os.makedirs(os.path.join(d, "sub"))
        if post == "sequence-vbr_calib-links-to-input":
            os.makedirs(os.path.join(d, "linkseq"))
            os.symlink("../cal/calib.yaml", os.path.join(d, "linkseq", "vbr_calib.yaml"))
        if post == "force-out-holds-the-rig":
            os.makedirs(os.path.join(d, "out/sim"), exist_ok=True)
            shutil.copy(os.path.join(sw.base, "rig.yaml"), os.path.join(d, "out/sim/rig.yaml"))
        if post == "out-is-a-folder":
            os.makedirs(os.path.join(d, "out"), exist_ok=True)
    os.makedirs(os.path.join(d, ".sweep-tmp"))
    if spec["as_nobody"]:
        for p, ds, fs in os.walk(d):
            os.chmod(p, 0o777)
            for n in fs:
                q = os.path.join(p, n)
                if not os.path.islink(q) and os.stat(q).st_mode & 0o777:
                    os.chmod(q, 0o666)
        for ro in (os.path.join(d, "ro", "seq"), os.path.join(d, "ro")):
            if os.path.isdir(ro):
                os.chmod(ro, 0o555)
    argv = spec["argv"] or (s["argv"] + spec["extra"])
    return argv, desc_extra


def preexec():
    os.setsid()
    resource.setrlimit(resource.RLIMIT_AS, (MEM_LIMIT, MEM_LIMIT))
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))


def run_proc(sw, argv, cwd, log, as_nobody, timeout):
    """rigcal under /usr/bin/time (peak RSS of rigcal alone) and prlimit (the address-space cap)."""
    env = {"PATH": "/usr/bin:/bin", "HOME": cwd, "TMPDIR": os.path.join(cwd, ".sweep-tmp"), "LANG": "C.UTF-8"}
    out = open(log + ".stdout", "wb")
    err = open(log + ".stderr", "wb")
    kw = dict(user=NOBODY, group=NOBODY, extra_groups=[]) if as_nobody else {}
    timef = log + ".time"
    open(timef, "w").close()
    os.chmod(timef, 0o666)        # /usr/bin/time writes it as the run's user
    wrap = []
    if os.path.exists("/usr/bin/time"):
        wrap += ["/usr/bin/time", "-f", "%M %x", "-o", timef]
    wrap += ["prlimit", f"--as={MEM_LIMIT}", "--core=0", "--"]
    t0 = time.monotonic()
    p = subprocess.Popen(wrap + [sw.bin] + argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=out, stderr=err, env=env,
                         start_new_session=True, **kw)
    hung = False
    ru = None
    try:
        p.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        hung = True
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except OSError:
            pass
        p.wait()
    wall = time.monotonic() - t0
    out.close()
    err.close()
    rc, rss = p.returncode, 0
    try:
        t = open(timef).read().splitlines()
        m = re.match(r"(\d+) (-?\d+)", t[-1])
        rss = int(m.group(1))
        sig = [re.search(r"signal (\d+)", l) for l in t if "terminated by signal" in l]
        rc = -int(sig[0].group(1)) if sig and sig[0] else int(m.group(2))
    except (OSError, IndexError, AttributeError, ValueError):
        pass
    return dict(rc=rc, hung=hung, wall=round(wall, 3), rss_kb=rss,
                stderr=open(log + ".stderr", "rb").read(), stdout_bytes=os.path.getsize(log + ".stdout"))


ERR_RE = re.compile(rb"error", re.I)


def judge(spec, s, res, before, after, inputs_before, inputs_after, tmp_after):
    v, notes = [], []
    rc = res["rc"]
    lines = [l for l in res["stderr"].replace(b"\r", b"\n").split(b"\n") if l.strip()]
    last = lines[-1] if lines else b""
    if res["hung"]:
        v.append("hang")
    elif rc < 0:
        v.append("signal")
    if res["rss_kb"] > RSS_LIMIT_KB:
        v.append("memory")
    if not res["hung"] and rc >= 0:
        if rc == 1:
            v.append("exit-1")
        elif rc not in (0, 2, 3) or (rc == 3 and not spec["allow3"]):
            v.append("unexpected-exit")
        if rc == 1 and (b"bad_alloc" in res["stderr"] or b"memory" in res["stderr"].lower()):
            notes.append("out of memory under the 4 GB address-space cap")
    if rc == 2 and not res["hung"]:
        if not lines:
            v.append("no-message")
        else:
            errl = [l for l in lines if ERR_RE.search(l)]
            if len(lines) > 1:
                if len(errl) > 1 or not ERR_RE.search(last):
                    v.append("multi-line-stderr")
                else:
                    notes.append(f"{len(lines) - 1} progress line(s) before the error")
            try:
                last.decode("utf-8")
            except UnicodeDecodeError:
                v.append("message-invalid-utf8")
            names = [n.encode() for n in (spec["names"] or []) if n]
            if names and not any(n in last for n in names):
                if re.search(rb"[\w.-]+\.(yaml|yml|txt|tum|csv|pcd|bin|png|jpg|json|vnl|pdf)\b|/", last):
                    notes.append("the message names another file or path")
                else:
                    v.append("message-not-naming-file")
            if spec["mutate"] and spec["mutate"][1] in TEXT_KINDS and not re.search(rb":\d+", last):
                notes.append("no line number")
    if rc == 0 and spec["invalid"]:
        v.append("accepted-invalid")
    if "50MB" in spec["kind"]:
        if rc == 0:
            notes.append("50 MB file accepted (no size limit)")
        if res["wall"] > 1.0:
            notes.append(f"50 MB file took {res['wall']:.1f} s (no early size limit)")
    # inputs
    changed = [p for p, h in inputs_before.items() if inputs_after.get(p) != h]
    if changed:
        v.append("input-changed")
        notes.append("inputs changed or removed: " + ", ".join(sorted(changed)[:8]))
    # outputs
    if rc != 0 or res["hung"]:
        bad = []
        for rel in s["outs"] + (s["reports"] if (rc == 2 and s["report_on_2"]) else []):
            b, a = before.get(rel, {}), after.get(rel, {})
            if a != b and a:
                bad.append(rel)
        if bad:
            v.append("half-written")
            notes.append("written on failure: " + ", ".join(bad))
    if tmp_after:
        v.append("temp-left")
        notes.append("temporary files left: " + ", ".join(tmp_after[:8]))
    return v, notes, len(lines), last


def run_case(sw, spec, idx):
    S = scenarios()
    s = S[spec["scn"]]
    cid = f"{idx:05d}-{spec['scn']}"
    d = os.path.join(sw.cases_dir, cid)
    argv, desc_extra = setup_case(sw, spec, cid, d)
    outs = [os.path.join(d, r) for r in s["outs"] + s["reports"]]
    before = {r: snapshot(os.path.join(d, r)) for r in s["outs"] + s["reports"]}
    full_before = snapshot(d)

    def inputs(snap):
        return {p: h for p, h in snap.items()
                if h.startswith("file:") or h.startswith("link:") or h == "other"
                if not any(p == r or p.startswith(r.rstrip("/") + "/") for r in s["outs"] + s["reports"] + [".sweep-tmp"])}
    inputs_before = inputs(full_before)
    if spec["post"] and "out" not in spec["post"] and "report" not in spec["post"]:
        pass
    res = run_proc(sw, argv, d, d + ".log", spec["as_nobody"], sw.a.timeout * (3 if spec["cost"] >= 5 and spec["kind"] not in ("fifo", "devzero") else 1))
    subprocess.run(["chmod", "-R", "u+rwX", d], stderr=subprocess.DEVNULL)
    full_after = snapshot(d)
    after = {r: snapshot(os.path.join(d, r)) for r in s["outs"] + s["reports"]}
    inputs_after = inputs(full_after)
    # for outputs that name an input, the output is the input: keep checking it as an input
    tmp_after = sorted(p for p in full_after if p not in full_before and looks_temp(os.path.basename(p)))
    tmp_after += [".sweep-tmp/" + n for n in os.listdir(os.path.join(d, ".sweep-tmp"))] if os.path.isdir(os.path.join(d, ".sweep-tmp")) else []
    v, notes, nlines, last = judge(spec, s, res, before, after, inputs_before, inputs_after, tmp_after)
    desc = spec["desc"] + (f" [{desc_extra}]" if desc_extra else "")
    cmd = "cd " + d + " && " + ("sudo -u nobody " if spec["as_nobody"] else "") + sw.bin + " " + " ".join(shquote(a) for a in argv)
    return dict(id=cid, scenario=spec["scn"], group=spec["group"], kind=spec["kind"], input=desc, command=cmd,
                exit=res["rc"] if not res["hung"] else None, signal=(-res["rc"] if res["rc"] < 0 and not res["hung"] else None),
                timeout=res["hung"], wall_s=res["wall"], peak_rss_mb=round(res["rss_kb"] / 1024, 1),
                stderr_lines=nlines, stderr=res["stderr"][-4000:].decode("utf-8", "backslashreplace"),
                last_line=last[-600:].decode("utf-8", "backslashreplace"), violations=v, notes=notes)


def shquote(a):
    if a and re.fullmatch(r"[\w@%+=:,./-]+", a):
        return a
    return "'" + a.replace("'", "'\"'\"'") + "'"


# ------------------------------------------------------------------------------------------
# Concurrent writers on one output

def concurrency(sw, quick):
    d = os.path.join(sw.cases_dir, "concurrency")
    os.makedirs(d)
    results = []
    for rel in ("rig.yaml", "cal/calib.yaml", "tiny.yaml", "sim", "sim2", "prior.yaml", "st4", "target.yaml"):
        if os.path.exists(os.path.join(sw.base, rel)):
            sw.clone(rel, d)
    tests = [
        ("rig-convert", "out.yaml",
         ["rig", "convert", "rig.yaml", "--to", "rigcal", "--out", "out.yaml"],
         ["rig", "convert", "cal/calib.yaml", "--to", "rigcal", "--out", "out.yaml"], 6),
        ("rig-convert-ros", "outros",
         ["rig", "convert", "rig.yaml", "--to", "ros", "--out", "outros"],
         ["rig", "convert", "cal/calib.yaml", "--to", "ros", "--out", "outros"], 4),
        ("publish", "seq",
         ["publish", "rig.yaml", "seq", "--formats", "vbr,kalibr,ros,opencv", "--force"],
         ["publish", "cal/calib.yaml", "seq", "--formats", "vbr,kalibr,ros,opencv", "--force"], 4),
        ("simulate", "outsim",
         ["simulate", "--out", "outsim", "--config", "tiny.yaml", "--what", "imu,trajectories", "--seed", "1", "--force"],
         ["simulate", "--out", "outsim", "--config", "tiny.yaml", "--what", "imu,trajectories", "--seed", "2", "--force"], 3),
        ("cameras", "outcam",
         ["cameras", "--target", "target.yaml", "--session", "st4", "--out", "outcam/cam.yaml", "--report", "outcam/rep"],
         ["cameras", "--target", "target.yaml", "--session", "st4", "--model", "pinhole-radtan5", "--out", "outcam/cam.yaml", "--report", "outcam/rep"], 2),
        ("calibrate", "outcal",
         ["calibrate", "sim", "--rig", "prior.yaml", "--out", "outcal"],
         ["calibrate", "sim2", "--rig", "prior.yaml", "--out", "outcal"], 3),
    ]
    if quick:
        tests = [t[:4] + (2,) for t in tests[:1]]
    for name, out, a, b, rounds in tests:
        log = os.path.join(d, name)
        refs = {}
        for tag, argv in (("A", a), ("B", b)):
            if os.path.exists(os.path.join(d, out)):
                shutil.rmtree(os.path.join(d, out)) if os.path.isdir(os.path.join(d, out)) else os.unlink(os.path.join(d, out))
            r = run_proc(sw, argv, d, log + "." + tag, False, 120)
            refs[tag] = snapshot(os.path.join(d, out))
            shutil.move(os.path.join(d, out), os.path.join(d, f"{name}.ref{tag}")) if os.path.exists(os.path.join(d, out)) else None
        for k in range(rounds):
            target = os.path.join(d, out)
            if os.path.exists(target):
                shutil.rmtree(target) if os.path.isdir(target) else os.unlink(target)
            if name == "publish":
                os.makedirs(target)
            box = {}

            def go(tag, argv, delay):
                time.sleep(delay)
                box[tag] = run_proc(sw, argv, d, f"{log}.r{k}{tag}", False, 120)
            ths = [threading.Thread(target=go, args=("A", a, 0)), threading.Thread(target=go, args=("B", b, 0.003 * k))]
            [t.start() for t in ths]
            [t.join() for t in ths]
            snap = snapshot(target)
            keep = lambda sn: {p: h for p, h in sn.items() if not re.search(r"\.png$|\.svg$|\.pdf$", p)}
            sA, sB, sN = keep(refs["A"]), keep(refs["B"]), keep(snap)
            files = sorted(set(sA) | set(sB) | set(sN))
            fromA = [p for p in files if sN.get(p) == sA.get(p) and sA.get(p) != sB.get(p)]
            fromB = [p for p in files if sN.get(p) == sB.get(p) and sA.get(p) != sB.get(p)]
            neither = [p for p in files if sN.get(p) != sA.get(p) and sN.get(p) != sB.get(p)]
            temps = [p for p in snap if looks_temp(os.path.basename(p))]
            v, notes = [], []
            verdict = "A" if sN == sA else "B" if sN == sB else "mixture"
            if verdict == "mixture":
                v.append("concurrency")
                notes.append(f"files from A: {fromA[:6]}; from B: {fromB[:6]}; matching neither: {neither[:6]}")
            if temps:
                v.append("temp-left")
                notes.append("temporary files left: " + ", ".join(temps[:6]))
            for tag in "AB":
                rr = box[tag]
                if rr["hung"]:
                    v.append("hang")
                elif rr["rc"] < 0:
                    v.append("signal")
                elif rr["rc"] == 1:
                    v.append("exit-1")
            results.append(dict(id=f"concurrency-{name}-{k}", scenario=name, group="concurrency", kind="two writers",
                                input=f"two runs at once on the same output '{out}'",
                                command=f"cd {d} && ({sw.bin} {' '.join(shquote(x) for x in a)} & {sw.bin} {' '.join(shquote(x) for x in b)} & wait)",
                                exit=[box['A']['rc'], box['B']['rc']], signal=None, timeout=box['A']['hung'] or box['B']['hung'],
                                wall_s=max(box['A']['wall'], box['B']['wall']),
                                peak_rss_mb=round(max(box['A']['rss_kb'], box['B']['rss_kb']) / 1024, 1),
                                stderr_lines=None, stderr=(box['A']['stderr'][-800:] + b"\n--- B ---\n" + box['B']['stderr'][-800:]).decode("utf-8", "backslashreplace"),
                                last_line="", verdict=verdict, violations=v, notes=notes))
            if os.path.exists(target):
                shutil.move(target, os.path.join(d, f"{name}.round{k}"))
    return results


# ------------------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("rigcal")
    ap.add_argument("source")
    ap.add_argument("work")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=20)
    ap.add_argument("--only", default="", help="run only cases whose description contains this")
    ap.add_argument("--fixtures", default="")
    ap.add_argument("--no-concurrency", action="store_true")
    a = ap.parse_args()
    if a.quick and a.timeout == 20:
        a.timeout = 10
    sw = Sweep(a)
    t0 = time.monotonic()
    sw.prepare()
    specs = build_cases(sw, a.quick)
    if a.quick:
        rng = random.Random(a.seed)
        chosen = [s for s in specs if s["q"]]
        rest = [s for s in specs if not s["q"] and s["cost"] <= 0.5 and "50MB" not in s["kind"]]
        rng.shuffle(rest)
        budget = 85 - len(chosen)
        by_kind = {}
        for s in rest:
            key = (s["group"], s["scn"])
            if by_kind.get(key, 0) < 2 and budget > 0:
                chosen.append(s)
                by_kind[key] = by_kind.get(key, 0) + 1
                budget -= 1
        order = {id(s): i for i, s in enumerate(specs)}
        specs = sorted(chosen, key=lambda s: order[id(s)])
    if a.only:
        specs = [s for s in specs if a.only in s["desc"] or a.only == s["scn"]]
    print(f"{len(specs)} cases ({'quick' if a.quick else 'full'}, seed {a.seed}), {a.jobs} at a time; base ready in "
          f"{time.monotonic() - t0:.0f} s", flush=True)
    results = [None] * len(specs)
    order = sorted(range(len(specs)), key=lambda i: -specs[i]["cost"])
    lock = threading.Lock()
    done = [0]
    jl = open(os.path.join(sw.work, "cases.jsonl"), "w")

    def worker():
        while True:
            with lock:
                if not order:
                    return
                i = order.pop(0)
            try:
                r = run_case(sw, specs[i], i + 1)
            except Exception as e:  # a sweep bug: say so, never hide a case
                import traceback
                r = dict(id=f"{i + 1:05d}-{specs[i]['scn']}", scenario=specs[i]["scn"], group=specs[i]["group"],
                         kind=specs[i]["kind"], input=specs[i]["desc"], command="", exit=None, signal=None,
                         timeout=False, wall_s=0, peak_rss_mb=0, stderr_lines=0, stderr="", last_line="",
                         violations=["sweep-error"], notes=[traceback.format_exc()[-800:]])
            results[i] = r
            with lock:
                jl.write(json.dumps(r) + "\n")
                jl.flush()
                done[0] += 1
                if r["violations"]:
                    print(f"[{done[0]}/{len(specs)}] {r['id']} {','.join(r['violations'])}: {r['input'][:150]}", flush=True)
                elif done[0] % 100 == 0:
                    print(f"[{done[0]}/{len(specs)}] ...", flush=True)
    ths = [threading.Thread(target=worker) for _ in range(max(1, a.jobs))]
    [t.start() for t in ths]
    [t.join() for t in ths]
    if not a.no_concurrency and not a.only:
        results += concurrency(sw, a.quick)
    # base intact?
    for p, h in snapshot(sw.base).items():
        pass
    report(sw, results, time.monotonic() - t0)
    bad = [r for r in results if r["violations"]]
    sys.exit(1 if bad else 0)


def report(sw, results, elapsed):
    from collections import Counter, defaultdict
    by = defaultdict(list)
    for r in results:
        for v in r["violations"]:
            by[v].append(r)
    lines = []
    groups = Counter(r["group"] for r in results)
    scn = Counter(r["scenario"] for r in results)
    exits = Counter(str(r["exit"]) if not r["timeout"] else "timeout" for r in results)
    lines.append(f"rigcal sweep: {len(results)} cases in {elapsed:.0f} s (seed {sw.a.seed}{', quick' if sw.a.quick else ''})")
    lines.append("by kind:     " + ", ".join(f"{k} {v}" for k, v in sorted(groups.items())))
    lines.append("by command:  " + ", ".join(f"{k} {v}" for k, v in sorted(scn.items())))
    lines.append("exit codes:  " + ", ".join(f"{k}: {v}" for k, v in sorted(exits.items())))
    rss = max((r["peak_rss_mb"] for r in results), default=0)
    slow = max(results, key=lambda r: r["wall_s"]) if results else None
    lines.append(f"max peak RSS {rss} MB; slowest {slow['wall_s'] if slow else 0} s ({slow['id'] if slow else ''})")
    notes = Counter(n.split(":")[0] for r in results for n in r["notes"] if not n.startswith("inputs changed"))
    lines.append("notes:       " + "; ".join(f"{k} ({v})" for k, v in notes.most_common(12)))
    nviol = sum(1 for r in results if r["violations"])
    lines.append(f"\n{nviol} case(s) violate the promise")
    lines.append(f"{'id':28} {'violation':26} {'exit':>7} {'wall':>6} {'rss MB':>7}  input")
    for v in SEVERITY + sorted(set(by) - set(SEVERITY)):
        for r in by.get(v, []):
            ex = "T/O" if r["timeout"] else (f"sig{r['signal']}" if r["signal"] else str(r["exit"]))
            lines.append(f"{r['id']:28} {v:26} {ex:>7} {r['wall_s']:6.2f} {r['peak_rss_mb']:7.1f}  {r['input'][:160]}")
            lines.append(f"{'':28}   $ {r['command'][:400]}")
            if r["last_line"]:
                lines.append(f"{'':28}   stderr({r['stderr_lines']}): {r['last_line'][:300]}")
            for n in r["notes"]:
                lines.append(f"{'':28}   note: {n[:300]}")
    txt = "\n".join(lines) + "\n"
    with open(os.path.join(sw.work, "summary.txt"), "w") as f:
        f.write(txt)
    with open(os.path.join(sw.work, "sweep.json"), "w") as f:
        json.dump(dict(seed=sw.a.seed, quick=sw.a.quick, binary=sw.bin, elapsed_s=round(elapsed, 1), cases=results), f, indent=1)
    head = txt if len(txt) < 20000 else txt[:20000] + f"\n... (the rest in {os.path.join(sw.work, 'summary.txt')})\n"
    print(head)
    print(f"every case: {os.path.join(sw.work, 'sweep.json')}")


if __name__ == "__main__":
    main()
