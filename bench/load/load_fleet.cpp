#include "load_fleet.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <sys/resource.h>

#include <atomic>
#include <condition_variable>
#include <cstring>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <unordered_map>

#include "dynid.h"
#include "dynid/dds/conversions.hpp"
#include "dynid/dds/entity.hpp"
#include "dynid/dds/error.hpp"
#include "dynid/dds/participant.hpp"
#include "dynid/dds/reader.hpp"
#include "dynid/dds/writer.hpp"
#include "dynid/error.hpp"
#include "dynid/ingest/run_processor.hpp"
#include "process_stats.hpp"
#include "synthetic_body_run.hpp"

namespace dynid::load {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

std::int64_t ns_since(Clock::time_point origin) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - origin).count();
}

double own_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const auto tv = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return tv(usage.ru_utime) + tv(usage.ru_stime);
}

// R_k: the model's row count after folding chunks 0..k (the server's RunProcessor, offline).
std::vector<std::uint64_t> expected_rows(const SyntheticBodyRun& run, const LoadOptions& o) {
  ingest::RunProcessor processor(run.announcement("reference", o.run));
  std::vector<std::uint64_t> rows;
  rows.reserve(o.chunks_per_vehicle);
  for (std::uint64_t k = 0; k < o.chunks_per_vehicle; ++k) {
    processor.push(run.chunk("reference", o.run, k));
    const ls::EquationGroups* groups = processor.groups(0);
    std::uint64_t total = 0;
    for (std::size_t g = 0; groups && g < groups->size(); ++g)
      total += groups->group(g).row_count();
    rows.push_back(total);
  }
  return rows;
}

// One simulated car: its writers and what the receiver learnt about it.
struct Vehicle {
  Vehicle(const dds::Participant& participant, std::string vehicle_id, std::uint64_t chunks)
      : id(std::move(vehicle_id)),
        announcements(participant, {dds::vehicle_partition(id)}),
        chunk_writer(participant, {dds::vehicle_partition(id)}),
        written_at(new std::atomic<std::int64_t>[chunks]) {}

  std::string id;
  dds::Writer<dynid_wire_RunAnnouncement> announcements;
  dds::Writer<dynid_wire_Chunk> chunk_writer;
  std::unique_ptr<std::atomic<std::int64_t>[]> written_at;  // ns since the origin
  std::atomic<std::uint64_t> written{0};                    // chunks 0..written-1 have been written
  std::atomic<std::int64_t> acked{-2};  // highest contiguous; -2: announcement not accepted
  // Writing thread only (resend_overdue): the ack mark last seen and since when it stands.
  std::int64_t progress_mark = -2;
  Clock::time_point last_progress{};
  // Receiver thread only:
  std::uint64_t next_ack = 0, next_estimate = 0, last_rows = 0;
  bool has_estimate = false;
};

class Fleet {
 public:
  explicit Fleet(const LoadOptions& o)
      : options_(o),
        run_(o.sample_rate_hz, o.chunk_rows, o.odmf),
        rows_(expected_rows(run_, o)),
        participant_({o.domain, o.cyclone_config}),
        acks_(participant_, {dds::kAllVehiclesPartition}),
        estimates_(participant_, {dds::kAllVehiclesPartition}) {
    for (std::size_t v = 0; v < o.vehicles; ++v) {
      vehicles_.push_back(std::make_unique<Vehicle>(participant_, fmt::format("{}-{}", o.prefix, v),
                                                    o.chunks_per_vehicle));
      index_.emplace(vehicles_.back()->id, v);
    }
  }

  LoadResult run();

 private:
  void connect();
  void stream();
  void send(Vehicle& v, std::uint64_t k);
  void write(Vehicle& v, const dynid_wire_Chunk& sample);
  void resend_overdue();
  void wait_until(Clock::time_point due);
  void receive_loop();
  void take_acks();
  void take_estimates();
  bool done() const;
  void sample_rss();
  LoadResult summarize();

