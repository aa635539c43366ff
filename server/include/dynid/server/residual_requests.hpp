#pragma once
// The residual loop's requests on a stored run (DESIGN.md "Residual loop"; core/residual):
//
//   residual    vehicle*, run*, model*, effects, candidates, format   diagnose: noise floor,
//                                                                     ranked candidates, verdict
//   add-effect  vehicle*, run*, model*, effect*, effects, format      before/after report
//   trace       vehicle*, run*, model*, effects, reference, rounds,    the loop: diagnose, add,
//               format                                                diagnose again (trace.hpp)
//   consistency vehicle*, run*, reference, format                      every announced model
//                                                                     fitted with its effects;
//                                                                     shared parameters and
//                                                                     references compared
//                                                                     (consistency.hpp)
//   iv          vehicle*, run*, model*, effects, format                instrumental variables and
//                                                                     the Durbin-Wu-Hausman test
//                                                                     (iv_fit.hpp)
//
// `effects` (comma list) are the model's declared effects; absent, those the run's announcement
// gives the model; "none", no effect. `candidates` (comma list) restricts the screen. `reference` (repeatable,
// name=value, e.g. mass=1457.5): known values, whose errors the trace reports. `rounds`: effects
// the trace may add (0..10, default 4). format: text (default), json (for tools), or html (the
// self-contained page of report/residual_html.hpp; a trace's page shows its last added effect;
// not for consistency and iv).
//
// The run is replayed from the store (every chunk up to the highest contiguous one), assembled
// and preprocessed offline (ingest/recorded_run.hpp). Pure: no DDS, no store; RunService feeds
// it the run's announcement and chunks. Errors: InputError (a model the announcement does not
// run, an unknown effect, a channel missing) reach the engineer as BAD_REQUEST.
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "dynid/ingest/chunk.hpp"
#include "dynid/ingest/recorded_run.hpp"
#include "dynid/ingest/run_announcement.hpp"
#include "dynid/model/model.hpp"
#include "dynid/residual/iv_fit.hpp"
#include "dynid/residual/simex.hpp"

namespace dynid::server {

struct ResidualRequest {
  std::string model;
  std::optional<std::vector<std::string>> effects;  ///< declared; absent: the announcement's
  std::vector<std::string> candidates;              ///< empty: every candidate
  std::string effect;                               ///< add-effect only
  std::string format = "text";                      ///< text | json | html
  /// residual | add-effect | trace | consistency | iv | simex | export (export_request.hpp)
  std::string kind = "residual";
  std::map<std::string, double> reference;          ///< add-effect, trace, consistency
  int rounds = 4;                                   ///< trace only
  bool series = false;  ///< json of add-effect and trace: the added effect's series row by row
  int part = 1;         ///< export only: which part of an export past a reply's limit (1..N)
};

struct ResidualReply {
  std::string payload;
  std::string payload_format;  ///< "text/plain", "application/json" or "text/html"
};

ResidualReply residual_reply(const ingest::RunAnnouncement& announcement,
                             const std::vector<ingest::Chunk>& chunks, const ResidualRequest& request);

/// What the server judges of one model of a run in the background (--live-residual): the residual
/// loop's verdict (residual::Diagnosis, one line) and the instrumental-variable estimate with its
/// test of least squares' bias (residual::IvFit), each absent when it cannot be had yet.
struct LiveVerdict {
  std::string verdict;    ///< "adequate", "explained", "structure left"; "" when not diagnosed
  std::string statement;  ///< Diagnosis::statement()
  std::optional<residual::IvFit> iv;
  std::optional<residual::SimexFit> simex;
};

/// The instrumental-variable fit of a model on a run, as the `iv` request and the live
/// judgement take it: the run's preprocessing sets the instruments' lag.
residual::IvFit iv_of(const model::Model& model, const std::vector<std::string>& effects,
                      const ingest::RunAnnouncement& announcement,
                      const std::vector<ingest::PreprocessedSegment>& segments);

/// The channel noise SIMEX corrects for on a run (`run` assembled, `segments` =
/// preprocess_offline(run)): measured above the cut-off, or declared by the profile (the
/// announcement's channel_noise). Once per run: every model's fit shares it.
std::vector<residual::ChannelNoise> run_noise(const ingest::RecordedRun& run,
                                              const std::vector<ingest::PreprocessedSegment>& segments);

/// The SIMEX fit of a model on a run with the run's noise (run_noise), as the live judgement
/// takes it: SimexOptions' defaults (seed 1: a stored run gives the same values every time it is
/// fitted).
residual::SimexFit simex_of(const model::Model& model, const std::vector<std::string>& effects,
                            const ingest::RecordedRun& run, const std::vector<ingest::PreprocessedSegment>& segments,
                            const std::vector<residual::ChannelNoise>& noise);

/// The verdict of each of `models` (announced models, with their declared effects) on the run so
/// far: what a server started with --live-residual publishes beside the estimates. A model that
/// can be neither diagnosed nor fitted by IV yet (no row, no valid segment long enough to filter,
/// a noise floor that cannot be measured on so little) is left out, not an error. `diagnose`
/// false: the IV and SIMEX fits only, what the publication rule needs (a closed run's tables
/// without --live-residual: run_service.hpp).
std::map<std::string, LiveVerdict> live_verdicts(const ingest::RunAnnouncement& announcement,
                                                 const std::vector<ingest::Chunk>& chunks,
                                                 const std::vector<std::string>& models,
                                                 bool diagnose = true);

}  // namespace dynid::server
