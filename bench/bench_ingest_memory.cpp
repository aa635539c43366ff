// Memory per vehicle-run of the server's RunProcessor (issue 7 goal 4: < 1 MB per run), on the
// load benchmark's body run (bench/load/synthetic_body_run.hpp: 30 channels, 100 Hz, 100-row
// chunks, odmf 8). Holds `runs` processors, pushes the same chunks into each, and reports per
// run after 1, 2, 4, ... `chunks` chunks:
//   - VmRSS growth / runs (what the load benchmark sees, allocator slack included);
//   - live heap growth / runs (glibc mallinfo2: bytes in allocated blocks, exact);
// then the itemised buffers of one processor (RunProcessor::held_buffers: allocated and held
// bytes per buffer), so the sum can be set against the heap figure.
// Usage: bench_ingest_memory [runs=200] [chunks=64]
//
// `bench_ingest_memory digest` prints instead, for several chunkings of a run with two gaps
// (one of them too short to filter), a hash of checkpoint() after every push and the final
// counters and estimates in hex floats: run it before and after a change of the buffers to
// show that every output stayed bit-identical (diff the two outputs).
#include <malloc.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "dynid/ingest/run_processor.hpp"
#include "load/synthetic_body_run.hpp"

namespace {

long vm_rss_kb() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

std::size_t heap_bytes() {
  const struct mallinfo2 m = mallinfo2();
  return m.uordblks + m.hblkhd;  // small blocks, and the large ones glibc maps on their own
}

struct Mark {
  long rss_kb;
  std::size_t heap;
};

Mark mark() {
  return {vm_rss_kb(), heap_bytes()};
}

void report(const char* what, const Mark& base, std::size_t runs) {
  const Mark now = mark();
  std::printf("%-22s rss %8.1f KB/run   heap %8.1f KB/run\n", what,
              static_cast<double>(now.rss_kb - base.rss_kb) / static_cast<double>(runs),
              static_cast<double>(now.heap - base.heap) / 1024.0 / static_cast<double>(runs));
}

// Rows [from, to) of the run are invalid (a gap).
void mark_gap(dynid::ingest::Chunk& c, std::uint64_t from, std::uint64_t to) {
  for (std::size_t r = 0; r < c.valid.size(); ++r) {
    const std::uint64_t index = c.first_sample_index + r;
    if (index >= from && index < to) c.valid[r] = 0;
  }
}

// One run of 7000 samples cut into chunks of `rows`: digest of every checkpoint, then results.
void digest(Eigen::Index rows) {
  const dynid::load::SyntheticBodyRun gen(100.0, rows, 8);
  dynid::ingest::RunProcessor p(gen.announcement("probe-car", "run-1"));
  std::size_t h = 0;
  for (std::uint64_t k = 0; k * static_cast<std::uint64_t>(rows) < 7000; ++k) {
    dynid::ingest::Chunk c = gen.chunk("probe-car", "run-1", k);
    mark_gap(c, 2000, 2050);  // a gap
    mark_gap(c, 2060, 2070);  // then a segment too short to filter
    c.seal();
    p.push(c);
    h = h * 31 + std::hash<std::string>{}(p.checkpoint());
  }
  p.finish();
  h = h * 31 + std::hash<std::string>{}(p.checkpoint());
  const dynid::ingest::RunCounters& n = p.counters();
  std::printf("chunk rows %ld: checkpoints %016zx counters %llu %llu %llu %llu %llu %llu\n",
              static_cast<long>(rows), h, static_cast<unsigned long long>(n.samples),
              static_cast<unsigned long long>(n.invalid_samples),
              static_cast<unsigned long long>(n.segments),
              static_cast<unsigned long long>(n.short_segments),
              static_cast<unsigned long long>(n.final_samples),
              static_cast<unsigned long long>(n.chunks));
  for (const dynid::ingest::ModelEstimate& e : p.estimates()) {
    if (!e.estimate) continue;
    const Eigen::VectorXd& v = e.estimate->estimate.value;
    for (Eigen::Index i = 0; i < v.size(); ++i) std::printf(" %a", v(i));
    std::printf(" sigma %a", e.estimate->estimate.sigma);
    std::printf("\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "digest") {
    for (const Eigen::Index rows : {1, 7, 64, 100, 333, 1000, 7000}) digest(rows);
    return EXIT_SUCCESS;
  }
  const std::size_t runs = argc > 1 ? std::stoul(argv[1]) : 200;
  const std::uint64_t chunks = argc > 2 ? std::stoull(argv[2]) : 64;
  const dynid::load::SyntheticBodyRun gen(100.0, 100, 8);
  const dynid::ingest::RunAnnouncement announcement = gen.announcement("probe-car", "run-1");
  std::vector<dynid::ingest::Chunk> data;
  for (std::uint64_t k = 0; k < chunks; ++k) data.push_back(gen.chunk("probe-car", "run-1", k));

  const Mark base = mark();
  std::vector<dynid::ingest::RunProcessor> processors;
  processors.reserve(runs);
  for (std::size_t i = 0; i < runs; ++i) processors.emplace_back(announcement);
  report("built", base, runs);
  for (std::uint64_t k = 0; k < chunks; ++k) {
    for (dynid::ingest::RunProcessor& p : processors) p.push(data[k]);
    if (((k + 1) & k) == 0 || k + 1 == chunks)  // 1, 2, 4, ... and the last
      report(("after " + std::to_string(k + 1) + " chunks").c_str(), base, runs);
  }

  std::size_t allocated = 0;
  std::size_t held = 0;
  std::printf("\nbuffers of one run after %llu chunks (bytes):\n%-36s %10s %10s\n",
              static_cast<unsigned long long>(chunks), "buffer", "allocated", "held");
  for (const dynid::signal::HeldBuffer& b : processors.front().held_buffers()) {
    std::printf("%-36s %10zu %10zu\n", b.name.c_str(), b.allocated, b.held);
    allocated += b.allocated;
    held += b.held;
  }
  std::printf("%-36s %10zu %10zu\n", "total", allocated, held);
  return EXIT_SUCCESS;
}
