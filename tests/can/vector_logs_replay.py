#!/usr/bin/python3
"""Issue 17, item 2: ASC and BLF files written by python-can (Debian's python3-can, the reference,
never our own code) from the RAV4 candump log replay through dynid-car to the same chunks, bit for
bit, as the candump log itself.

usage: vector_logs_replay.py DYNID_CAR PROFILE SHARED_DATA OUT_DIR
Exit 0 pass, 1 fail, 77 skip (the reference data folder is absent). python-can missing is a failure:
deploy/setup.sh installs python3-can from deploy/packages.txt.
"""
import hashlib
import os
import subprocess
import sys

dynid_car, profile, shared, out = sys.argv[1:5]
log = os.path.join(shared, "rav4-comma2k19", "rav4_2018-08-02_seg40.candump.log")
if not os.path.isfile(log):
    print(f"SKIP: reference data {log} is absent (../shared/data beside the clone)")
    sys.exit(77)
try:
    import can  # noqa: E402
except ImportError as e:
    print(f"FAIL: python-can is not importable ({e}): deploy/setup.sh installs python3-can")
    sys.exit(1)

os.environ["TZ"] = "UTC"  # python-can writes the ASC/BLF start in local time; dynid reads it as UTC
os.makedirs(out, exist_ok=True)
messages = list(can.LogReader(log))
paths = {"candump": log}
for ext in ("asc", "blf"):
    path = os.path.join(out, f"rav4.{ext}")
    with can.Logger(path) as writer:
        for m in messages:
            writer.on_message_received(m)
    paths[ext] = path
    print(f"python-can {can.__version__} wrote {len(messages)} frames to {path} ({os.path.getsize(path)} bytes)")

digests = {}
for name, path in paths.items():
    chunks = os.path.join(out, f"rav4-{name}.chunks")
    cmd = [dynid_car, "--profile", profile, "--run", "seg40", "--replay", path, "--fast", "--chunks-out", chunks]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        print(f"FAIL: {' '.join(cmd)} exited {r.returncode}\n{r.stderr}")
        sys.exit(1)
    with open(chunks, "rb") as f:
        data = f.read()
    digests[name] = hashlib.sha256(data).hexdigest()
    print(f"{name:8s} {len(data):8d} bytes of chunks, sha256 {digests[name]}")

if len(set(digests.values())) != 1 or os.path.getsize(os.path.join(out, "rav4-candump.chunks")) == 0:
    print("FAIL: the chunks differ")
    sys.exit(1)
print("PASS: candump, ASC and BLF replay to the same chunks, bit for bit")
