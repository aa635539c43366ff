#!/usr/bin/env python3
"""Medians of dynid-load's JSON lines (stdin) as the tables of docs/BENCHMARKS.md ("Load").

    load_table.py table DDSPERF_SAMPLES_PER_S PAYLOAD_BYTES < results.jsonl
    load_table.py stores < results.jsonl     (run-load.sh stores: SQLite and PostgreSQL side by side)
    load_table.py soak < results.jsonl
    load_table.py dashboards < results.jsonl  (run-load.sh dashboards: without and with dashboards)
"""
import json
import statistics
import sys


def med(values):
    values = [v for v in values if v == v]  # NaN out
    return statistics.median(values) if values else float("nan")


def table(rows, dds_rate, dds_bytes):
    print(f"ddsperf (pub/sub, reliable keep-all, {dds_bytes} B payload): {dds_rate:,.0f} samples/s")
    print()
    print("| mode | N | runs (ok) | chunks/s | rows/s ingested | rows/s folded | x ddsperf | "
          "ack p50 / p99 ms | chunk->estimate p50 / p99 ms | lost | server CPU % (per vehicle) | "
          "CPU µs per row, server / generator | RSS MB end (per vehicle, KB) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    keys = sorted({(r["mode"], r["vehicles"]) for r in rows}, key=lambda k: (k[0], k[1]))
    for mode, n in keys:
        rs = [r for r in rows if r["mode"] == mode and r["vehicles"] == n]
        ok = sum(1 for r in rs if r["status"] == 0)
        chunks_s = med([r["chunks_acked"] / r["stream_seconds"] for r in rs if r["stream_seconds"] > 0])
        ingest = med([r["sample_rows_acked"] / r["stream_seconds"] for r in rs if r["stream_seconds"] > 0])
        folded = med([r["sample_rows_folded"] / r["fold_seconds"] for r in rs if r["fold_seconds"] > 0])
        cpu = med([100 * r["server_cpu_seconds"] / r["stream_seconds"] for r in rs if r["stream_seconds"] > 0])
        # CPU per sample row: what contention on a shared machine changes least (A/B runs).
        per_row = [r for r in rs if r["sample_rows_acked"] > 0]
        us_server = med([1e6 * r["server_cpu_seconds"] / r["sample_rows_acked"] for r in per_row])
        us_load = med([1e6 * r["load_cpu_seconds"] / r["sample_rows_acked"] for r in per_row])
        rss = med([r["server_rss_end_mb"] for r in rs])
        rss_per = med([1024 * (r["server_rss_end_mb"] - r["server_rss_start_mb"]) / n for r in rs])
        lost = max(r["lost"] + r["missed"] for r in rs)
        print(f"| {mode} | {n} | {len(rs)} ({ok}) | {chunks_s:,.0f} | {ingest:,.0f} | {folded:,.0f} | "
              f"{chunks_s / dds_rate:.3f} | {med([r['ack_p50_ms'] for r in rs]):.1f} / "
              f"{med([r['ack_p99_ms'] for r in rs]):.1f} | {med([r['estimate_p50_ms'] for r in rs]):.1f} / "
              f"{med([r['estimate_p99_ms'] for r in rs]):.1f} | {lost} | {cpu:.0f} ({cpu / n:.2f}) | "
              f"{us_server:.2f} / {us_load:.2f} | {rss:.1f} ({rss_per:.0f}) |")


def stores(rows):
    """One row per (mode, N, store, servers), in the order the configurations first ran."""
    print("ack latency: from the first send of a chunk to the first acknowledgement covering it "
          "(resends included); rows/s: sample rows acknowledged / (first write -> last ack); "
          "resent: chunks sent again after the ack timeout (median of the runs, max); stored once: "
          "runs whose store holds each chunk exactly once with a contiguous ledger, all runs; "
          "server CPU and RSS summed over the servers; CPU µs per row: the servers' over the stream, "
          "PostgreSQL's (its server processes) from the servers' start to their stop, per sample row acknowledged")
    print()
    print("| mode | N | store | servers | runs (ok) | rows/s ingested | ack p50 / p99 ms | "
          "chunk->estimate p50 / p99 ms | resent (max) | lost | stored once | server CPU % | "
          "CPU µs per row, servers / PostgreSQL | server RSS MB end |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    keys = []
    for r in rows:
        key = (r["mode"], r["vehicles"], r.get("store", "sqlite"), r.get("servers", 1))
        if key not in keys:
            keys.append(key)
    keys.sort(key=lambda k: (k[0], k[1]))  # stable: the stores keep their order
    for mode, n, store, servers in keys:
        rs = [r for r in rows if (r["mode"], r["vehicles"], r.get("store", "sqlite"), r.get("servers", 1))
              == (mode, n, store, servers)]
        ok = sum(1 for r in rs if r["status"] == 0)
        ingest = med([r["sample_rows_acked"] / r["stream_seconds"] for r in rs if r["stream_seconds"] > 0])
        cpu = med([100 * r["server_cpu_seconds"] / r["stream_seconds"] for r in rs if r["stream_seconds"] > 0])
        resent = [r.get("resent_chunks", 0) for r in rs]
        lost = max(r["lost"] + r["missed"] for r in rs)
        once = sum(r.get("store_runs_complete", 0) for r in rs)
        runs = sum(r["vehicles"] for r in rs)
        per_row = [r for r in rs if r["sample_rows_acked"] > 0]
        us_server = med([1e6 * r["server_cpu_seconds"] / r["sample_rows_acked"] for r in per_row])
        us_db = med([1e6 * r.get("db_cpu_seconds", 0) / r["sample_rows_acked"] for r in per_row])
        db = f"{us_db:.2f}" if store == "postgresql" else "-"
        print(f"| {mode} | {n} | {store} | {servers} | {len(rs)} ({ok}) | {ingest:,.0f} | "
              f"{med([r['ack_p50_ms'] for r in rs]):.1f} / {med([r['ack_p99_ms'] for r in rs]):.1f} | "
              f"{med([r['estimate_p50_ms'] for r in rs]):.1f} / {med([r['estimate_p99_ms'] for r in rs]):.1f} | "
              f"{med(resent):.0f} ({max(resent)}) | {lost} | {once} / {runs} | {cpu:.0f} | "
              f"{us_server:.2f} / {db} | "
              f"{med([r['server_rss_end_mb'] for r in rs]):.1f} |")


def soak(rows):
    for r in rows:
        print(f"soak: {r['vehicles']} vehicles, {r['chunks_acked']}/{r['chunks_written']} chunks acked, "
              f"lost {r['lost']}, missed {r['missed']}, RSS {r['server_rss_start_mb']:.1f} -> "
              f"{r['server_rss_end_mb']:.1f} MB (peak {r['server_peak_rss_mb']:.1f}), slope after the "
              f"first fifth {r['rss_slope_kb_per_min']:.1f} KB/min over {r['rss_samples']} samples, "
              f"chunk->estimate p50 {r['estimate_p50_ms']:.1f} ms p99 {r['estimate_p99_ms']:.1f} ms")
        series = r.get("rss_series_mb", [])
        step = max(1, len(series) // 10)
        print("RSS (MB) every", step, "samples:", " ".join(f"{v:.1f}" for v in series[::step]))


def dashboards(rows):
    """Per mode and N, the runs without dashboards beside those with (labels fast-K, paced-K),
    and the ratio with / without of the ingest rate and of the server's CPU per row."""
    print("| mode | N | dashboards | runs (ok) | rows/s ingested | chunk->estimate p50 / p99 ms | lost | "
          "server CPU µs per row | rows/s, with / without | CPU per row, with / without |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for mode in ("fast", "paced"):
        for n in sorted({r["vehicles"] for r in rows}):
            base = None
            for k in sorted({int(r["mode"].split("-")[1]) for r in rows if r["mode"].startswith(mode + "-")}):
                rs = [r for r in rows if r["mode"] == f"{mode}-{k}" and r["vehicles"] == n]
                if not rs:
                    continue
                ok = sum(1 for r in rs if r["status"] == 0)
                ingest = med([r["sample_rows_acked"] / r["stream_seconds"] for r in rs if r["stream_seconds"] > 0])
                us = med([1e6 * r["server_cpu_seconds"] / r["sample_rows_acked"] for r in rs if r["sample_rows_acked"] > 0])
                lost = max(r["lost"] + r["missed"] for r in rs)
                ratios = "-" if base is None else f"{ingest / base[0]:.3f}"
                cpu_ratio = "-" if base is None else f"{us / base[1]:.3f}"
                if base is None:
                    base = (ingest, us)
                print(f"| {mode} | {n} | {k} | {len(rs)} ({ok}) | {ingest:,.0f} | "
                      f"{med([r['estimate_p50_ms'] for r in rs]):.1f} / {med([r['estimate_p99_ms'] for r in rs]):.1f} | "
                      f"{lost} | {us:.2f} | {ratios} | {cpu_ratio} |")


def main():
    rows = [json.loads(line) for line in sys.stdin if line.strip()]
    if sys.argv[1] == "table":
        table(rows, float(sys.argv[2]), int(sys.argv[3]))
    elif sys.argv[1] == "stores":
        stores(rows)
    elif sys.argv[1] == "dashboards":
        dashboards(rows)
    else:
        soak(rows)


if __name__ == "__main__":
    main()
