#pragma once
// StribeckSpeedBank: the Stribeck speed v_s by a bank of accumulators, one per candidate
// (borsotto §3.5 "NL for v_s, linear for the rest" and §8.4: v_s enters mu nonlinearly, so keep
// it out of the parameter vector, fold the same rows into one accumulator per candidate v_s, and
// pick the candidate with the minimum residual norm).
//
// Each candidate is a ClutchSlipModel built from the same constants with stribeck_speed set to
// the candidate; the rows differ only in the Stribeck column. Memory is one (n+1)^2 triangle
// per candidate, so the bank streams like a single accumulator.
#include <memory>
#include <vector>

#include "dynid/ls/accumulator.hpp"
#include "dynid/ls/estimate.hpp"
#include "dynid/model/clutch_slip.hpp"

namespace dynid::model {

class StribeckSpeedBank {
 public:
  /// `candidates`: distinct speeds > 0 (rad/s); `effects` enabled in every candidate model
  /// (stribeck_friction is added when missing). Throws InputError on bad candidates.
  StribeckSpeedBank(const Constants& constants, std::vector<double> candidates,
                    std::vector<std::string> effects = {"stribeck_friction", "viscous_friction"});

  /// Folds the rows of `channels` into every candidate's accumulator.
  void fold(const ChannelSet& channels);

  std::size_t size() const { return models_.size(); }
  double candidate(std::size_t i) const { return *models_.at(i)->stribeck_speed(); }
  const ClutchSlipModel& model(std::size_t i) const { return *models_.at(i); }
  const ls::Accumulator& accumulator(std::size_t i) const { return accumulators_.at(i); }
  const std::vector<std::string>& effects() const { return effects_; }

  /// ||W x - y|| at each candidate's least-squares solution. InputError when nothing was folded.
  std::vector<double> residual_norms() const;
  /// The index of the candidate with the smallest residual norm.
  std::size_t best() const;

 private:
  std::vector<std::unique_ptr<ClutchSlipModel>> models_;
  std::vector<ls::Accumulator> accumulators_;
  std::vector<std::string> effects_;
};

}  // namespace dynid::model
