#pragma once
// CanInterfaceFollower: a second CAN bus read live on its own interface with its own DBC (a
// [[sources]] type = "can" in a live run: dynid-car --can can0 --source chassis=can1), as a
// LiveSource (live_source.hpp) that live_merge.hpp merges beside the main bus.
//
// Rows: one per frame that gives channels of the source (SignalMapper over the source's own
// bus profile, so its interfaces filter, DBC, units and scales apply as in a replay of its log),
// at the frame's kernel time to the microsecond (live_timestamp) + the source's offset. A
// channel's sample that does not come after its previous one is left out, as a replay of the log
// drops it (auxiliary.cpp).
//
// Completeness: frames reach the socket in the order the kernel stamped them, a moment after
// their stamp. When a poll has emptied the socket, every frame stamped more than kDeliverySlack
// before the poll began has been read: complete_until() is the later of that and the last frame's
// time (plus the offset). A frame delivered later than the slack would arrive late (counted by
// the merge). The interface failing (removed, down) stops the source with SocketCanError's text.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dynid/car/live_source.hpp"
#include "dynid/car/signal_mapper.hpp"
#include "dynid/car/socketcan_source.hpp"
#include "dynid/car/vehicle_profile.hpp"

namespace dynid::car {

class CanInterfaceFollower final : public LiveSource {
 public:
  static constexpr double kDeliverySlack = 0.05;  ///< seconds from the kernel's stamp to the socket
  static constexpr std::size_t kMaxFramesPerPoll = 100000;

  /// `spec.type` must be "can"; opens and binds the interface now (SocketCanError if it cannot).
  CanInterfaceFollower(const AuxiliarySourceSpec& spec, const std::string& interface_name, double offset);

  std::vector<AuxiliaryRow> poll() override;
  double complete_until() const override;
  bool ended() const override { return ended_; }
  const std::optional<std::string>& error() const override { return error_; }
  const std::string& name() const override { return spec_.name; }
  std::string origin() const override { return socket_.name(); }
  std::uint64_t rows() const override { return rows_; }

 private:
  const AuxiliarySourceSpec spec_;
  double offset_;
  SocketCanSource socket_;
  SignalMapper mapper_;
  std::vector<ChannelSample> samples_;
  std::vector<double> last_time_;  // per channel, source clock
  double complete_ = 0.0;          // source clock
  bool started_ = false;
  bool ended_ = false;
  std::optional<std::string> error_;
  std::uint64_t rows_ = 0;
};

}  // namespace dynid::car
