#pragma once
// Delivery: the car's side of the acknowledgement protocol. Every chunk goes into the Spool
// before it is published, and leaves the spool only when the server acknowledges it durably
// (ChunkAck.highest_contiguous). Whatever is unacknowledged is sent again, oldest first, when
// the link seems lost or a server (re)appears, and after a restart of the car.
//
// Contract:
// - The constructor picks up what an earlier process left in the spool: it announces the
//   pending runs again (their stored announcements) and queues their chunks in storage order,
//   ahead of anything new. Nothing is sent twice on purpose, except by a resend below.
// - announce() stores the run's announcement in the spool, then publishes it.
// - submit() stores the chunk (durable when it returns; SpoolFull and InputError propagate and
//   nothing is queued), then sends it if the window allows. It never drops a chunk.
// - A spool whose filesystem refuses the write (SpoolWriteError: disk full, I/O error): the
//   chunk, and every later one, waits in memory in order, and service() retries storing them
//   oldest first; nothing is sent before it is spooled, so the spool stays a prefix of the
//   run. The outage is logged as an error once (naming the spool and the reason) and its end
//   as info. Held bytes are bounded by `max_held_bytes`: beyond, submit() throws SpoolFull (the
//   caller stops reading, as for a full spool). An acknowledgement the spool cannot record is
//   retried the same way (the chunks stay in the spool meanwhile; the server holds them).
//   What is held in memory is lost if the process dies before it is spooled.
// - At most `window` chunks are in flight (sent, not yet acknowledged): the server reads chunks
//   keep-all with bounded depth, and a car must not overrun it. The rest wait in the spool and
//   go out, in order, as acknowledgements free the window.
// - service() takes the acknowledgements (waiting up to `wait` for the first), prunes the spool
//   to each run's highest contiguous sequence, reports new rejections of unacknowledged chunks
//   once each (with the server's reason; a rejected chunk stays in the spool and holds up its
//   run), and resends everything in flight from the oldest unacknowledged chunk when (a) no
//   acknowledgement made progress for ack_timeout while chunks were in flight (a lost link),
//   (b) a new chunk reader matched (a server started or restarted and missed the volatile
//   chunks), or (c) a new rejection named a chunk still in the spool (e.g. it overtook its run's
//   announcement; a rejection that repeats with the same reason does not trigger it again).
// - A chunk the server refuses for good never holds up the chunks after it. A rejection of a
//   pending chunk is checked with the server's own rule (ingest::validate_chunk against the
//   run's stored announcement): when the chunk breaks it (a value past the limit, NaN, a bad
//   shape or checksum), no resend can ever be accepted, so the chunk is set aside in the spool
//   (Spool::set_aside: kept with the reason) and a stand-in takes its place and is sent: the same
//   sequence and rows, every value 0 and every row invalid. The server stores the stand-in, its
//   ledger stays contiguous and holds the refused rows as a gap of invalid rows (as a dropout of
//   the bus), and the run's later chunks are stored and folded. set_aside_report() names each
//   such chunk, its rows and the reason. A rejection the rule does not confirm (the chunk
//   overtook its announcement, the server's window was full) is resent as before.
// - A run whose name the server holds with other content (a rejection saying
//   ingest::kStoredWithOtherContent) cannot be delivered under that name: its chunks are set
//   aside in the spool (Spool::set_aside_run: kept, never resent) and service() throws RunRefused
//   with the server's reason. Acknowledgements never reach past the highest sequence this car
//   has sent of a run: the server's mark for a name taken by another recording counts that
//   recording's chunks, not this car's.
// - server_knows() tells whether the server published any receipt for the run: it does when it
//   accepts an announcement, so a replay can wait for it before sending the run's chunks.
// - drain() services until the spool holds nothing or `timeout` passes; returns drained().
// - Single-threaded: the caller interleaves submit() and service() (the replay's callbacks, the
//   live loop's timeouts). Spool and Uplink must outlive the Delivery.
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <dynid/error.hpp>

#include "dynid/car/spool.hpp"
#include "dynid/car/uplink.hpp"

