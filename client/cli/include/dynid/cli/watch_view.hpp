#pragma once
// WatchView: what `dynid watch --model M` prints of each publication of one model's estimate,
// for an engineer following a run live (issue 16, item 6).
//
// text(): a compact block, one line per parameter: value, std, relative std %, status, and how
// the value moved since the previous publication this view saw (the change, and the change in
// units of the new std: "+12.3 (+0.5 std)"; "new" for the first). A model the source does not
// excite prints its one line (EstimateTable::not_excited) instead. The block ends with a
// newline; line_count() is its number of lines, so a terminal can redraw it in place.
//
// json_line(): the same as one JSON object on one line (JSON lines, for tools): vehicle,
// model, source, revision, rows, not_excited, and per parameter name, unit, value, std,
// relative_std_percent, status, reason, change (null for the first publication) and
// change_in_std.
//
// redraw(): the text block for a terminal: cursor up over the previous block and clear to the
// end of the screen (ANSI "ESC[<n>A ESC[J"), then the new block. For a pipe or a file the
// caller appends text() blocks instead.
#include <map>
#include <string>

#include "dynid/dds/estimate_table.hpp"

namespace dynid::cli {

class WatchView {
 public:
  std::string text(const dds::EstimateTable& table);
  std::string json_line(const dds::EstimateTable& table);
  std::string redraw(const dds::EstimateTable& table);

 private:
  /// The previous values of the table's model (name -> value), then records the new ones.
  std::map<std::string, double> advance(const dds::EstimateTable& table);

  std::map<std::string, std::map<std::string, double>> previous_;  // model -> name -> value
  std::size_t shown_lines_ = 0;
};

/// The number of lines of a block of text (its newlines).
std::size_t line_count(const std::string& text);

}  // namespace dynid::cli
