#include "dynid/model/channel_set.hpp"

#include <cmath>

#include "dynid/error.hpp"

namespace dynid::model {

ChannelSet::ChannelSet(double sample_period, Eigen::Index samples)
    : sample_period_(sample_period), samples_(samples) {
  if (!std::isfinite(sample_period) || sample_period <= 0.0)
    throw InputError("channel set: sample period " + std::to_string(sample_period) +
                     " s is not a positive finite number");
  if (samples < 0)
    throw InputError("channel set: negative sample count " + std::to_string(samples));
  valid_.assign(static_cast<std::size_t>(samples), true);
}

void ChannelSet::add(const std::string& name, const std::string& unit, Eigen::VectorXd values) {
  if (name.empty()) throw InputError("channel set: a channel name is empty");
  if (has(name)) throw InputError("channel set: duplicate channel '" + name + "'");
  if (values.size() != samples_)
    throw InputError("channel set: channel '" + name + "' has " + std::to_string(values.size()) +
                     " samples, the set has " + std::to_string(samples_));
  // The usual all-finite channel is checked at vector speed; only one with a NaN/Inf is looked
  // at sample by sample, where the validity flags decide.
  if (!values.allFinite())
    for (Eigen::Index k = 0; k < samples_; ++k)
      if (valid(k) && !std::isfinite(values(k)))
        throw InputError("channel set: channel '" + name + "' is not finite at sample " +
                         std::to_string(k) + " (mark the stretch invalid first)");
  channels_.emplace(name,
                    Channel{unit, std::make_shared<const Eigen::VectorXd>(std::move(values))});
}

void ChannelSet::replace(const std::string& name, Eigen::VectorXd values) {
  const auto it = channels_.find(name);
  if (it == channels_.end()) throw InputError("channel set: no channel '" + name + "' to replace");
  Channel old = std::move(it->second);
  channels_.erase(it);
  try {
    add(name, old.unit, std::move(values));  // the same checks as a new channel
  } catch (...) {
    channels_.emplace(name, std::move(old));  // the set unchanged
    throw;
  }
}

namespace {
thread_local ChannelLookupProbe* active_lookup_probe = nullptr;
}  // namespace

ChannelLookupProbe::ChannelLookupProbe() : outer_(active_lookup_probe) {
  active_lookup_probe = this;
}

ChannelLookupProbe::~ChannelLookupProbe() {
  active_lookup_probe = outer_;
}

void ChannelLookupProbe::record(const std::string& name) {
  looked_up_.insert(name);
  if (outer_ != nullptr) outer_->record(name);
}

const Eigen::VectorXd& ChannelSet::operator[](const std::string& name) const {
  if (active_lookup_probe != nullptr) active_lookup_probe->record(name);
  const auto it = channels_.find(name);
  if (it == channels_.end()) throw InputError("channel set: no channel '" + name + "'");
  return *it->second.values;
}

const std::string& ChannelSet::unit(const std::string& name) const {
  const auto it = channels_.find(name);
  if (it == channels_.end()) throw InputError("channel set: no channel '" + name + "'");
  return it->second.unit;
}

std::vector<std::string> ChannelSet::names() const {
  std::vector<std::string> out;
  out.reserve(channels_.size());
  for (const auto& [name, channel] : channels_) out.push_back(name);
  return out;
}

void ChannelSet::invalidate(Eigen::Index first, Eigen::Index count) {
  if (first < 0 || count < 0 || first > samples_ - count)
    throw InputError("channel set: invalid range [" + std::to_string(first) + ", " +
                     std::to_string(first) + " + " + std::to_string(count) + ") of " +
                     std::to_string(samples_) + " samples");
  for (Eigen::Index k = first; k < first + count; ++k) valid_[static_cast<std::size_t>(k)] = false;
}

Eigen::Index ChannelSet::valid_count() const {
  Eigen::Index n = 0;
  for (const bool v : valid_) n += v ? 1 : 0;
  return n;
}

}  // namespace dynid::model
