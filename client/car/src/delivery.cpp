#include "dynid/car/delivery.hpp"

#include <algorithm>

#include <dynid/ingest/refusals.hpp>

#include "dynid/dds/protocol.hpp"

namespace dynid::car {
namespace {

using dds::protocol::kAnnouncementSequence;

std::string name_of(const std::string& vehicle, const std::string& run, std::uint64_t sequence) {
  if (sequence == kAnnouncementSequence) return "the announcement of " + vehicle + "/" + run;
  return vehicle + "/" + run + "#" + std::to_string(sequence);
}

// What a held chunk costs in memory, near enough for the bound.
std::uint64_t held_size(const ingest::Chunk& chunk) {
  return static_cast<std::uint64_t>(chunk.samples.size()) * sizeof(double) + chunk.valid.size() + 256;
}

}  // namespace

Delivery::Delivery(Spool& spool, Uplink& uplink, DeliveryOptions options, DeliveryLog logger)
    : spool_(spool), uplink_(uplink), options_(options), log_(std::move(logger)),
      last_progress_(Clock::now()) {
  if (options_.window == 0) options_.window = 1;
  // A restart: the server may never have seen these runs (or lost nothing and acknowledges
  // them at once from its ledger); either way they are announced before their chunks.
  const auto runs = spool_.pending_announcements();
  for (const auto& announcement : runs) {
    own_runs_.insert({announcement.vehicle, announcement.run});
    uplink_.announce(announcement);
  }
  for (const auto& e : spool_.pending_entries()) {
    own_runs_.insert({e.vehicle, e.run});
    queue_.push_back({e.vehicle, e.run, e.sequence, true});
    auto& sent = sent_through_[{e.vehicle, e.run}];  // an earlier process may have sent it
    sent = std::max(sent, e.sequence);
  }
  if (!queue_.empty())
    log(LogLevel::info, "resuming: " + std::to_string(queue_.size()) + " unacknowledged chunks in the spool (" +
                            std::to_string(runs.size()) + " runs announced again), oldest " +
                            name_of(queue_.front().vehicle, queue_.front().run, queue_.front().sequence));
}

void Delivery::announce(const ingest::RunAnnouncement& announcement) {
  own_runs_.insert({announcement.vehicle, announcement.run});
  spool_.store_announcement(announcement);
  uplink_.announce(announcement);
}

void Delivery::submit(const ingest::Chunk& chunk) {
  own_runs_.insert({chunk.vehicle, chunk.run});
  if (!held_.empty()) {
    hold(chunk, {});  // behind the held ones: the spool stays a prefix of the run
  } else {
    try {
      spool_.store(chunk);  // durable before it is sent; throws (SpoolFull...) before queueing
      ++stats_.submitted;
      queue_.push_back({chunk.vehicle, chunk.run, chunk.sequence, false});
    } catch (const SpoolWriteError& e) {
      hold(chunk, e.what());
    }
  }
  service(std::chrono::milliseconds(0));
}

void Delivery::hold(const ingest::Chunk& chunk, const std::string& why) {
  const std::uint64_t bytes = held_size(chunk);
  if (held_bytes_ + bytes > options_.max_held_bytes)
    throw SpoolFull("spool " + spool_.file().string() + " cannot store chunks and " + std::to_string(held_.size()) +
                    " (" + std::to_string(held_bytes_) + " bytes) already wait in memory: " +
                    name_of(chunk.vehicle, chunk.run, chunk.sequence) + " does not fit");
  if (held_.empty())
    log(LogLevel::error, why + ": holding " + name_of(chunk.vehicle, chunk.run, chunk.sequence) +
                             " and what follows in memory until the spool can store them (nothing is sent "
                             "before it is spooled; retrying)");
  held_.push_back(chunk);
  held_bytes_ += bytes;
  ++stats_.held;
}

void Delivery::spool_held() {
  std::size_t stored = 0;
  while (!held_.empty()) {
    const ingest::Chunk& chunk = held_.front();
    try {
      spool_.store(chunk);
    } catch (const SpoolWriteError&) {
      return;  // still no room: reported when the outage began
    } catch (const SpoolFull&) {
      return;  // the spool's own bound: acknowledgements make room
    }
    ++stats_.submitted;
    ++stored;
    queue_.push_back({chunk.vehicle, chunk.run, chunk.sequence, false});
    held_bytes_ -= held_size(chunk);
    held_.pop_front();
  }
  if (stored > 0)
    log(LogLevel::info, "spool " + spool_.file().string() + " stores again: " + std::to_string(stored) +
                            " chunks held in memory are spooled");
}

void Delivery::record_acknowledgements() {
  for (auto it = unrecorded_.begin(); it != unrecorded_.end(); it = unrecorded_.erase(it)) {
    try {
      spool_.acknowledge(it->first.first, it->first.second, it->second);
    } catch (const SpoolWriteError&) {
      return;  // reported when it first failed
    }
  }
}

void Delivery::service(std::chrono::milliseconds wait) {
  record_acknowledgements();  // first: deleting acknowledged chunks makes room
  spool_held();
  bool rejected = false;
  for (const auto& receipt : uplink_.receipts(wait)) rejected = on_receipt(receipt) || rejected;
  if (rejected && sent_ > 0) restart_round("the server rejected a chunk in flight");
  const std::uint32_t readers = uplink_.readers_matched_total();
  if (readers > readers_seen_) {
    readers_seen_ = readers;
    if (sent_ > 0) restart_round("a server (re)appeared");
  }
  if (sent_ > 0 && Clock::now() - last_progress_ > options_.ack_timeout)
    restart_round("no acknowledgement for " + std::to_string(options_.ack_timeout.count()) + " ms");
  pump();
}

bool Delivery::drain(std::chrono::milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (!drained()) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) break;
    service(std::min(left, std::chrono::milliseconds(100)));
  }
  return drained();
}

