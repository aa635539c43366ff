#!/usr/bin/env python3
# Writes the fuzz_mdf4 seeds into corpus/fuzz_mdf4 (docs/FUZZING.md), cut down from the CANedge
# MDF 4.11 logs of the shared data (MIT, corpus/LICENSE.canedge), each at most 64 KB:
#   python3 tests/fuzz/make_mdf4_seeds.py ../shared/data/mdf4-canedge/raw tests/fuzz/corpus/fuzz_mdf4
# - unfinalized-*.mf4: the first bytes of the three unfinalized ("UnFinMF ") logs; their last
#   ##DT runs to the end of the file, so a cut file is still a log (a partial record at the end);
# - finalized-sorted.mf4: the finalized split's metadata with its CAN_DataFrame group only, 300
#   records in the ##DT and the ##SD values they point to (cycle count and links rewritten);
# - zipped-*.mf4, list.mf4: that file with its ##DT replaced by a ##DZ (deflate, transposed
#   deflate) or by a ##DL of two blocks.
import os, struct, sys, zlib

raw, out = sys.argv[1], sys.argv[2]
os.makedirs(out, exist_ok=True)

def u64(b, at):
    return struct.unpack_from("<Q", b, at)[0]

def block(id_, links, data):
    return b"##" + id_ + b"\0" * 4 + struct.pack("<QQ", 24 + 8 * len(links) + len(data), len(links)) + \
        struct.pack("<%dQ" % len(links), *links) + data

def append(b, blk):
    b += b"\0" * (-len(b) % 8)
    at = len(b)
    b += blk
    return at

def dz(data, zip_type, columns):
    src = data
    if zip_type == 1:
        rows = len(data) // columns
        t = bytearray(data)
        for r in range(rows):
            for c in range(columns):
                t[c * rows + r] = data[r * columns + c]
        src = bytes(t)
    z = zlib.compress(src)
    return block(b"DZ", [], b"DT" + bytes([zip_type, 0]) + struct.pack("<IQQ", columns, len(data), len(z)) + z)

for name, keep in (("17BD1DB7_00000006_00000170.MF4", 12000), ("2F6913DB_00000004_00000001.MF4", 20000),
                   ("94C49784_00000005_00000002.MF4", 20000)):
    b = open(os.path.join(raw, name), "rb").read()
    open(os.path.join(out, "unfinalized-" + name[:8] + ".mf4"), "wb").write(b[:keep])

b = open(os.path.join(raw, "3BA199E2_00000164_00000001-60FE3F04.MF4"), "rb").read()
hd_dg = u64(b, 64 + 24)
dg_next_at, dg_data_at = hd_dg + 24, hd_dg + 40
dt = u64(b, dg_data_at)
cg = u64(b, hd_dg + 32)
cg_links = u64(b, cg + 16)
cycles_at = cg + 24 + 8 * cg_links + 8
record = struct.unpack_from("<I", b, cg + 24 + 8 * cg_links + 24)[0]
n = 300
records = b[dt + 24: dt + 24 + n * record]
offsets = [u64(records, k * record + 14) for k in range(n)]  # CAN_DataFrame.DataBytes
old_sd = None
for at in range(0, dt, 8):  # the DataBytes channel's data link: the one link to an ##SD
    v = u64(b, at)
    if 0 < v < len(b) - 4 and b[v:v + 4] == b"##SD":
        old_sd, sd_link_at = v, at
end = max(o + 4 + struct.unpack_from("<I", b, old_sd + 24 + o)[0] for o in offsets)
sd_data = b[old_sd + 24: old_sd + 24 + end]
meta = bytearray(b[:dt])
struct.pack_into("<Q", meta, dg_next_at, 0)  # the CAN_DataFrame data group alone
struct.pack_into("<Q", meta, cycles_at, n)
base = bytearray(meta)
append(base, block(b"DT", [], records))
struct.pack_into("<Q", base, sd_link_at, append(base, block(b"SD", [], sd_data)))
open(os.path.join(out, "finalized-sorted.mf4"), "wb").write(base)
for tag, blk in (("zipped-deflate", dz(records, 0, 0)), ("zipped-transposed", dz(records, 1, record))):
    v = bytearray(base)
    struct.pack_into("<Q", v, dg_data_at, append(v, blk))
    open(os.path.join(out, tag + ".mf4"), "wb").write(v)
v = bytearray(base)
half = len(records) // 2 + 5
first = append(v, block(b"DT", [], records[:half]))
second = append(v, dz(records[half:], 0, 0))
struct.pack_into("<Q", v, dg_data_at, append(v, block(b"DL", [0, first, second], struct.pack("<B3xIQQ", 0, 2, 0, half))))
open(os.path.join(out, "list.mf4"), "wb").write(v)
