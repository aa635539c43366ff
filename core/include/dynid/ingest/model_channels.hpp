#pragma once
// What a model of a run reads, and what the run lacks of it: the one rule by which the server
// runs a model or keeps it "not run: the run has no channel ..." (run_processor.hpp), and by
// which dynid-car refuses, at start, a profile whose run could not run one of its models.
//
// Contract:
// - channels_read(): every channel the model reads, in its order without repeats: its own
//   (Model::channels(), optional ones included) and those of the enabled effects (the model's
//   candidate effects, dictionary effects).
// - A run provides a channel it announces, and d_<x> for an announced x: the server derives
//   the derivative of a channel it has (run_processor.hpp). Constants do not stand in for a
//   channel: a model needs its channels whatever constants it is given.
// - channel_gaps(): of the channels read, `missing` are those the model cannot do without (its
//   required ones and every enabled effect's) that the run does not provide; `optional_absent`
//   the optional ones it does not provide (the model runs without them). A model runs on a run
//   iff `missing` is empty.
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "dynid/ingest/run_announcement.hpp"
#include "dynid/model/model.hpp"

namespace dynid::ingest {

std::vector<std::string> channels_read(const model::Model& model, const ModelSpec& spec);

/// True when the run of `announcement` provides `channel` (announced, or derived from one).
bool run_provides(const RunAnnouncement& announcement, std::string_view channel);

struct ChannelGaps {
  std::vector<std::string> missing;
  std::vector<std::string> optional_absent;
};

ChannelGaps channel_gaps(const model::Model& model, const ModelSpec& spec,
                         const std::function<bool(const std::string&)>& provided);

/// "'a', 'b'": channel names quoted, as the server's notes and dynid-car's refusal list them.
std::string quoted_list(const std::vector<std::string>& names);

}  // namespace dynid::ingest