std::string Delivery::holdup() const {
  if (!held_.empty())
    return std::to_string(held_.size()) + " chunks wait in memory, lost at exit: the spool " + spool_.file().string() +
           " could not store them";
  if (queue_.empty())
    return unrecorded_.empty() ? std::string()
                               : "the spool " + spool_.file().string() +
                                     " could not record the server's acknowledgements (its chunks are resent "
                                     "on the next start and acknowledged again)";
  const Entry& oldest = queue_.front();
  std::string why = std::to_string(queue_.size()) + " chunks unacknowledged, oldest " +
                    name_of(oldest.vehicle, oldest.run, oldest.sequence);
  if (auto it = rejected_.find({oldest.run, oldest.sequence}); it != rejected_.end())
    return why + ": the server rejected it: " + it->second;
  if (readers_seen_ == 0) return why + ": no server ever matched the chunk topic";
  return why + ": no acknowledgement from the server";
}

bool Delivery::on_receipt(const dds::ChunkReceipt& receipt) {
  known_runs_.insert({receipt.vehicle, receipt.run});
  if (own_runs_.count({receipt.vehicle, receipt.run}) == 0) return false;  // another car's run
  bool pending_rejected = false;
  for (const auto& r : receipt.rejections) {
    // Other content under this run's name is never history: the server's mark is not this
    // car's, so it is refused before the mark is taken.
    if (r.sequence != kAnnouncementSequence &&
        r.reason.find(ingest::kStoredWithOtherContent) != std::string::npos) {
      ++stats_.rejections;
      log(LogLevel::warning,
          "server rejected " + name_of(receipt.vehicle, receipt.run, r.sequence) + ": " + r.reason);
      refuse_run(receipt.vehicle, receipt.run, r.reason);
    }
    // Rejections of chunks acknowledged since (a resend went through) are history.
    const bool settled = r.sequence != kAnnouncementSequence && receipt.highest_contiguous >= 0 &&
                         r.sequence <= static_cast<std::uint64_t>(receipt.highest_contiguous);
    if (settled || !rejections_seen_.insert({receipt.run, r.sequence, r.reason}).second) continue;
    ++stats_.rejections;
    rejected_[{receipt.run, r.sequence}] = r.reason;
    log(LogLevel::warning, "server rejected " + name_of(receipt.vehicle, receipt.run, r.sequence) + ": " + r.reason);
    const auto pending = std::find_if(queue_.begin(), queue_.end(), [&](const Entry& e) {
      return e.vehicle == receipt.vehicle && e.run == receipt.run && e.sequence == r.sequence;
    });
    if (pending == queue_.end()) continue;
    pending_rejected = true;
    set_aside_if_refused(*pending, r.reason);
  }
  // Never past what this car sent: a chunk not sent yet cannot be the server's.
  const auto sent = sent_through_.find({receipt.vehicle, receipt.run});
  if (receipt.highest_contiguous >= 0 && sent != sent_through_.end())
    acknowledge(receipt.vehicle, receipt.run,
                std::min(static_cast<std::uint64_t>(receipt.highest_contiguous), sent->second));
  return pending_rejected;
}

