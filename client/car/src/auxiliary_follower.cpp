#include "dynid/car/auxiliary_follower.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <limits>

#include "dynid/error.hpp"

namespace dynid::car {

AuxiliaryFollower::AuxiliaryFollower(const AuxiliarySourceSpec& spec, std::filesystem::path file, double offset)
    : spec_(spec), file_(std::move(file)), offset_(offset), parser_(spec_, file_.string()) {
  const std::string what = "auxiliary source '" + spec.name + "' (" + file_.string() + ")";
  if (spec.type != "csv") throw InputError(what + ": only a CSV source can be followed live");
  fd_ = ::open(file_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) throw InputError(what + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd_, &st) != 0 || !(S_ISREG(st.st_mode) || S_ISFIFO(st.st_mode))) {
    ::close(fd_);
    throw InputError(what + ": neither a regular file nor a named pipe (FIFO)");
  }
  fifo_ = S_ISFIFO(st.st_mode);
}

AuxiliaryFollower::~AuxiliaryFollower() {
  if (fd_ >= 0) ::close(fd_);
}

void AuxiliaryFollower::stop(std::string reason) {
  error_ = std::move(reason);
  ended_ = true;
}

void AuxiliaryFollower::take_line(std::string_view line, std::vector<AuxiliaryRow>& out) {
  try {
    auto row = parser_.line(line);
    if (!row) return;
    row->time += offset_;
    for (std::size_t ci = 0; ci < row->values.size(); ++ci) row->values[ci] = auxiliary_si(spec_, ci, row->values[ci]);
    last_time_ = row->time;
    ++rows_;
    out.push_back(std::move(*row));
  } catch (const InputError& e) {
    stop(e.what());
  }
}

void AuxiliaryFollower::take_lines(std::vector<AuxiliaryRow>& out) {
  std::size_t from = 0;
  for (std::size_t nl; !ended_ && (nl = pending_.find('\n', from)) != std::string::npos; from = nl + 1)
    take_line(std::string_view(pending_).substr(from, nl - from), out);
  pending_.erase(0, from);
  if (!ended_ && pending_.size() > kMaxLineBytes)
    stop(file_.string() + ":" + std::to_string(parser_.line_number() + 1) + ": a line longer than " +
         std::to_string(kMaxLineBytes) + " bytes");
}

std::vector<AuxiliaryRow> AuxiliaryFollower::poll() {
  std::vector<AuxiliaryRow> out;
  if (ended_) return out;
  if (!fifo_) {  // a file that shrinks was rewritten: what was read no longer describes it
    struct stat st {};
    if (::fstat(fd_, &st) == 0 && static_cast<std::uint64_t>(st.st_size) < read_bytes_) {
      stop(file_.string() + ": the file shrank from " + std::to_string(read_bytes_) + " to " +
           std::to_string(st.st_size) + " bytes while it was followed");
      return out;
    }
  }
  char buffer[65536];
  std::size_t taken = 0;
  while (taken < kMaxBytesPerPoll && !ended_) {
    const ssize_t n = ::read(fd_, buffer, sizeof buffer);
    if (n > 0) {
      pending_.append(buffer, static_cast<std::size_t>(n));
      read_bytes_ += static_cast<std::uint64_t>(n);
      taken += static_cast<std::size_t>(n);
      take_lines(out);
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK) stop(file_.string() + ": read: " + std::strerror(errno));
    // n == 0 on a FIFO: no writer. Before the first byte the writer may not have come yet; after
    // it, the writer closed: the source ends with its last line.
    if (n == 0 && fifo_ && read_bytes_ > 0) {
      if (!pending_.empty()) take_line(pending_, out);
      pending_.clear();
      ended_ = true;
    }
    break;
  }
  return out;
}

double AuxiliaryFollower::complete_until() const {
  if (ended_) return std::numeric_limits<double>::infinity();
  return last_time_.value_or(-std::numeric_limits<double>::infinity());
}

}  // namespace dynid::car
