#!/usr/bin/python3
"""Independent reference for tests/signal: Debian's scipy (python3-scipy).

Usage: scipy_reference.py ORDER CUTOFF_HZ SAMPLE_RATE_HZ [SIGNAL_FILE]
Prints butter(ORDER, CUTOFF_HZ, fs=SAMPLE_RATE_HZ, output='sos') as
    sos <sections>        then one line of 6 numbers per section,
and, when SIGNAL_FILE (rows = samples, columns = channels, whitespace separated) is given,
sosfiltfilt(sos, x, axis=0) with its defaults as
    y <rows> <columns>    then one line per sample,
or, when scipy rejects the signal,
    error <message>.
Exit status 3 when scipy cannot be imported (the C++ test then skips, saying so).
"""
import sys

try:
    import numpy as np
    from scipy import signal
except ImportError as exc:  # pragma: no cover - depends on the machine
    print(f"unavailable {exc}")
    sys.exit(3)


def main(argv):
    order, cutoff, fs = int(argv[1]), float(argv[2]), float(argv[3])
    sos = signal.butter(order, cutoff, fs=fs, output="sos")
    print(f"sos {sos.shape[0]}")
    for row in sos:
        print(" ".join(f"{v:.17g}" for v in row))
    if len(argv) > 4:
        x = np.loadtxt(argv[4], ndmin=2)
        try:
            y = signal.sosfiltfilt(sos, x, axis=0)
        except ValueError as exc:
            print(f"error {exc}")
            return
        print(f"y {y.shape[0]} {y.shape[1]}")
        for row in y:
            print(" ".join(f"{v:.17g}" for v in row))


if __name__ == "__main__":
    main(sys.argv)
