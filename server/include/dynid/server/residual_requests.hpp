#pragma once
// The residual loop's requests on a stored run (DESIGN.md "Residual loop"; core/residual):
//
//   residual    vehicle*, run*, model*, effects, candidates, format   rank the candidate effects
//   add-effect  vehicle*, run*, model*, effect*, effects, format      before/after report
//
// `effects` (comma list) are the model's declared effects; absent, those the run's announcement
// gives the model. `candidates` (comma list) restricts the screen. format: text (default),
// html (the self-contained page of report/residual_html.hpp) or json is refused (the report is
// for people; the estimate tables are the machine-readable output).
//
// The run is replayed from the store (every chunk up to the highest contiguous one), assembled
// and preprocessed offline (ingest/recorded_run.hpp). Pure: no DDS, no store; RunService feeds
// it the run's announcement and chunks. Errors: InputError (a model the announcement does not
// run, an unknown effect, a channel missing) reach the engineer as BAD_REQUEST.
#include <optional>
#include <string>
#include <vector>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"

namespace dynid::server {

struct ResidualRequest {
  std::string model;
  std::optional<std::vector<std::string>> effects;  ///< declared; absent: the announcement's
  std::vector<std::string> candidates;              ///< empty: every candidate
  std::string effect;                               ///< add-effect only
  std::string format = "text";                      ///< text | html
};

struct ResidualReply {
  std::string payload;
  std::string payload_format;  ///< "text/plain" or "text/html"
};

ResidualReply residual_reply(const ingest::RunAnnouncement& announcement,
                             const std::vector<ingest::Chunk>& chunks, const ResidualRequest& request);

}  // namespace dynid::server
