#!/usr/bin/python3
"""Bad auxiliary data through dynid-car (issue 17, item 3), with the RAV4 log and the recorder's
IMU of ../shared/data: a clock that drifts, rows out of order, a column the profile names that the
file lacks, a --source the profile does not declare. Each must exit 1 with a message naming the
problem and write no chunk file; the good file must go through and print its estimated offset.

usage: auxiliary_cli.py DYNID_CAR PROFILE SHARED_DATA OUT_DIR      (exit 77: data absent)
"""
import os
import subprocess
import sys

car, profile, shared, out = sys.argv[1:5]
data = os.path.join(shared, "rav4-comma2k19")
log = os.path.join(data, "rav4_2018-08-02_seg40.candump.log")
imu = os.path.join(data, "phone_imu_accel.csv")
if not os.path.isfile(log):
    print(f"SKIP: reference data {data} is absent (../shared/data beside the clone)")
    sys.exit(77)
os.makedirs(out, exist_ok=True)
rows = open(imu).read().splitlines()
header, body = rows[0], rows[1:]
t0 = float(body[0].split(",")[0])


def variant(name, lines):
    path = os.path.join(out, name)
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    return path


def stretched(line, factor):
    cells = line.split(",")
    cells[0] = repr(t0 + (float(cells[0]) - t0) * factor)
    return ",".join(cells)


cases = [
    # (name, --source values, expected exit, words expected on stderr)
    ("good", ["recorder_imu=" + imu], 0, ["source 'recorder_imu'", "clock offset", "+-", "at the start"]),
    ("drifting clock", ["recorder_imu=" + variant("drift.csv", [header] + [stretched(l, 1.02) for l in body])], 1,
     ["the clock drifts", "at the start", "at the end (drift", "one offset cannot align it"]),
    ("unsorted", ["recorder_imu=" + variant("unsorted.csv", [header] + body[:100] + [body[50]] + body[100:])], 1,
     ["unsorted.csv:102: time", "the rows must be sorted by time"]),
    ("unknown column", ["recorder_imu=" + variant("nocol.csv", ["t,accel_x,ay,az"] + body)], 1,
     ["nocol.csv:1: auxiliary source 'recorder_imu': no column 'ax' in the header (columns: t, accel_x, ay, az)"]),
    ("undeclared source", ["gnss=" + imu], 1, ["declares no source 'gnss' (declared: recorder_imu, gnss_pose)"]),
]
failed = 0
for name, sources, status, words in cases:
    chunks = os.path.join(out, name.replace(" ", "_") + ".chunks")
    if os.path.exists(chunks):
        os.remove(chunks)
    cmd = [car, "--profile", profile, "--run", "aux", "--replay", log, "--fast", "--chunks-out", chunks]
    for s in sources:
        cmd += ["--source", s]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    first = next((l for l in r.stderr.splitlines() if "recorder_imu" in l or "error" in l), "")
    ok = r.returncode == status and all(w in r.stderr for w in words) and (status == 0) == os.path.exists(chunks)
    print(f"{'ok  ' if ok else 'FAIL'} {name}: exit {r.returncode}; {first}")
    if not ok:
        failed += 1
        print(r.stderr)
sys.exit(1 if failed else 0)
