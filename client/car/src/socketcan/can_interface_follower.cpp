#include "dynid/car/can_interface_follower.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "dynid/error.hpp"

namespace dynid::car {
namespace {

// Checked before any member uses it: the mapper reads the source's own bus profile.
const AuxiliarySourceSpec& can_source(const AuxiliarySourceSpec& spec) {
  if (spec.type != "can" || !spec.bus)
    throw InputError("source '" + spec.name + "': only a CAN source is read from an interface");
  return spec;
}

}  // namespace

CanInterfaceFollower::CanInterfaceFollower(const AuxiliarySourceSpec& spec, const std::string& interface_name,
                                           double offset)
    : spec_(can_source(spec)),
      offset_(offset),
      socket_(interface_name),
      mapper_(*spec_.bus),
      last_time_(spec_.channels.size(), -std::numeric_limits<double>::infinity()) {}

std::vector<AuxiliaryRow> CanInterfaceFollower::poll() {
  std::vector<AuxiliaryRow> out;
  if (ended_) return out;
  const double began = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  can::Frame frame;
  try {
    for (std::size_t n = 0; n < kMaxFramesPerPoll; ++n) {
      const NextStatus status = socket_.next(frame, std::chrono::milliseconds(0));
      if (status == NextStatus::End) {
        ended_ = true;
        break;
      }
      if (status == NextStatus::Timeout) {  // emptied: everything stamped before the slack is in
        complete_ = std::max(complete_, began - kDeliverySlack);
        started_ = true;
        break;
      }
      frame.timestamp = live_timestamp(frame.timestamp);
      samples_.clear();
      mapper_.map(frame, samples_);
      AuxiliaryRow row{frame.timestamp + offset_, std::vector<double>(spec_.channels.size(),
                                                                      std::numeric_limits<double>::quiet_NaN())};
      bool any = false;
      for (const auto& s : samples_) {
        if (!(s.time > last_time_[s.channel])) continue;  // as a replay of the log drops it
        last_time_[s.channel] = s.time;
        row.values[s.channel] = s.value;
        any = true;
      }
      complete_ = std::max(complete_, frame.timestamp);
      started_ = true;
      if (!any) continue;
      ++rows_;
      out.push_back(std::move(row));
    }
  } catch (const std::exception& e) {
    error_ = e.what();
    ended_ = true;
  }
  return out;
}

double CanInterfaceFollower::complete_until() const {
  if (ended_) return std::numeric_limits<double>::infinity();
  return started_ ? complete_ + offset_ : -std::numeric_limits<double>::infinity();
}

}  // namespace dynid::car
