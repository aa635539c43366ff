#pragma once
// The `export` request (`dynid export`): a stored run's preprocessed channels, each model's
// measured side, fitted values and residual on the rows it is fitted on, as one ASAM MDF 4.10
// file (report/run_export.hpp, report/mdf4_writer.hpp); the CLI writes it or turns it into CSV.
//
//   export   vehicle*, run*, model, effects
//
// Without `model`, every model the run announces, each with its declared effects; a model that
// cannot be fitted (a channel missing, no row, a channel the run's health check condemns) is left
// out and named in the file's comment. With `model`, that model (with `effects` when given), and
// the reason as the error when it cannot be fitted. The reply is the file's bytes
// ("application/x-mdf4"); InputError when nothing can be exported or the file is past a reply's
// limit (protocol: 16 MiB), naming the size.
#include <vector>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"
#include "dynid/server/residual_requests.hpp"

namespace dynid::server {

/// `request.model` ("" for every model) and `request.effects` are read; the other fields not.
ResidualReply export_reply(const ingest::RunAnnouncement& announcement,
                           const std::vector<ingest::Chunk>& chunks,
                           const ResidualRequest& request);

}  // namespace dynid::server