void Delivery::set_aside_if_refused(const Entry& entry, const std::string& reason) {
  const auto announcement = spool_.announcement(entry.vehicle, entry.run);
  const auto chunk = spool_.load(entry.vehicle, entry.run, entry.sequence);
  if (!announcement || !chunk) return;  // nothing to check it against: resent as before
  try {
    ingest::validate_chunk(*chunk, *announcement);
    return;  // the rule takes it: the refusal may pass (it overtook its announcement, a full
             // window)
  } catch (const InputError&) {
  }
  ingest::Chunk stand_in = *chunk;
  stand_in.samples.setZero();
  std::fill(stand_in.valid.begin(), stand_in.valid.end(), std::uint8_t{0});
  stand_in.seal();
  try {
    ingest::validate_chunk(stand_in, *announcement);
  } catch (const InputError&) {
    return;  // its shape is wrong too: nothing can take its place, it holds the run as before
  }
  spool_.set_aside(stand_in, reason);
  rejected_.erase({entry.run, entry.sequence});  // what is pending now is the stand-in
  ++stats_.set_aside;
  const auto rows = static_cast<std::uint64_t>(chunk->samples.rows());
  const std::string line = name_of(entry.vehicle, entry.run, entry.sequence) + " (samples " +
                           std::to_string(chunk->first_sample_index) + ".." +
                           std::to_string(chunk->first_sample_index + rows - 1) +
                           ") refused for good by the server: " + reason +
                           "; set aside in the spool " + spool_.file().string() + ", its " +
                           std::to_string(rows) +
                           " rows sent as invalid in its place so the run's later chunks go on";
  set_aside_.push_back(line);
  log(LogLevel::warning, line);
}

void Delivery::refuse_run(const std::string& vehicle, const std::string& run,
                          const std::string& reason) {
  const auto of_run = [&](const Entry& e) { return e.vehicle == vehicle && e.run == run; };
  sent_ -= static_cast<std::size_t>(
      std::count_if(queue_.begin(), queue_.begin() + static_cast<std::ptrdiff_t>(sent_), of_run));
  std::erase_if(queue_, of_run);
  std::erase_if(held_, [&](const ingest::Chunk& c) {
    if (c.vehicle != vehicle || c.run != run) return false;
    held_bytes_ -= held_size(c);
    return true;
  });
  const std::size_t moved = spool_.set_aside_run(vehicle, run, reason);
  throw RunRefused(
      "the server refused run " + vehicle + "/" + run + ": " + reason +
      ": its name holds another recording's chunks; replay this one under another --run (its " +
      std::to_string(moved) + " chunks are set aside in the spool " + spool_.file().string() +
      ", not resent)");
}

void Delivery::acknowledge(const std::string& vehicle, const std::string& run, std::uint64_t through) {
  const auto covered = [&](const Entry& e) { return e.vehicle == vehicle && e.run == run && e.sequence <= through; };
  const auto in_flight_end = queue_.begin() + static_cast<std::ptrdiff_t>(sent_);
  const auto acked_in_flight = static_cast<std::size_t>(std::count_if(queue_.begin(), in_flight_end, covered));
  const auto before = queue_.size();
  // The spool first: if the process dies now, the worst case is resending acknowledged chunks.
  if (std::any_of(queue_.begin(), queue_.end(), covered)) {
    try {
      spool_.acknowledge(vehicle, run, through);
    } catch (const SpoolWriteError& e) {  // the server holds them: only the spool's record waits
      if (unrecorded_.empty())
        log(LogLevel::warning, std::string(e.what()) + ": acknowledgement of " + name_of(vehicle, run, through) +
                                   " not recorded in the spool yet; retrying");
      auto& mark = unrecorded_[{vehicle, run}];
      mark = std::max(mark, through);
    }
  }
  std::erase_if(queue_, covered);
  const std::size_t removed = before - queue_.size();
  if (removed == 0) return;
  sent_ -= acked_in_flight;
  stats_.acknowledged += removed;
  last_progress_ = Clock::now();
}

void Delivery::restart_round(const std::string& why) {
  ++stats_.resend_rounds;
  log(LogLevel::warning, why + ": resending " + std::to_string(queue_.size()) + " unacknowledged chunks from " +
                             name_of(queue_.front().vehicle, queue_.front().run, queue_.front().sequence));
  sent_ = 0;
}

void Delivery::pump() {
  while (sent_ < queue_.size() && sent_ < options_.window) {
    Entry& e = queue_[sent_];
    const auto chunk = spool_.load(e.vehicle, e.run, e.sequence);
    if (!chunk) {  // cannot happen while the queue mirrors the spool; never send a hole silently
      log(LogLevel::error, "spool lost " + name_of(e.vehicle, e.run, e.sequence) + " before it was acknowledged");
      queue_.erase(queue_.begin() + static_cast<std::ptrdiff_t>(sent_));
      continue;
    }
    if (!uplink_.send(*chunk)) {  // the server's queue is full: it is alive, just behind
      ++stats_.blocked;
      last_progress_ = Clock::now();
      return;
    }
    if (sent_ == 0) last_progress_ = Clock::now();  // the ack timeout runs from the first send
    auto& through = sent_through_[{e.vehicle, e.run}];
    through = std::max(through, e.sequence);
    ++(e.sent_before ? stats_.resent : stats_.sent);
    e.sent_before = true;
    ++sent_;
  }
}

void Delivery::log(LogLevel level, const std::string& message) const {
  if (log_) log_(level, message);
}

}  // namespace dynid::car