namespace dynid::car {

/// The server cannot take a run of this car: its name holds another recording's chunks.
class RunRefused : public InputError {
 public:
  using InputError::InputError;
};

enum class LogLevel { info, warning, error };
using DeliveryLog = std::function<void(LogLevel, const std::string&)>;

struct DeliveryOptions {
  std::chrono::milliseconds ack_timeout{5000};
  std::size_t window = 32;  ///< below the chunk QoS's 64 unread samples per run
  std::uint64_t max_held_bytes = 64ULL << 20;  ///< chunks held while the spool cannot store
};

struct DeliveryStats {
  std::uint64_t submitted = 0;     ///< chunks stored by this process
  std::uint64_t sent = 0;          ///< first sends by this process
  std::uint64_t resent = 0;        ///< sends of a chunk sent before (or left by an earlier process)
  std::uint64_t acknowledged = 0;  ///< chunks pruned from the spool by acknowledgements
  std::uint64_t resend_rounds = 0;
  std::uint64_t blocked = 0;       ///< sends refused because the server's queue stayed full
  std::uint64_t rejections = 0;    ///< distinct rejections reported by the server
  std::uint64_t held = 0;          ///< chunks held in memory while the spool could not store
  std::uint64_t set_aside = 0;     ///< chunks refused for good, set aside and sent as invalid rows
};

class Delivery {
 public:
  Delivery(Spool& spool, Uplink& uplink, DeliveryOptions options = {}, DeliveryLog logger = {});

  void announce(const ingest::RunAnnouncement& announcement);
  void submit(const ingest::Chunk& chunk);
  void service(std::chrono::milliseconds wait);
  bool drain(std::chrono::milliseconds timeout);

  bool drained() const { return queue_.empty() && held_.empty() && unrecorded_.empty(); }
  bool server_knows(const std::string& vehicle, const std::string& run) const {
    return known_runs_.count({vehicle, run}) > 0;
  }
  /// Chunks in the spool (this process's and earlier ones') and held for it.
  std::size_t pending() const { return queue_.size() + held_.size(); }
  std::size_t in_flight() const { return sent_; }
  const DeliveryStats& stats() const { return stats_; }
  /// Why the oldest pending chunk is not acknowledged, as far as the car knows (a rejection's
  /// reason, or that no server matched), for the final message; empty when drained.
  std::string holdup() const;
  /// One line per chunk refused for good and set aside by this process: which chunk, its rows
  /// and samples, the server's reason, and what was sent in its place.
  const std::vector<std::string>& set_aside_report() const { return set_aside_; }

 private:
  struct Entry {
    std::string vehicle;
    std::string run;
    std::uint64_t sequence = 0;
    bool sent_before = false;
  };
  using Clock = std::chrono::steady_clock;

  /// True when the receipt brings a new rejection of a chunk still in the spool.
  bool on_receipt(const dds::ChunkReceipt& receipt);
  void acknowledge(const std::string& vehicle, const std::string& run, std::uint64_t through);
  /// Sets the pending chunk aside with a stand-in when the server's rule refuses it for good.
  void set_aside_if_refused(const Entry& entry, const std::string& reason);
  /// Sets the run's chunks aside and throws RunRefused with the server's reason.
  [[noreturn]] void refuse_run(const std::string& vehicle, const std::string& run,
                               const std::string& reason);
  void restart_round(const std::string& why);
  /// Stores the held chunks, oldest first, until the spool refuses again.
  void spool_held();
  void hold(const ingest::Chunk& chunk, const std::string& why);
  /// Records acknowledgements the spool could not record earlier.
  void record_acknowledgements();
  void pump();
  void log(LogLevel level, const std::string& message) const;

  Spool& spool_;
  Uplink& uplink_;
  DeliveryOptions options_;
  DeliveryLog log_;
  std::deque<Entry> queue_;  // the spool's chunks, storage order
  std::deque<ingest::Chunk> held_;  // not yet spooled (the spool could not write), in order
  std::uint64_t held_bytes_ = 0;
  std::map<std::pair<std::string, std::string>, std::uint64_t> unrecorded_;  // acks to record
  std::size_t sent_ = 0;     // queue_[0, sent_) are in flight in the current round
  Clock::time_point last_progress_;
  std::uint32_t readers_seen_ = 0;
  std::set<std::tuple<std::string, std::uint64_t, std::string>> rejections_seen_;
  std::map<std::pair<std::string, std::uint64_t>, std::string> rejected_;  // (run, seq) -> reason
  std::set<std::pair<std::string, std::string>> known_runs_;  // (vehicle, run) with a receipt
  // (vehicle, run) this car announced or spooled: the receipts of the vehicle's other cars (they
  // share its partition) are not its news.
  std::set<std::pair<std::string, std::string>> own_runs_;
  // (vehicle, run) -> the highest sequence sent (by this process or, for what the spool held at
  // start, an earlier one): how far an acknowledgement of the run may reach.
  std::map<std::pair<std::string, std::string>, std::uint64_t> sent_through_;
  std::vector<std::string> set_aside_;
  DeliveryStats stats_;
};

}  // namespace dynid::car
