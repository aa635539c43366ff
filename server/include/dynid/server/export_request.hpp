#pragma once
// The `export` request (`dynid export`): a stored run's preprocessed channels, each model's
// measured side, fitted values and residual on the rows it is fitted on, as one ASAM MDF 4.10
// file (report/run_export.hpp, report/mdf4_writer.hpp); the CLI writes it or turns it into CSV.
//
//   export   vehicle*, run*, model, effects, part
//
// Without `model`, every model the run announces, each with its declared effects; a model that
// cannot be fitted (a channel missing, no row, a channel the run's health check condemns) is left
// out and named in the file's comment. With `model`, that model (with `effects` when given), and
// the reason as the error when it cannot be fitted. The reply is the file's bytes,
// "application/x-mdf4; part=K/N": an export past a reply's limit (protocol: 16 MiB) comes in N
// files of whole tables (report::export_parts), `part` K (default 1) asking for one, each with
// the whole export's comment; the CLI asks for every part and joins them. InputError when
// nothing can be exported, a single table is past the limit, or `part` is not one of 1..N.
#include <vector>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/run_announcement.hpp"
#include "dynid/server/residual_requests.hpp"

namespace dynid::server {

/// `request.model` ("" for every model), `request.effects` and `request.part` are read; the other
/// fields not.
ResidualReply export_reply(const ingest::RunAnnouncement& announcement,
                           const std::vector<ingest::Chunk>& chunks,
                           const ResidualRequest& request);

}  // namespace dynid::server