  const LoadOptions& options_;
  SyntheticBodyRun run_;
  std::vector<std::uint64_t> rows_;
  dds::Participant participant_;
  dds::Reader<dynid_wire_ChunkAck> acks_;
  dds::Reader<dynid_wire_Estimate> estimates_;
  std::vector<std::unique_ptr<Vehicle>> vehicles_;
  std::unordered_map<std::string, std::size_t> index_;
  Clock::time_point origin_ = Clock::now();
  std::atomic<bool> stop_{false};
  std::mutex progress_mutex_;
  std::condition_variable progress_;  // an ack arrived (fast mode waits on it)
  // Receiver thread's results (read after it is joined):
  std::vector<double> ack_ms_, estimate_ms_;
  std::uint64_t rejections_ = 0, model_rows_ = 0;
  std::int64_t last_ack_ns_ = 0, last_estimate_ns_ = 0;
  std::vector<double> rss_t_, rss_mb_;
  std::atomic<std::uint64_t> retries_{0};
  std::uint64_t resent_ = 0, resend_rounds_ = 0;  // writing thread only
  Clock::time_point last_resend_check_{};
  ProcessStats server_start_{}, server_end_{};
  double load_cpu_start_ = 0.0;
};

void Fleet::connect() {
  const auto deadline = Clock::now() + options_.patience;
  for (auto& v : vehicles_) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    const auto wait = std::max(left, std::chrono::milliseconds(1));
    if (!v->chunk_writer.wait_for_readers(options_.servers, wait) ||
        !v->announcements.wait_for_readers(options_.servers, wait))
      throw std::runtime_error(fmt::format("load: {} server(s) not discovered for {} within the patience",
                                           options_.servers, v->id));
  }
  for (auto& v : vehicles_)
    v->announcements.write(dds::to_wire(run_.announcement(v->id, options_.run)).data);
  while (Clock::now() < deadline) {  // the server answers every accepted announcement with an ack
    take_acks();
    if (std::all_of(vehicles_.begin(), vehicles_.end(),
                    [](const auto& v) { return v->acked >= -1; }))
      return;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  throw std::runtime_error(
      "load: the server did not accept every announcement within the patience");
}

void Fleet::send(Vehicle& v, std::uint64_t k) {
  const auto sample = dds::to_wire(run_.chunk(v.id, options_.run, k));
  v.written_at[k].store(ns_since(origin_), std::memory_order_relaxed);  // the first send only
  v.written.store(k + 1, std::memory_order_release);
  write(v, sample.data);
}

void Fleet::write(Vehicle& v, const dynid_wire_Chunk& sample) {
  while (!v.chunk_writer.write(sample)) {  // the server's reader is full: retry, as a spool does
    retries_.fetch_add(1);
    if (stop_.load()) return;
  }
}

// dynid-car's resend rule (load_fleet.hpp), checked at most every 10 ms.
void Fleet::resend_overdue() {
  const auto now = Clock::now();
  if (now - last_resend_check_ < std::chrono::milliseconds(10)) return;
  last_resend_check_ = now;
  for (auto& vehicle : vehicles_) {
    Vehicle& v = *vehicle;
    const std::int64_t acked = v.acked.load();
    const auto first = static_cast<std::uint64_t>(std::max<std::int64_t>(acked + 1, 0));
    const std::uint64_t written = v.written.load();
    if (acked > v.progress_mark || first >= written) {  // progress, or nothing in flight
      v.progress_mark = std::max(v.progress_mark, acked);
      v.last_progress = now;
      continue;
    }
    if (now - v.last_progress < options_.ack_timeout) continue;
    ++resend_rounds_;
    for (std::uint64_t k = first; k < written && !stop_.load(); ++k) {
      write(v, dds::to_wire(run_.chunk(v.id, options_.run, k)).data);
      ++resent_;
    }
    v.last_progress = Clock::now();
  }
}

