#!/usr/bin/python3
"""Issue 17, item 1, as a user would: the real binaries, no test code in between.

  dynid-server --store <temp>/store.db --cyclone-config deploy/cyclonedds/loopback.xml
  dynid-car --profile deploy/profiles/rav4.toml --replay <RAV4 candump log> --fast
            --source recorder_imu=<phone_imu_accel.csv>     (the clock offset is estimated, printed)
  dynid --json trace --vehicle rav4-2017 --run seg40 --model kinematic_longitudinal

The loop must add the road grade (road_grade_profile) to the kinematic model, and the grade it
implies, asin(contribution / g), must follow the GNSS/INS grade of pose.csv (correlation >= 0.85).
This script only starts the programs and reads what they print.

usage: rav4_auxiliary_e2e.py BUILD_DIR SOURCE_DIR SHARED_DATA
Exit 0 pass, 1 fail, 77 skip (the reference data is absent).
"""
import json
import os
import re
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np

build, source, shared = sys.argv[1:4]
data = os.path.join(shared, "rav4-comma2k19")
log = os.path.join(data, "rav4_2018-08-02_seg40.candump.log")
if not os.path.isfile(log):
    print(f"SKIP: reference data {data} is absent (../shared/data beside the clone)")
    sys.exit(77)
server_bin = os.path.join(build, "server", "dynid-server")
car_bin = os.path.join(build, "client", "car", "dynid-car")
cli_bin = os.path.join(build, "client", "cli", "dynid")
config = os.path.join(source, "deploy", "cyclonedds", "loopback.xml")
profile = os.path.join(source, "deploy", "profiles", "rav4.toml")
G = 9.80665
DOMAIN = "37"  # a DDS domain of its own: other e2e tests use 17..31


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def gnss_grade(path):
    """The road grade of the recorder's GNSS/INS pose: the slope of the ECEF velocity against
    the WGS84 ellipsoid normal (as tests/residual/test_rav4_grade.cpp computes it)."""
    p = np.loadtxt(path, delimiter=",", skiprows=1)
    a, f = 6378137.0, 1.0 / 298.257223563
    b = a * (1 - f)
    e2, ep2 = f * (2 - f), (a * a - b * b) / (b * b)
    x, y, z = p[:, 1], p[:, 2], p[:, 3]
    r = np.hypot(x, y)
    th = np.arctan2(z * a, r * b)
    lat = np.arctan2(z + ep2 * b * np.sin(th) ** 3, r - e2 * a * np.cos(th) ** 3)
    lon = np.arctan2(y, x)
    up = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=1)
    vel = p[:, 4:7]
    vertical = np.sum(vel * up, axis=1)
    horizontal = np.linalg.norm(vel - vertical[:, None] * up, axis=1)
    keep = horizontal >= 1.0
    return p[keep, 0], np.arctan2(vertical[keep], horizontal[keep])


with tempfile.TemporaryDirectory(prefix="dynid-rav4-aux-") as tmp:
    server = subprocess.Popen([server_bin, "--store", os.path.join(tmp, "store.db"), "--cyclone-config", config,
                               "--domain", DOMAIN],
                              stdout=subprocess.DEVNULL, stderr=open(os.path.join(tmp, "server.log"), "w"))
    try:
        car_cmd = [car_bin, "--profile", profile, "--cyclone-config", config, "--domain", DOMAIN, "--run", "seg40", "--replay", log,
                   "--fast", "--spool", os.path.join(tmp, "spool"),
                   "--source", "recorder_imu=" + os.path.join(data, "phone_imu_accel.csv")]
        print("$ " + " ".join(car_cmd))
        car = subprocess.run(car_cmd, capture_output=True, text=True, timeout=240)
        lines = [l for l in car.stderr.splitlines() if "dynid-car" in l]
        print("\n".join(lines))
        if car.returncode != 0:
            fail(f"dynid-car exited {car.returncode}")
        clock = re.search(r"source 'recorder_imu' .*clock offset ([-+0-9.]+) s \+- ([0-9.]+) s", car.stderr)
        if not clock:
            fail("dynid-car did not print the estimated clock offset of recorder_imu")
        offset, offset_std = float(clock.group(1)), float(clock.group(2))
        origin = re.search(r"grid row 0 is at ([0-9.]+) s of the log's clock", car.stderr)
        if not origin:
            fail("dynid-car did not print where the grid starts on the log's clock")
        origin = float(origin.group(1))

        trace_cmd = [cli_bin, "--cyclone-config", config, "--domain", DOMAIN, "--json", "trace", "--vehicle", "rav4-2017", "--run", "seg40",
                     "--model", "kinematic_longitudinal"]
        print("$ " + " ".join(trace_cmd))
        trace = subprocess.run(trace_cmd, capture_output=True, text=True, timeout=240)
        if trace.returncode != 0:
            fail(f"dynid trace exited {trace.returncode}: {trace.stderr}")
        report = json.loads(trace.stdout)
    finally:
        server.send_signal(signal.SIGTERM)
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            server.kill()

print("trace: added " + ", ".join(report["added"]) + "; stopped: " + report["stopped"])
grade_round = next((r for r in report["rounds"] if r.get("added") and r["added"]["effect"] == "road_grade_profile"), None)
if grade_round is None:
    fail("the loop did not add road_grade_profile")
series = grade_round["added"]["effect_series"]
if not series:
    fail("the trace reports no series of the added effect")
t = np.array(series[0]["time_s"]) + origin
implied = np.arcsin(np.clip(np.array(series[0]["contribution"]) / G, -1, 1))
gt, gg = gnss_grade(os.path.join(data, "pose.csv"))
gnss = np.interp(t, gt, gg)
r = float(np.corrcoef(implied, gnss)[0, 1])
print(f"recorder IMU clock offset {offset:+.3f} s +- {offset_std:.3f} s (bus time = IMU time + offset)")
print(f"GNSS grade over the rows {100 * np.tan(gnss.min()):.1f} % .. {100 * np.tan(gnss.max()):.1f} %; "
      f"correlation of the traced grade with it: {r:.3f} ({len(t)} rows)")
if r < 0.85:
    fail(f"correlation {r:.3f} < 0.85")
print("PASS")
