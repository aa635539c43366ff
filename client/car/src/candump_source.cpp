#include "dynid/car/candump_source.hpp"

#include <dynid/input/input_file.hpp>

#include "dynid/error.hpp"

namespace dynid::car {
namespace {

// Checked before opening: opening a FIFO would block until a writer appears.
std::ifstream open_log(const std::filesystem::path& path) {
  input::check_input_file(path, "CAN log");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open the CAN log");
  return in;
}

}  // namespace

CandumpSource::CandumpSource(const std::filesystem::path& path, std::size_t max_bad_lines)
    : file_(open_log(path)),
      size_(std::filesystem::file_size(path)),
      reader_(file_, path.filename().string(), can::OnError::Continue) {
  reader_.stop_after_errors(max_bad_lines);
}

NextStatus CandumpSource::next(can::Frame& frame, std::chrono::milliseconds /*timeout*/) {
  if (ended_ || !reader_.next(frame)) {
    ended_ = true;
    return NextStatus::End;
  }
  return NextStatus::Frame;
}

double CandumpSource::fraction_done() const {
  if (ended_ || size_ == 0) return 1.0;
  const auto pos = file_.tellg();
  if (pos < 0) return 1.0;
  return static_cast<double>(pos) / static_cast<double>(size_);
}

std::vector<std::string> CandumpSource::errors() const {
  std::vector<std::string> out;
  for (const auto& e : reader_.errors()) out.push_back(reader_.describe(e));
  return out;
}

}  // namespace dynid::car
