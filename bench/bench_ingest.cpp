// The server's CPU work per chunk, without DDS or the store: what bounds its ingest rate.
//   - Process: the load benchmark's body-model run (bench/load/synthetic_body_run.hpp: 10
//     parameters, 30 channels, 100 Hz, odmf 8) pushed through ingest::RunProcessor in chunks of
//     100 rows (validation, zero-phase filter, rows, fold), as the server does for each chunk;
//   - ProcessValidated: the same with chunks validated beforehand (ValidatedChunk), as the
//     server validates each chunk on arrival;
//   - Validate / Encode / Decode / Checksum: the per-chunk steps the server adds around it
//     (validate_chunk, the store's encoding and its inverse, the CRC-32 of a chunk).
// items/s = sample rows/s. Chunks are made before timing (the vehicles' work, not the server's).
#include <benchmark/benchmark.h>

#include <vector>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_processor.hpp"
#include "dynid/ingest/validated_chunk.hpp"
#include "dynid/signal/butterworth.hpp"
#include "dynid/signal/streaming_zero_phase_filter.hpp"
#include "load/synthetic_body_run.hpp"

namespace {

constexpr Eigen::Index kChunkRows = 100;
constexpr int kOdmf = 8;
constexpr std::uint64_t kChunks = 200;  // 20,000 rows per iteration (past the filter's start)

struct Run {
  dynid::ingest::RunAnnouncement announcement;
  std::vector<dynid::ingest::Chunk> chunks;
};

const Run& body_run() {
  static const Run run = [] {
    const dynid::load::SyntheticBodyRun gen(100.0, kChunkRows, kOdmf);
    Run r{gen.announcement("bench-car", "run-1"), {}};
    for (std::uint64_t k = 0; k < kChunks; ++k) r.chunks.push_back(gen.chunk("bench-car", "run-1", k));
    return r;
  }();
  return run;
}

void set_rows(benchmark::State& state, std::size_t chunks) {
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(chunks) * kChunkRows);
}

// One whole run per iteration (processor built outside the timing).
void BM_Process(benchmark::State& state) {
  const Run& run = body_run();
  for (auto _ : state) {
    state.PauseTiming();
    dynid::ingest::RunProcessor p(run.announcement);
    state.ResumeTiming();
    for (const dynid::ingest::Chunk& c : run.chunks) p.push(c);
    benchmark::DoNotOptimize(p.counters());
  }
  set_rows(state, run.chunks.size());
}
BENCHMARK(BM_Process)->Unit(benchmark::kMillisecond);

// Process of chunks the caller validated already (ValidatedChunk, made before the timing as
// the server makes them on arrival): push() without its second validation.
void BM_ProcessValidated(benchmark::State& state) {
  const Run& run = body_run();
  std::vector<dynid::ingest::ValidatedChunk> chunks;
  for (const dynid::ingest::Chunk& c : run.chunks)
    chunks.push_back(dynid::ingest::ValidatedChunk::validate(c, run.announcement));
  for (auto _ : state) {
    state.PauseTiming();
    dynid::ingest::RunProcessor p(run.announcement);
    state.ResumeTiming();
    for (const dynid::ingest::ValidatedChunk& c : chunks) p.push(c);
    benchmark::DoNotOptimize(p.counters());
  }
  set_rows(state, chunks.size());
}
BENCHMARK(BM_ProcessValidated)->Unit(benchmark::kMillisecond);

// The low-pass alone, as RunProcessor sets it up (the announcement's Butterworth and tolerance),
// on the same chunks: its share of Process.
void BM_Filter(benchmark::State& state) {
  const Run& run = body_run();
  const dynid::ingest::Preprocessing& pre = run.announcement.preprocessing;
  const double rate = run.announcement.sample_rate_hz;
  const dynid::signal::Sos sos =
      dynid::signal::butterworth_lowpass(pre.butterworth_order, pre.cutoff(rate), rate);
  for (auto _ : state) {
    dynid::signal::StreamingZeroPhaseFilter f(sos, run.chunks.front().samples.cols(),
                                              pre.filter_tolerance);
    for (const dynid::ingest::Chunk& c : run.chunks) benchmark::DoNotOptimize(f.push(c.samples));
  }
  set_rows(state, run.chunks.size());
}
BENCHMARK(BM_Filter)->Unit(benchmark::kMillisecond);

void BM_Validate(benchmark::State& state) {
  const Run& run = body_run();
  for (auto _ : state)
    for (const dynid::ingest::Chunk& c : run.chunks) dynid::ingest::validate_chunk(c, run.announcement);
  set_rows(state, run.chunks.size());
}
BENCHMARK(BM_Validate)->Unit(benchmark::kMillisecond);

void BM_Checksum(benchmark::State& state) {
  const Run& run = body_run();
  for (auto _ : state)
    for (const dynid::ingest::Chunk& c : run.chunks) benchmark::DoNotOptimize(c.compute_checksum());
  set_rows(state, run.chunks.size());
}
BENCHMARK(BM_Checksum)->Unit(benchmark::kMillisecond);

void BM_Encode(benchmark::State& state) {
  const Run& run = body_run();
  for (auto _ : state)
    for (const dynid::ingest::Chunk& c : run.chunks)
      benchmark::DoNotOptimize(dynid::ingest::encode_chunk(c));
  set_rows(state, run.chunks.size());
}
BENCHMARK(BM_Encode)->Unit(benchmark::kMillisecond);

void BM_Decode(benchmark::State& state) {
  const Run& run = body_run();
  std::vector<std::string> bytes;
  for (const dynid::ingest::Chunk& c : run.chunks) bytes.push_back(dynid::ingest::encode_chunk(c));
  for (auto _ : state)
    for (const std::string& b : bytes) benchmark::DoNotOptimize(dynid::ingest::decode_chunk(b));
  set_rows(state, run.chunks.size());
}
BENCHMARK(BM_Decode)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
