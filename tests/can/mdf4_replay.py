#!/usr/bin/python3
"""ASAM MDF4 through dynid-car: the two splits of CANedge recording 00000164 (shared data
mdf4-canedge/raw), given together to --replay, cut the same chunks, bit for bit, as the same frames
written as one candump log by an independent reader (below: a few lines of Python over the MDF 4.1
block layout, never the product's code). The splits given in the other order cut the same chunks
(they are merged by time). The unfinalized log 2F6913DB (the same module) replays to the chunks of
its candump too, and the replay says what it recovered. The profile streams the GNSS/IMU module on
bus channel 2 with its DBC.

usage: mdf4_replay.py DYNID_CAR SHARED_DATA OUT_DIR
Exit 0 pass, 1 fail, 77 skip (the reference data folder is absent).
"""
import hashlib
import os
import struct
import subprocess
import sys

dynid_car, shared, out = sys.argv[1:4]
raw = os.path.join(shared, "mdf4-canedge", "raw")
splits = [os.path.join(raw, n) for n in ("3BA199E2_00000164_00000001-60FE3F04.MF4",
                                         "3BA199E2_00000164_00000002-60FE415D.MF4")]
unfinalized = os.path.join(raw, "2F6913DB_00000004_00000001.MF4")
dbc = os.path.join(shared, "mdf4-canedge", "dbc", "canmod-gps.dbc")
if not all(os.path.isfile(p) for p in splits + [unfinalized, dbc]):
    print(f"SKIP: reference data {raw} is absent (../shared/data beside the clone)")
    sys.exit(77)


def read_frames(path):
    """(ns since 1970, bus channel, id, extended, payload) of the CAN_DataFrame records."""
    d = open(path, "rb").read()

    def block(at):
        length, count = struct.unpack_from("<QQ", d, at + 8)
        links = struct.unpack_from("<%dQ" % count, d, at + 24)
        return d[at:at + 4], links, at + 24 + 8 * count, at + length

    def text(at):
        _, _, data, end = block(at)
        return d[data:end].split(b"\0")[0].decode()

    _, hd_links, hd_data, _ = block(64)
    start_ns = struct.unpack_from("<Q", d, hd_data)[0]
    frames = []
    dg = hd_links[0]
    while dg:
        _, dg_links, dg_data, _ = block(dg)
        id_size = d[dg_data]
        groups = {}
        cg = dg_links[1]
        while cg:
            _, cg_links, cg_data, _ = block(cg)
            rec_id, _, flags, _, _, data_bytes, inval = struct.unpack_from("<QQHH4sII", d, cg_data)
            channels = {}
            stack = [cg_links[1]]
            while stack:  # the channel tree, composition children included
                cn = stack.pop()
                if not cn:
                    continue
                _, cn_links, cn_data, _ = block(cn)
                ctype, _, _, bit, byte, bits = struct.unpack_from("<BBBBII", d, cn_data)
                factor = 1.0
                if cn_links[4]:
                    _, _, cc_data, _ = block(cn_links[4])
                    if d[cc_data] == 1:  # linear: offset, factor
                        factor = struct.unpack_from("<d", d, cc_data + 32)[0]
                channels[text(cn_links[2])] = (ctype, bit, byte, bits, cn_links[5], factor)
                stack += [cn_links[0], cn_links[1]]
            groups[rec_id] = (cg, text(cg_links[2]) if cg_links[2] else "", flags, data_bytes + inval, channels)
            cg = cg_links[0]
        # the records: a ##DT (an unfinalized file's runs to the end of the file)
        kind, _, data, end = block(dg_links[2])
        assert kind == b"##DT", kind
        if d[:8] == b"UnFinMF ":
            end = len(d)
        records = {k: [] for k in groups}
        vlsd = {g[0]: b"" for g in groups.values() if g[2] & 1}
        pos = data
        while pos < end:
            rid = int.from_bytes(d[pos:pos + id_size], "little") if id_size else next(iter(groups))
            pos += id_size
            cg_at, name, flags, size, _ = groups[rid]
            if flags & 1:
                n = struct.unpack_from("<I", d, pos)[0]
                vlsd[cg_at] += d[pos:pos + 4 + n]
                pos += 4 + n
            else:
                records[rid].append(d[pos:pos + size])
                pos += size
        for rid, (cg_at, name, _, _, ch) in groups.items():
            if name != "CAN_DataFrame":
                continue

            def field(rec, key):
                _, bit, byte, bits, _, _ = ch["CAN_DataFrame." + key]
                return (int.from_bytes(rec[byte:byte + 8], "little") >> bit) & ((1 << bits) - 1)
            _, _, t_byte, _, _, t_factor = ch["Timestamp"]
            _, _, b_byte, _, b_link, _ = ch["CAN_DataFrame.DataBytes"]
            if b_link in vlsd:
                values = vlsd[b_link]
            else:  # an ##SD block
                _, _, sd_data, sd_end = block(b_link)
                values = d[sd_data:sd_end]
            for rec in records[rid]:
                t = struct.unpack_from("<d", rec, t_byte)[0] * t_factor
                offset = struct.unpack_from("<Q", rec, b_byte)[0]
                n = struct.unpack_from("<I", values, offset)[0]
                length = field(rec, "DataLength")
                payload = values[offset + 4:offset + 4 + n][:length]
                frames.append((start_ns + round(t * 1e9), field(rec, "BusChannel"), field(rec, "ID"),
                               field(rec, "IDE"), payload))
        dg = dg_links[0]
    return frames


