#include "dynid/car/log_source.hpp"

#include <algorithm>

namespace dynid::car {

LogSource::LogSource(const std::filesystem::path& path, std::size_t max_bad,
                     std::uint64_t max_bytes) {
  reader_ = can::open_log(path, can::OnError::Continue);  // checks the path first
  size_ = std::filesystem::file_size(path);
  reader_->stop_after_errors(max_bad);
  reader_->stop_after_bytes(max_bytes);
}

NextStatus LogSource::next(can::Frame& frame, std::chrono::milliseconds /*timeout*/) {
  if (ended_ || !reader_->next(frame)) {
    ended_ = true;
    return NextStatus::End;
  }
  return NextStatus::Frame;
}

double LogSource::fraction_done() const {
  if (ended_ || size_ == 0) return 1.0;
  return std::min(1.0, static_cast<double>(reader_->bytes_consumed()) / static_cast<double>(size_));
}

std::vector<std::string> LogSource::errors() const {
  std::vector<std::string> out;
  for (const auto& e : reader_->errors()) out.push_back(reader_->describe(e));
  return out;
}

}  // namespace dynid::car
