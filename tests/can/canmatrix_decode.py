#!/usr/bin/python3
"""Independent reference decoder for the C++ DBC decoder tests, built on canmatrix.

Usage: canmatrix_decode.py <file.dbc> <frames.txt>
frames.txt holds one frame per line: "<message name> <payload hex>".
Prints, for every frame, one line per decoded signal: "<frame index> <signal> <value>", the
physical value as Python's repr of a float (17 significant digits, round-trips exactly).
Only signals active under the frame's multiplexer value are printed (canmatrix's decode()).
Each decoded frame also gets "<frame index> # decoded".
A message canmatrix does not know (it refused its BO_ line) prints "<frame index> ! unknown".
"""
import contextlib
import logging
import sys

import canmatrix.formats

logging.disable(logging.CRITICAL)  # canmatrix warns about every oddity of real files


def main():
    dbc_path, frames_path = sys.argv[1], sys.argv[2]
    # canmatrix prints the lines it refuses on stdout; keep stdout for the values.
    with contextlib.redirect_stdout(sys.stderr):
        db = canmatrix.formats.loadp_flat(dbc_path, dbcImportEncoding="utf-8")
    out = []
    with open(frames_path) as frames:
        for index, line in enumerate(frames):
            name, payload = line.split()
            frame = db.frame_by_name(name)
            if frame is None:
                out.append("%d ! unknown" % index)
                continue
            decoded = frame.decode(bytearray.fromhex(payload))
            out.append("%d # decoded" % index)  # also for messages without signals
            for signal_name, value in decoded.items():
                out.append("%d %s %r" % (index, signal_name, float(value.phys_value)))
    sys.stdout.write("\n".join(out) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
