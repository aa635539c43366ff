#!/usr/bin/env python3
"""Turns bench_fold's CSV (--benchmark_repetitions, aggregates) into the Markdown table of
docs/BENCHMARKS.md: median rows/s, and each fold's ratio to batch dgeqrf of the same rows."""
import csv
import sys

median = {}
for row in csv.DictReader(line for line in sys.stdin if line.startswith(('name', '"BM_'))):
    name = row['name']
    if name.endswith('_median'):
        median[name[:-len('_median')]] = float(row['items_per_second'])

def rate(kind, n, packet):
    return median.get(f'BM_{kind}/{n}/{packet}')

print('| n | packet | fold extended | fold double | normal eq. (dsyrk) | batch dgeqrf | Eigen HouseholderQR | extended / dgeqrf | double / dgeqrf |')
print('|---|---|---|---|---|---|---|---|---|')
for n in (4, 10, 16, 32, 64):
    batch = rate('BatchDgeqrf', n, 0)
    eigen = rate('EigenHouseholder', n, 0)
    for packet in (1, 16, 256, 3000):
        ext, dbl, ne = (rate(k, n, packet) for k in ('FoldExtended', 'FoldDouble', 'NormalEquations'))
        print(f'| {n} | {packet} | {ext/1e6:.3f} M | {dbl/1e6:.3f} M | {ne/1e6:.3f} M | '
              f'{batch/1e6:.3f} M | {eigen/1e6:.3f} M | {ext/batch:.2f} | {dbl/batch:.2f} |')
