#pragma once
// AuxiliaryFollower: an auxiliary CSV source read while the run is live (dynid-car --can): a
// regular file another program appends to, or a named pipe (FIFO) it writes into. The rows are
// those of a whole file (auxiliary_csv.hpp, the same rules); they arrive as the writer writes
// them. live_merge.hpp holds the bus until the source has caught up.
//
// Contract:
// - The constructor opens the file without blocking (a FIFO needs no writer yet) and throws
//   InputError if it cannot be opened or is neither a regular file nor a FIFO: checked before
//   the run starts.
// - poll() reads what was written since the last call (at most kMaxBytesPerPoll, never
//   blocking) and returns its complete rows on the bus's clock (row time + offset), values in SI.
//   A line is complete at its newline; a FIFO's writer closing ends the source (its last line
//   taken even without a newline). A regular file never ends by itself: the run's end ends it.
// - A line that breaks a rule, a line longer than kMaxLineBytes, a file that shrinks, or a read
//   error stop the source: error() says what and where; what came before is kept. The bus is
//   never stopped for a source.
// - complete_until() is the bus time up to which every row of the source has been read: the
//   last row's time (rows are sorted and never repeat a time), -inf before the first, +inf once
//   the source has ended or stopped.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dynid/car/auxiliary_csv.hpp"
#include "dynid/car/live_source.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {

class AuxiliaryFollower final : public LiveSource {
 public:
  static constexpr std::size_t kMaxBytesPerPoll = 1u << 20;
  static constexpr std::size_t kMaxLineBytes = 1u << 16;

  /// `offset`: bus time = source time + offset.
  AuxiliaryFollower(const AuxiliarySourceSpec& spec, std::filesystem::path file, double offset);
  ~AuxiliaryFollower() override;
  AuxiliaryFollower(const AuxiliaryFollower&) = delete;
  AuxiliaryFollower& operator=(const AuxiliaryFollower&) = delete;

  std::vector<AuxiliaryRow> poll() override;

  double complete_until() const override;
  bool ended() const override { return ended_; }
  const std::optional<std::string>& error() const override { return error_; }
  const std::string& name() const override { return spec_.name; }
  std::string origin() const override { return file_.string(); }
  std::uint64_t rows() const override { return rows_; }
  const AuxiliaryCsvParser& parser() const { return parser_; }

 private:
  const AuxiliarySourceSpec spec_;
  std::filesystem::path file_;
  double offset_;
  int fd_ = -1;
  bool fifo_ = false;
  std::uint64_t read_bytes_ = 0;
  std::string pending_;  // bytes after the last newline
  AuxiliaryCsvParser parser_;
  std::optional<double> last_time_;  // bus clock
  bool ended_ = false;
  std::optional<std::string> error_;
  std::uint64_t rows_ = 0;

  void take_line(std::string_view line, std::vector<AuxiliaryRow>& out);
  void take_lines(std::vector<AuxiliaryRow>& out);
  void stop(std::string reason);
};

/// A source followed live (a file, a pipe, an interface) and where its channels sit in the
/// run's profile.
struct FollowedSource {
  std::unique_ptr<LiveSource> follower;
  std::vector<std::size_t> column_of;  ///< per declared channel: its column in the run's profile
  double wait = 1.0;                   ///< seconds the bus may be held for it ([[sources]] wait)
};

}  // namespace dynid::car
