#pragma once
// ChannelSet: preprocessed measurement channels of one run on a uniform time grid, the input of
// every model (DYCARO's script_obs reads the output of script_filtre).
//
// Contract: every channel has the same number of samples; values are SI (conversions happen
// where signals enter: the car-side profile); `valid(k)` is false for samples inside a detected
// gap or bad stretch, and models leave such rows out. Channel names follow the catalogue in
// docs/CHANNELS.md. Adding a channel of the wrong length, a duplicate name, or a NaN/Inf at a
// sample marked valid throws InputError naming the channel and sample. A channel's values never
// change once added (replace swaps in new ones), so copies of a set share them: copying a set, as
// the residual loop does for every candidate and noise draw, costs its names, not its samples.
//
// ChannelLookupProbe lists the channels a computation can have read: while one is alive on a
// thread, every lookup of a channel's values (operator[]) on that thread is recorded. A channel
// not in the list was never seen, so the computation's result cannot depend on its values.
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace dynid::model {

/// Records the channels whose values are looked up on this thread, while alive (above); probes
/// nest, and a lookup is recorded by every live one.
class ChannelLookupProbe {
 public:
  ChannelLookupProbe();
  ~ChannelLookupProbe();
  ChannelLookupProbe(const ChannelLookupProbe&) = delete;
  ChannelLookupProbe& operator=(const ChannelLookupProbe&) = delete;
  const std::set<std::string>& looked_up() const { return looked_up_; }
  void record(const std::string& name);

 private:
  std::set<std::string> looked_up_;
  ChannelLookupProbe* outer_;
};

class ChannelSet {
 public:
  /// An empty set of `samples` samples every `sample_period` seconds (> 0), all valid.
  ChannelSet(double sample_period, Eigen::Index samples);

  double sample_period() const { return sample_period_; }
  Eigen::Index samples() const { return samples_; }

  /// Adds a channel (SI unit given for documentation and checks).
  void add(const std::string& name, const std::string& unit, Eigen::VectorXd values);
  bool has(const std::string& name) const { return channels_.count(name) > 0; }
  /// Replaces the values of a channel the set has (same checks as add, InputError when absent).
  void replace(const std::string& name, Eigen::VectorXd values);
  /// The values of a channel; throws InputError naming the missing channel.
  const Eigen::VectorXd& operator[](const std::string& name) const;
  const std::string& unit(const std::string& name) const;
  std::vector<std::string> names() const;

  /// Marks samples [first, first + count) invalid (a gap, a NaN run, a saturated sensor...).
  void invalidate(Eigen::Index first, Eigen::Index count);
  bool valid(Eigen::Index k) const { return valid_[static_cast<std::size_t>(k)]; }
  Eigen::Index valid_count() const;

 private:
  struct Channel {
    std::string unit;
    std::shared_ptr<const Eigen::VectorXd> values;  // shared by copies of the set
  };
  double sample_period_;
  Eigen::Index samples_;
  std::map<std::string, Channel> channels_;
  std::vector<bool> valid_;
};

}  // namespace dynid::model
