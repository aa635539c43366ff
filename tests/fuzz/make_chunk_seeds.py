#!/usr/bin/env python3
# Writes the fuzz_chunk seeds into corpus/fuzz_chunk (docs/FUZZING.md):
#   python3 tests/fuzz/make_chunk_seeds.py tests/fuzz/corpus/fuzz_chunk CHUNKS.bin
# enc() lays out ingest::encode_chunk's version-1 encoding (chunk.hpp); the corpus replay's
# "re-encodes to exactly its bytes" check proves the seeds equal the encoder's output. CHUNKS.bin
# is a `dynid-car --chunks-out` file (u64 length + encode_chunk bytes per chunk); its first chunk
# is kept as a real one.
import struct, zlib, math, sys
out = sys.argv[1]
def enc(vehicle, run, seq, first, rows, valid):
    b = b"DYNIDCHK" + struct.pack("<H", 1)
    for s in (vehicle, run):
        b += struct.pack("<I", len(s)) + s.encode()
    b += struct.pack("<QQQQ", seq, first, len(rows), len(rows[0]) if rows else 0)
    for r in rows:
        b += struct.pack("<%dd" % len(r), *r)
    b += struct.pack("<Q", len(valid)) + bytes(valid)
    return b + struct.pack("<I", zlib.crc32(b) & 0xffffffff)
def row(k):
    s = k / 100.0
    vx = 18 + 6 * math.sin(0.21 * s) + 2.5 * math.sin(0.67 * s + 1)
    dvx = 6 * 0.21 * math.cos(0.21 * s) + 2.5 * 0.67 * math.cos(0.67 * s + 1)
    w = 3.9 * vx / 0.31
    return [vx, dvx + 0.12, 0.31 * (1450 * dvx + 0.432 * vx * abs(vx) + 160), w,
            0.9 * 3.9 * dvx / 0.31 + 12 + 0.05 * w + 4e-4 * w * w, 3.0]
def write(name, data):
    open(out + "/" + name, "wb").write(data)
write("run6_seq0_160rows.chunk", enc("proto-17", "run-0042", 0, 0, [row(k) for k in range(160)], [1] * 160))
v = [1] * 120
for k in range(50, 60): v[k] = 0
rows = [row(k) if v[k] else [0.0] * 6 for k in range(120)]
write("run6_seq0_gap.chunk", enc("proto-17", "run-0042", 0, 0, rows, v))
write("run6_seq0_3rows.chunk", enc("v", "r", 0, 7, [row(k) for k in range(3)], [1, 0, 1]))
write("run6_seq1.chunk", enc("proto-17", "run-0042", 1, 160, [row(k) for k in range(160, 170)], [1] * 10))
write("empty_matrix.chunk", enc("v", "r", 0, 0, [], []))
# the first chunk dynid-car --chunks-out wrote (u64 length + encode_chunk bytes)
data = open(sys.argv[2], "rb").read()
n = struct.unpack_from("<Q", data, 0)[0]
write("dynid_car_testcar_seq0.chunk", data[8:8 + n])
