#pragma once
// LoadFleet: N simulated vehicles streaming SyntheticBodyRun chunks over DDS into the
// dynid-server(s) of a domain, and what they answer: durable acknowledgements and estimates.
//
// Each vehicle is what dynid-car is on the wire: its own RunAnnouncement and Chunk writers in
// its partition "vehicle/<id>", one run, chunks 0..K-1. One participant carries all vehicles
// (one process); acks and estimates are read on "vehicle/*".
//
// Modes. Paced (chunk_period > 0): vehicle v sends chunk k at t0 + (k + v/N) * chunk_period,
// whatever the acks say, as a car does. Fast (chunk_period == 0): each vehicle keeps at most
// `window` chunks unacknowledged and sends the next as soon as an ack makes room.
// A write refused by DDS flow control (the server's reader full for max_blocking_time) is
// retried, as the car's spool does, and counted.
//
// Resends, as dynid-car's Delivery does (client/car/include/dynid/car/delivery.hpp): when a
// vehicle has chunks in flight and no acknowledgement has made progress for `ack_timeout`
// (counted from the first send after an idle spell, the last progress or the last resend),
// every chunk in flight is sent again, oldest first, with its vehicle, run and sequence
// unchanged: the store keeps one copy (a resent chunk it holds is a duplicate, re-acked). This
// is what moves a vehicle along when servers sharing a store hand it over (a chunk sent to a
// server that no longer holds the vehicle is dropped unacknowledged). All writes, first sends
// and resends, are made by one thread.
//
// Measures (all times on this process's steady clock):
// - ack latency of chunk k: the FIRST dds_write of k -> the first ChunkAck of its run with
//   highest_contiguous >= k (the chunk is durable in the store); a resent chunk's latency
//   includes the wait for the ack timeout and the resend.
// - chunk-to-estimate latency of chunk k: dds_write of k -> arrival of the first Estimate of
//   the run whose row count >= R_k, where R_k is the model row count after folding chunks
//   0..k, computed before the run by an ingest::RunProcessor on the same chunks (the server's
//   own code). Only chunks that add rows (R_k > R_{k-1}) are measurable: the first chunks of a
//   run fill the zero-phase filter's delay and produce no row yet.
// - lost: chunks written but not acknowledged when the drain ends; missed: measurable chunks
//   that no estimate covered by then; rejections: reasons the server listed in its acks.
// - server CPU seconds and RSS from /proc/<pid> of every server pid given, summed, at the start
//   and end of the stream, and RSS every `rss_period` (the soak's flatness).
// - resends: chunks written again (and the rounds that did it).
// Throws InputError for bad options, DdsError when DDS fails, std::runtime_error when the
// server is not discovered or does not accept the announcements within `patience`.
#include <dds/dds.h>
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

namespace dynid::load {

struct LoadOptions {
  std::string cyclone_config;  ///< as for Participant (file URI + fragments)
  dds_domainid_t domain = 0;
  std::size_t vehicles = 1;
  std::uint64_t chunks_per_vehicle = 100;
  long chunk_rows = 100;
  double sample_rate_hz = 100.0;
  int odmf = 8;
  bool paced = true;                        ///< else as fast as the window allows
  std::size_t window = 16;                  ///< fast mode: unacknowledged chunks per vehicle
  std::chrono::seconds patience{60};        ///< discovery and announcement acceptance
  std::chrono::seconds drain{60};           ///< after the last write: wait for acks and estimates
  std::chrono::milliseconds ack_timeout{5000};  ///< resend after this long without progress
  int servers = 1;                          ///< chunk readers (servers) to discover before starting
  std::vector<pid_t> server_pids;           ///< empty: no /proc readings; several: summed
  std::chrono::milliseconds rss_period{0};  ///< 0: RSS only at start and end
  std::string prefix = "load";              ///< vehicle ids "<prefix>-<k>"
  std::string run = "run-1";
};

struct LoadResult {
  std::size_t vehicles = 0;
  int servers = 0;
  std::uint64_t chunks_written = 0, chunks_acked = 0, write_retries = 0;
  std::uint64_t resent_chunks = 0, resend_rounds = 0;
  long long ack_timeout_ms = 0;
  std::uint64_t lost = 0, missed = 0, rejections = 0, unmeasurable = 0;
  std::uint64_t vehicles_fully_acked = 0, vehicles_with_estimate = 0, final_rows_wrong = 0;
  std::uint64_t sample_rows_acked = 0, sample_rows_folded = 0, model_rows_folded = 0;
  double stream_seconds = 0.0;  ///< first write -> last chunk acknowledged
  double fold_seconds = 0.0;    ///< first write -> last measurable chunk seen in an estimate
  double ack_p50_ms = 0.0, ack_p99_ms = 0.0;
  double estimate_p50_ms = 0.0, estimate_p99_ms = 0.0, estimate_max_ms = 0.0;
  std::uint64_t latency_samples = 0;
  std::size_t chunk_bytes = 0;  ///< payload of one chunk sample (doubles + flags)
  double server_cpu_seconds = 0.0;
  double server_rss_start_mb = 0.0, server_rss_end_mb = 0.0, server_peak_rss_mb = 0.0;
  double rss_slope_kb_per_min = 0.0;  ///< over the samples after the first fifth
  std::uint64_t rss_samples = 0;
  std::vector<double> rss_series_mb;  ///< every sample, in order (the soak's curve)
  double load_cpu_seconds = 0.0;  ///< this process (it shares the machine with the server)

  std::string to_json() const;
};

LoadResult run_load(const LoadOptions& options);

}  // namespace dynid::load
