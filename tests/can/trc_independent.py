#!/usr/bin/python3
"""An independent parse of a PCAN trace of file version 1.1 (as PCAN-View writes it), written for
the test from the text alone, sharing nothing with the product's reader.

usage: trc_independent.py FILE
Prints "start <epoch seconds>" ($STARTTIME: days since 1899-12-30), then one line per data frame:
"<offset in whole microseconds> <id as written> <payload hex or ->". Exits 1 on a line it cannot read.
"""
import sys
from decimal import Decimal

with open(sys.argv[1], encoding="ascii") as f:
    lines = f.read().splitlines()
start = None
frames = []
for number, line in enumerate(lines, 1):
    fields = line.split()
    if not fields:
        continue
    if fields[0].startswith(";$STARTTIME="):
        start = (Decimal(fields[0].split("=", 1)[1]) - 25569) * 86400
    if fields[0].startswith(";"):
        continue
    count, offset, kind, ident, dlc, data = fields[0], fields[1], fields[2], fields[3], int(fields[4]), fields[5:]
    if not count.endswith(")") or kind not in ("Rx", "Tx") or len(data) != dlc:
        sys.exit(f"line {number}: not a 1.1 data frame: {line!r}")
    frames.append(f"{int(Decimal(offset) * 1000)} {ident} {''.join(data) or '-'}")
if start is None:
    sys.exit("no $STARTTIME")
print(f"start {start:.6f}")
print("\n".join(frames))
