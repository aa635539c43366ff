#include "dynid/car/progress_display.hpp"

#include <spdlog/sinks/base_sink.h>

#include <cinttypes>

namespace dynid::car {
namespace {

// spdlog -> ProgressDisplay::message(), so log lines never tear the status line.
class DisplaySink final : public spdlog::sinks::base_sink<std::mutex> {
 public:
  explicit DisplaySink(ProgressDisplay& display) : display_(display) {}

 protected:
  void sink_it_(const spdlog::details::log_msg& msg) override {
    spdlog::memory_buf_t formatted;
    formatter_->format(msg, formatted);
    std::string line(formatted.data(), formatted.size());
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    display_.message(line);
  }
  void flush_() override {}

 private:
  ProgressDisplay& display_;
};

}  // namespace

ProgressDisplay::ProgressDisplay(std::FILE* out, bool terminal, std::chrono::milliseconds tty_interval,
                                 std::chrono::milliseconds line_interval)
    : out_(out), terminal_(terminal), interval_(terminal ? tty_interval : line_interval) {}

void ProgressDisplay::update(const std::string& status, bool force) {
  const std::lock_guard lock(mutex_);
  status_ = status;
  const auto now = std::chrono::steady_clock::now();
  if (!force && shown_once_ && now - last_ < interval_) return;
  last_ = now;
  shown_once_ = true;
  draw_locked();
}

void ProgressDisplay::draw_locked() {
  if (status_.empty()) return;
  if (terminal_) {
    std::fprintf(out_, "\r%s\033[K", status_.c_str());
    on_screen_ = true;
  } else {
    std::fprintf(out_, "%s\n", status_.c_str());
  }
  std::fflush(out_);
}

void ProgressDisplay::message(const std::string& text) {
  const std::lock_guard lock(mutex_);
  if (on_screen_) std::fputs("\r\033[K", out_);
  std::fprintf(out_, "%s\n", text.c_str());
  if (on_screen_) draw_locked();
  std::fflush(out_);
}

void ProgressDisplay::finish() {
  const std::lock_guard lock(mutex_);
  if (on_screen_) std::fputc('\n', out_);
  on_screen_ = false;
  std::fflush(out_);
}

std::shared_ptr<spdlog::sinks::sink> ProgressDisplay::log_sink() { return std::make_shared<DisplaySink>(*this); }

std::string format_progress(const std::string& source, const ReplayProgress& replay, const DeliveryStats& delivery,
                            std::size_t pending, std::uint64_t spool_bytes) {
  char buf[512];
  std::string where;
  if (replay.fraction >= 0.0) {
    std::snprintf(buf, sizeof buf, "replay %5.1f %% of %s, %.1f s", 100.0 * replay.fraction,
                  source.c_str(), replay.log_seconds);
    where = buf;
  } else {
    where = source;
  }
  // The spool's size only when it holds something worth its own number (a link down).
  const double mib = static_cast<double>(spool_bytes) / (1024.0 * 1024.0);
  char spool[64];
  if (mib >= 0.1)
    std::snprintf(spool, sizeof spool, "%zu (%.1f MiB)", pending, mib);
  else
    std::snprintf(spool, sizeof spool, "%zu", pending);
  std::snprintf(buf, sizeof buf,
                " | %" PRIu64 " frames | chunks: %" PRIu64 " sent, %" PRIu64 " acked, %" PRIu64
                " resent | spool %s",
                replay.frames, delivery.sent, delivery.acknowledged, delivery.resent, spool);
  return where + buf;
}

}  // namespace dynid::car