def write_candump(path, frame_lists):
    with open(path, "w") as f:
        for frames in frame_lists:
            for ns, bus, fid, ext, payload in frames:
                ident = "%08X" % fid if ext else "%03X" % fid
                f.write("(%d.%06d) can%d %s#%s\n" % (ns // 10**9, ns % 10**9 // 1000, bus - 1, ident,
                                                      payload.hex().upper()))


os.makedirs(out, exist_ok=True)
log = os.path.join(out, "00000164.candump.log")
per_split = [read_frames(p) for p in splits]
write_candump(log, per_split)
unfinalized_log = os.path.join(out, "2F6913DB.candump.log")
write_candump(unfinalized_log, [read_frames(unfinalized)])
last1, first2 = per_split[0][-1][0], per_split[1][0][0]
print(f"independent reader: {len(per_split[0])} + {len(per_split[1])} frames; last of split 1 at "
      f"{last1 / 1e9:.6f}, first of split 2 at {first2 / 1e9:.6f} (join gap {(first2 - last1) / 1e6:.3f} ms)")
if not last1 < first2:
    print("FAIL: split 2 does not start after split 1")
    sys.exit(1)

profile = os.path.join(out, "canedge-gnss.toml")
with open(profile, "w") as f:
    f.write(f"""[vehicle]
id = "canedge-gnss"
dbc = "{dbc}"
interfaces = ["can1"]
[grid]
rate_hz = 50.0
chunk_seconds = 1.0
[spool]
directory = "{os.path.join(out, 'spool')}"
max_bytes = 104857600
""")
    for name, signal in (("ax", "AccelerationX"), ("ay", "AccelerationY"), ("yaw_rate", "AngularRateZ")):
        f.write(f'[[channels]]\nname = "{name}"\nmessage = "gnss_imu"\nsignal = "{signal}"\n')



def replay(name, logs):
    """The sha256 of the chunks dynid-car cuts from `logs`, and its log lines."""
    chunks = os.path.join(out, f"{name}.chunks")
    cmd = [dynid_car, "--profile", profile, "--run", "r1", "--replay", *logs, "--fast", "--chunks-out", chunks]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        print(f"FAIL: {' '.join(cmd)} exited {r.returncode}\n{r.stderr}")
        sys.exit(1)
    data = open(chunks, "rb").read()
    if not data:
        print(f"FAIL: {name}: no chunks")
        sys.exit(1)
    digest = hashlib.sha256(data).hexdigest()
    done = [line for line in r.stderr.splitlines() if "replay done" in line]
    print(f"{name:24s} {len(data):8d} bytes of chunks, sha256 {digest[:16]}; {done[0] if done else ''}")
    return digest, r.stderr


failed = False
runs = {name: replay(name, logs) for name, logs in (("00000164-mdf4", splits), ("00000164-mdf4-reversed", splits[::-1]),
                                                   ("00000164-candump", [log]))}
if len({d for d, _ in runs.values()}) != 1:
    print("FAIL: the chunks of the splits and of their candump differ")
    failed = True
mdf4, err = replay("2F6913DB-mdf4", [unfinalized])
candump, _ = replay("2F6913DB-candump", [unfinalized_log])
notes = [line for line in err.splitlines() if "unfinalized" in line]
print("\n".join(notes))
if mdf4 != candump:
    print("FAIL: the chunks of the unfinalized log and of its candump differ")
    failed = True
if not notes:
    print("FAIL: the replay of the unfinalized log says nothing of what it recovered")
    failed = True
if failed:
    sys.exit(1)
print("PASS: the MDF4 splits (in either order) and the unfinalized log replay to the chunks of their frames as candump")
