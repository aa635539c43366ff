#include "dynid/car/log_source.hpp"

#include <algorithm>

#include <dynid/can/mdf4_bus.hpp>
#include <dynid/error.hpp>

namespace dynid::car {

LogSource::LogSource(const std::filesystem::path& path, std::size_t max_bad,
                     std::uint64_t max_bytes)
    : LogSource(std::vector<std::filesystem::path>{path}, max_bad, max_bytes) {}

LogSource::LogSource(const std::vector<std::filesystem::path>& paths, std::size_t max_bad,
                     std::uint64_t max_bytes) {
  if (paths.empty()) throw InputError("no CAN log to replay");
  for (const auto& path : paths) {
    Input in;
    in.reader = can::open_log(path, can::OnError::Continue);  // checks the path first
    in.size = std::filesystem::file_size(path);
    in.reader->stop_after_errors(max_bad);
    in.reader->stop_after_bytes(max_bytes);
    inputs_.push_back(std::move(in));
  }
}

// A merge of the files by their next frame's time; one file is read straight through.
NextStatus LogSource::next(can::Frame& frame, std::chrono::milliseconds /*timeout*/) {
  if (!started_) {
    started_ = true;
    for (auto& in : inputs_) in.has = in.reader->next(in.pending);
  }
  Input* first = nullptr;
  for (auto& in : inputs_)
    if (in.has && (first == nullptr || in.pending.timestamp < first->pending.timestamp))
      first = &in;
  if (first == nullptr) return NextStatus::End;
  frame = first->pending;
  first->has = first->reader->next(first->pending);
  return NextStatus::Frame;
}

std::uint64_t LogSource::bad_input() const {
  std::uint64_t n = 0;
  for (const auto& in : inputs_) n += in.reader->error_count();
  return n;
}

double LogSource::fraction_done() const {
  std::uintmax_t size = 0;
  std::uint64_t read = 0;
  bool ended = started_;
  for (const auto& in : inputs_) {
    size += in.size;
    read += std::min<std::uint64_t>(in.reader->bytes_consumed(), in.size);
    ended = ended && !in.has;
  }
  if (ended || size == 0) return 1.0;
  return std::min(1.0, static_cast<double>(read) / static_cast<double>(size));
}

std::string LogSource::name() const {
  const std::string first = inputs_.front().reader->source();
  return inputs_.size() == 1 ? first : first + " (+" + std::to_string(inputs_.size() - 1) + ")";
}

std::vector<std::string> LogSource::errors() const {
  std::vector<std::string> out;
  for (const auto& in : inputs_)
    for (const auto& e : in.reader->errors()) out.push_back(in.reader->describe(e));
  return out;
}

std::vector<std::string> LogSource::notes() const {
  std::vector<std::string> out;
  for (const auto& in : inputs_)
    if (const auto* mdf = dynamic_cast<const can::Mdf4BusReader*>(in.reader.get()))
      for (const auto& note : mdf->notes()) out.push_back(in.reader->source() + ": " + note);
  return out;
}

}  // namespace dynid::car