// Sleeps until `due`, resending what is overdue meanwhile.
void Fleet::wait_until(Clock::time_point due) {
  for (;;) {
    resend_overdue();
    const auto now = Clock::now();
    if (now >= due) return;
    std::this_thread::sleep_until(std::min(due, now + std::chrono::milliseconds(10)));
  }
}

void Fleet::stream() {
  const std::size_t n = vehicles_.size();
  const std::uint64_t total = options_.chunks_per_vehicle * n;
  if (options_.paced) {
    const double period = static_cast<double>(options_.chunk_rows) / options_.sample_rate_hz;
    const auto start = Clock::now();
    for (std::uint64_t j = 0; j < total; ++j) {
      const auto due =
          start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                      period * static_cast<double>(j) / static_cast<double>(n)));
      wait_until(due);
      send(*vehicles_[j % n], j / n);
    }
    return;
  }
  std::uint64_t sent = 0;
  while (sent < total) {
    resend_overdue();
    bool any = false;
    for (auto& v : vehicles_) {
      const std::uint64_t k = v->written.load();
      if (k < options_.chunks_per_vehicle &&
          static_cast<std::int64_t>(k) <=
              v->acked.load() + static_cast<std::int64_t>(options_.window)) {
        send(*v, k);
        ++sent;
        any = true;
      }
    }
    if (!any) {
      std::unique_lock lock(progress_mutex_);
      progress_.wait_for(lock, std::chrono::milliseconds(2));
    }
  }
}

void Fleet::take_acks() {
  for (auto& s : acks_.take(256)) {
    const auto it =
        index_.find(std::string(s.data.vehicle, strnlen(s.data.vehicle, sizeof s.data.vehicle)));
    if (it == index_.end()) continue;
    Vehicle& v = *vehicles_[it->second];
    rejections_ += s.data.rejections._length;
    const std::int64_t mark = s.data.highest_contiguous;
    if (mark > v.acked.load()) v.acked.store(mark);
    if (v.acked.load() < -1) v.acked.store(-1);
    const std::int64_t now = ns_since(origin_);
    while (static_cast<std::int64_t>(v.next_ack) <= mark &&
           v.next_ack < v.written.load(std::memory_order_acquire)) {
      ack_ms_.push_back(1e-6 * static_cast<double>(now - v.written_at[v.next_ack].load()));
      ++v.next_ack;
      last_ack_ns_ = now;
    }
  }
  progress_.notify_all();
}

void Fleet::take_estimates() {
  for (auto& s : estimates_.take(256)) {
    const auto it =
        index_.find(std::string(s.data.vehicle, strnlen(s.data.vehicle, sizeof s.data.vehicle)));
    if (it == index_.end()) continue;
    Vehicle& v = *vehicles_[it->second];
    const std::int64_t now = ns_since(origin_);
    v.has_estimate = true;
    if (s.data.rows > v.last_rows) {
      model_rows_ += s.data.rows - v.last_rows;
      v.last_rows = s.data.rows;
    }
    const std::uint64_t written = v.written.load(std::memory_order_acquire);
    while (v.next_estimate < written && rows_[v.next_estimate] <= s.data.rows) {
      const std::uint64_t k = v.next_estimate++;
      if (rows_[k] == 0 || (k > 0 && rows_[k] == rows_[k - 1])) continue;  // adds no row
      estimate_ms_.push_back(1e-6 * static_cast<double>(now - v.written_at[k].load()));
      last_estimate_ns_ = now;
    }
  }
}

bool Fleet::done() const {
  const std::uint64_t last = options_.chunks_per_vehicle;
  return std::all_of(vehicles_.begin(), vehicles_.end(), [&](const auto& v) {
    return v->next_ack == last && v->last_rows >= rows_.back();
  });
}

