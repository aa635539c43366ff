#!/usr/bin/python3
"""Issue 38, item 4 through dynid-car --replay: the Yaris folder's PCAN-View traces are read as PCAN
traces (every record line a frame: "replay done: N frames (0 bad lines"; the folder has no profile,
and the test car's profile decodes a few of their ids, which is all this needs), and revlog.csv, a
table of ids and bytes without times, is refused with a message that says what it looks like and
that it has no time stamps.

usage: trc_replay.py DYNID_CAR PROFILE SHARED_DATA OUT_DIR
Exit 0 pass, 1 fail, 77 skip (the reference data folder is absent).
"""
import os
import subprocess
import sys

dynid_car, profile, shared, out = sys.argv[1:5]
folder = os.path.join(shared, "yaris-2009-eldominio")
if not os.path.isdir(folder):
    print(f"SKIP: reference data {folder} is absent (../shared/data beside the clone)")
    sys.exit(77)
os.makedirs(out, exist_ok=True)


def replay(name):
    chunks = os.path.join(out, name + ".chunks")
    if os.path.exists(chunks):
        os.remove(chunks)
    cmd = [dynid_car, "--profile", profile, "--run", "yaris", "--replay", os.path.join(folder, name), "--fast",
           "--chunks-out", chunks]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    return r.returncode, r.stdout + r.stderr, os.path.exists(chunks)


failed = False
for name in ("engineonaconoffstockecu.trc", "revstockecu.trc"):
    with open(os.path.join(folder, name), encoding="ascii") as f:
        frames = sum(1 for line in f if line.strip() and not line.lstrip().startswith(";"))
    status, output, _ = replay(name)
    expected = f"replay done: {frames} frames (0 bad lines"
    if expected not in output:
        print(f"FAIL: {name}: expected '{expected}' (every record line a frame), got exit {status}:\n{output}")
        failed = True
    else:
        print(f"{name}: read as a PCAN trace, {frames} frames, no bad line")

status, output, written = replay("revlog.csv")
expected = "it looks like a CSV table with the columns 'ID,Data Bytes' and no time stamps, so it cannot be replayed"
if status != 1 or expected not in output or written:
    print(f"FAIL: revlog.csv: expected exit 1, no chunk file and '{expected}'; got exit {status}, "
          f"chunks written: {written}:\n{output}")
    failed = True
else:
    print("revlog.csv refused: " + next(line for line in output.splitlines() if expected in line))
sys.exit(1 if failed else 0)
