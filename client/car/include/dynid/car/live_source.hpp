#pragma once
// LiveSource: an auxiliary source read while the run is live, beside the bus (live_merge.hpp
// merges it): a CSV file or named pipe a logger writes (auxiliary_follower.hpp), or a second CAN
// interface with its own DBC (can_interface_follower.hpp, client/car/src/socketcan).
//
// Contract:
// - poll() never blocks: it returns the rows that arrived since the last call, sorted by time,
//   on the bus's clock, one value per channel the source declares, in SI (NaN: no sample of that
//   channel in the row).
// - complete_until() is the bus time up to which every row of the source has been returned:
//   nothing returned later lies at or before it. -inf before anything is known; +inf once the
//   source has ended or stopped.
// - A failure of the source (bad data, a device gone) stops it: ended() is true, error() says
//   what and where, what came before is kept. A source never stops the bus.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dynid/car/auxiliary_csv.hpp"

namespace dynid::car {

class LiveSource {
 public:
  virtual ~LiveSource() = default;
  virtual std::vector<AuxiliaryRow> poll() = 0;
  virtual double complete_until() const = 0;
  virtual bool ended() const = 0;
  virtual const std::optional<std::string>& error() const = 0;
  /// The source's name in the profile.
  virtual const std::string& name() const = 0;
  /// Where it is read from: the file, or the interface.
  virtual std::string origin() const = 0;
  /// Rows returned so far.
  virtual std::uint64_t rows() const = 0;
};

}  // namespace dynid::car