void Fleet::receive_loop() {
  dds::Entity waitset(dds::check(dds_create_waitset(participant_.handle()), "dds_create_waitset"));
  dds::Entity on_ack(dds::check(dds_create_readcondition(acks_.handle(), DDS_ANY_STATE),
                                "dds_create_readcondition"));
  dds::Entity on_estimate(dds::check(dds_create_readcondition(estimates_.handle(), DDS_ANY_STATE),
                                     "dds_create_readcondition"));
  dds::check(dds_waitset_attach(waitset.get(), on_ack.get(), 0), "dds_waitset_attach");
  dds::check(dds_waitset_attach(waitset.get(), on_estimate.get(), 1), "dds_waitset_attach");
  while (!stop_.load()) {
    dds_waitset_wait(waitset.get(), nullptr, 0, DDS_MSECS(50));
    take_acks();
    take_estimates();
  }
}

void Fleet::sample_rss() {
  if (options_.server_pids.empty() || options_.rss_period.count() <= 0) return;
  auto next = Clock::now();
  while (!stop_.load()) {
    rss_t_.push_back(seconds_between(origin_, Clock::now()));
    rss_mb_.push_back(static_cast<double>(read_process_stats(options_.server_pids).rss_bytes) /
                      1048576.0);
    next += options_.rss_period;
    while (!stop_.load() && Clock::now() < next)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

LoadResult Fleet::run() {
  connect();
  if (!options_.server_pids.empty()) server_start_ = read_process_stats(options_.server_pids);
  load_cpu_start_ = own_cpu_seconds();
  origin_ = Clock::now();
  std::thread receiver([this] { receive_loop(); });
  std::thread rss([this] { sample_rss(); });
  try {
    stream();
  } catch (...) {
    stop_.store(true);
    receiver.join();
    rss.join();
    throw;
  }
  const auto drain_end = Clock::now() + options_.drain;
  while (Clock::now() < drain_end && !done())
    wait_until(Clock::now() + std::chrono::milliseconds(10));
  if (!options_.server_pids.empty()) server_end_ = read_process_stats(options_.server_pids);
  stop_.store(true);
  receiver.join();
  rss.join();
  return summarize();
}

LoadResult Fleet::summarize() {
  LoadResult r;
  r.vehicles = vehicles_.size();
  r.servers = options_.servers;
  r.write_retries = retries_.load();
  r.resent_chunks = resent_;
  r.resend_rounds = resend_rounds_;
  r.ack_timeout_ms = options_.ack_timeout.count();
  r.rejections = rejections_;
  r.chunk_bytes = static_cast<std::size_t>(options_.chunk_rows) * (run_.channels() * 8 + 1);
  for (const auto& v : vehicles_) {
    const std::uint64_t written = v->written.load();
    r.chunks_written += written;
    r.chunks_acked += v->next_ack;
    r.lost += written - v->next_ack;
    r.vehicles_fully_acked += v->next_ack == options_.chunks_per_vehicle;
    r.vehicles_with_estimate += v->has_estimate;
    r.final_rows_wrong += v->last_rows != rows_.back();
    for (std::uint64_t k = 0; k < written; ++k) {
      const bool measurable = rows_[k] > 0 && (k == 0 || rows_[k] > rows_[k - 1]);
      r.unmeasurable += !measurable;
      r.missed += measurable && k >= v->next_estimate;
    }
  }
  const auto rows = static_cast<std::uint64_t>(options_.chunk_rows);
  r.sample_rows_acked = r.chunks_acked * rows;
  r.sample_rows_folded = (r.chunks_written - r.missed) * rows;
  r.model_rows_folded = model_rows_;
  r.stream_seconds = 1e-9 * static_cast<double>(last_ack_ns_);
  r.fold_seconds = 1e-9 * static_cast<double>(last_estimate_ns_);
  r.ack_p50_ms = quantile(ack_ms_, 0.5);
  r.ack_p99_ms = quantile(ack_ms_, 0.99);
  r.estimate_p50_ms = quantile(estimate_ms_, 0.5);
  r.estimate_p99_ms = quantile(estimate_ms_, 0.99);
  r.estimate_max_ms = quantile(estimate_ms_, 1.0);
  r.latency_samples = estimate_ms_.size();
  if (!options_.server_pids.empty()) {
    r.server_cpu_seconds = server_end_.cpu_seconds - server_start_.cpu_seconds;
    r.server_rss_start_mb = static_cast<double>(server_start_.rss_bytes) / 1048576.0;
    r.server_rss_end_mb = static_cast<double>(server_end_.rss_bytes) / 1048576.0;
    r.server_peak_rss_mb = static_cast<double>(server_end_.peak_rss_bytes) / 1048576.0;
  }
  const std::size_t skip = rss_t_.size() / 5;  // warm-up: runs and caches being created
  r.rss_samples = rss_t_.size();
  r.rss_series_mb = rss_mb_;
  r.rss_slope_kb_per_min =
      1024.0 * 60.0 *
      slope({rss_t_.begin() + static_cast<std::ptrdiff_t>(skip), rss_t_.end()},
            {rss_mb_.begin() + static_cast<std::ptrdiff_t>(skip), rss_mb_.end()});
  r.load_cpu_seconds = own_cpu_seconds() - load_cpu_start_;
  return r;
}

}  // namespace

std::string LoadResult::to_json() const {
  return fmt::format(
      R"({{"vehicles":{},"servers":{},"chunks_written":{},"chunks_acked":{},"write_retries":{},)"
      R"("resent_chunks":{},"resend_rounds":{},"ack_timeout_ms":{},"lost":{},)"
      R"("missed":{},"rejections":{},"unmeasurable":{},"vehicles_fully_acked":{},)"
      R"("vehicles_with_estimate":{},"final_rows_wrong":{},"sample_rows_acked":{},)"
      R"("sample_rows_folded":{},"model_rows_folded":{},"stream_seconds":{:.4f},"fold_seconds":{:.4f},)"
      R"("ack_p50_ms":{:.3f},"ack_p99_ms":{:.3f},"estimate_p50_ms":{:.3f},"estimate_p99_ms":{:.3f},)"
      R"("estimate_max_ms":{:.3f},"latency_samples":{},"chunk_bytes":{},"server_cpu_seconds":{:.3f},)"
      R"("server_rss_start_mb":{:.2f},"server_rss_end_mb":{:.2f},"server_peak_rss_mb":{:.2f},)"
      R"("rss_slope_kb_per_min":{:.2f},"rss_samples":{},"load_cpu_seconds":{:.3f},"rss_series_mb":[{:.2f}]}})",
      vehicles, servers, chunks_written, chunks_acked, write_retries, resent_chunks, resend_rounds,
      ack_timeout_ms, lost, missed, rejections, unmeasurable,
      vehicles_fully_acked, vehicles_with_estimate, final_rows_wrong, sample_rows_acked,
      sample_rows_folded, model_rows_folded, stream_seconds, fold_seconds, ack_p50_ms, ack_p99_ms,
      estimate_p50_ms, estimate_p99_ms, estimate_max_ms, latency_samples, chunk_bytes,
      server_cpu_seconds, server_rss_start_mb, server_rss_end_mb, server_peak_rss_mb,
      rss_slope_kb_per_min, rss_samples, load_cpu_seconds, fmt::join(rss_series_mb, ","));
}

LoadResult run_load(const LoadOptions& options) {
  if (options.vehicles < 1) throw InputError("load: --vehicles must be >= 1");
  if (options.chunks_per_vehicle < 1) throw InputError("load: --chunks must be >= 1");
  if (options.window < 1) throw InputError("load: --window must be >= 1");
  if (options.servers < 1) throw InputError("load: --servers must be >= 1");
  if (options.ack_timeout.count() < 1) throw InputError("load: --ack-timeout must be > 0");
  Fleet fleet(options);
  return fleet.run();
}

}  // namespace dynid::load
