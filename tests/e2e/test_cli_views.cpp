// What the dynid CLI prints for people and tools, without DDS (issue 16, items 1, 4 and 6): the
// compact view of `dynid watch --model` (how a value moved, the in-place redraw, JSON lines) and
// `dynid status` as text, the estimate table of a model the run does not excite, and the
// excitation report (what a run identifies, and the manoeuvres that would bring the rest); and
// what `dynid export` writes (issue 38, item 5): the server's MDF4 file read back by the
// product's reader, and the CSV table made from it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "dynid/can/mdf4.hpp"
#include "dynid/cli/export_file.hpp"
#include "dynid/cli/shard_replies.hpp"
#include "dynid/cli/watch_view.hpp"
#include "dynid/error.hpp"
#include "dynid/report/estimate_report.hpp"
#include "dynid/report/excitation_report.hpp"
#include "dynid/report/mdf4_writer.hpp"
#include "dynid/report/run_export.hpp"
#include "dynid/report/text_wrap.hpp"

namespace dynid::test {
namespace {

dds::EstimateTable table(std::uint64_t revision, double mass, double mass_std) {
  dds::EstimateTable t;
  t.vehicle = "car";
  t.model = "longitudinal_wheel";
  t.source = "run-1";
  t.revision = revision;
  t.rows = 100 * revision;
  t.parameters.push_back({"mass", "kg", mass, mass_std, 100.0 * mass_std / mass,
                          ls::ParameterStatus::kIdentified, "", ""});
  t.parameters.push_back({"SCx", "m^2", -6.7, 0.96, 14.3, ls::ParameterStatus::kNotExcited, "",
                          "not excited: std 0.96 m^2 >= 0.7 m^2"});
  return t;
}

TEST(WatchView, OneLinePerParameterWithHowItMoved) {
  cli::WatchView view;
  const std::string first = view.text(table(1, 1500.0, 10.0));
  EXPECT_NE(first.find("car / longitudinal_wheel  source run-1, revision 1, rows 100"), std::string::npos) << first;
  EXPECT_NE(first.find("moved since last"), std::string::npos) << first;
  EXPECT_NE(first.find("identified"), std::string::npos) << first;
  EXPECT_NE(first.find("not excited"), std::string::npos) << first;
  EXPECT_NE(first.find("new"), std::string::npos) << first;
  EXPECT_EQ(cli::line_count(first), 4u) << first;  // heading, column names, two parameters
  const std::string second = view.text(table(2, 1480.0, 5.0));
  EXPECT_NE(second.find("-20 (-4 std)"), std::string::npos) << second;  // moved 20 kg = 4 new std
  EXPECT_NE(second.find("  0\n"), std::string::npos) << second;         // SCx did not move
}

TEST(WatchView, AModelTheRunDoesNotExciteIsOneLine) {
  cli::WatchView view;
  auto t = table(1, 160.0, 24.0);
  t.not_excited = "needs d_vx (accelerate, brake)";
  const std::string text = view.text(t);
  EXPECT_EQ(cli::line_count(text), 2u) << text;
  EXPECT_NE(text.find("  not excited by this run: needs d_vx (accelerate, brake)\n"), std::string::npos) << text;
  EXPECT_EQ(text.find("160"), std::string::npos) << text;  // no number that reads as an estimate
}

TEST(WatchView, RedrawMovesTheCursorOverThePreviousBlock) {
  cli::WatchView view;
  const std::string first = view.redraw(table(1, 1500.0, 10.0));
  EXPECT_EQ(first.find('\x1b'), std::string::npos) << first;
  const std::string second = view.redraw(table(2, 1490.0, 10.0));
  EXPECT_EQ(second.rfind("\x1b[4A\x1b[J", 0), 0u) << second;
  EXPECT_EQ(cli::line_count(second), 4u);
}

TEST(WatchView, JsonLinesCarryTheStatusAndTheMove) {
  cli::WatchView view;
  const std::string first = view.json_line(table(1, 1500.0, 10.0));
  const std::string second = view.json_line(table(2, 1480.0, 5.0));
  ASSERT_EQ(cli::line_count(first), 1u);
  ASSERT_EQ(first.back(), '\n');
  const auto a = nlohmann::json::parse(first);
  const auto b = nlohmann::json::parse(second);
  EXPECT_EQ(a["model"], "longitudinal_wheel");
  EXPECT_EQ(a["revision"], 1);
  EXPECT_TRUE(a["parameters"][0]["change"].is_null());
  EXPECT_EQ(a["parameters"][1]["status"], "not excited");
  EXPECT_EQ(a["parameters"][1]["reason"], "not excited: std 0.96 m^2 >= 0.7 m^2");
  EXPECT_DOUBLE_EQ(b["parameters"][0]["change"].get<double>(), -20.0);
  EXPECT_DOUBLE_EQ(b["parameters"][0]["change_in_std"].get<double>(), -4.0);
  EXPECT_EQ(b["not_excited"], "");
}

// `dynid estimates` (and every table of the server's replies) prints the same one line.
TEST(EstimateText, AModelTheRunDoesNotExciteIsOneLineAndItsJsonKeepsTheNumbers) {
  auto t = table(3, 160.0, 24.0);
  t.not_excited = "needs d_vx (accelerate, brake)";
  const std::string text = report::format_estimate_text(t);
  EXPECT_EQ(cli::line_count(text), 2u) << text;
  EXPECT_NE(text.find("  not excited by this run: needs d_vx (accelerate, brake) (300 rows; --json has the numbers)"),
            std::string::npos) << text;
  const auto json = nlohmann::json::parse(report::estimate_json(t));
  EXPECT_EQ(json["not_excited"], "needs d_vx (accelerate, brake)");
  EXPECT_DOUBLE_EQ(json["parameters"][0]["value"].get<double>(), 160.0);
  EXPECT_EQ(json["parameters"][1]["status"], "not excited");

  t.not_excited.clear();
  const std::string table_text = report::format_estimate_text(t);
  EXPECT_NE(table_text.find("not excited        not excited: std 0.96 m^2 >= 0.7 m^2"), std::string::npos)
      << table_text;  // status, then its reason
}

// The answer before the table: what the live verdict says the model lacks, by the explaining
// effect's name, then how many parameters the run identifies.
TEST(EstimateText, TheAnswerComesFirstInOneLine) {
  auto t = table(3, 160.0, 24.0);
  EXPECT_NE(report::format_estimate_text(t).find("\n  answer: 1 of 2 parameters identified\n"),
            std::string::npos)
      << report::format_estimate_text(t);
  t.residual_verdict = "explained";
  t.residual_statement =
      "explained: above the noise floor (longitudinal residual RMS 287.6, noise floor 86.36 (ratio "
      "of squares 11.1, "
      "at the floor up to 1.58)); road_grade (physics) explains it: held-out RMS -67.1 %, HAC Wald "
      "p = 0 < 0.00016";
  t.residual_through = 29;
  const std::string text = report::format_estimate_text(t);
  EXPECT_NE(text.find("\n  answer: lacks road_grade; 1 of 2 parameters identified\n"),
            std::string::npos)
      << text;
  EXPECT_NE(
      text.find("and 1 more finding (`dynid residual --model longitudinal_wheel`, or --json)"),
      std::string::npos)
      << text;
  t.residual_verdict = "adequate";
  t.residual_statement =
      "adequate: the residual of longitudinal_wheel is at the noise floor (longitudinal ...)";
  EXPECT_NE(report::format_estimate_text(t).find(
                "answer: lacks nothing its noise would not hide; 1 of 2"),
            std::string::npos);
  t.residual_verdict = "structure left";
  t.residual_statement = "structure left that no candidate explains: above the noise floor (...)";
  EXPECT_NE(report::format_estimate_text(t).find(
                "answer: lacks something no candidate effect explains in full"),
            std::string::npos);
}

dds::Reply status_reply(std::uint32_t shard, std::uint32_t count, const std::string& payload) {
  dds::Reply r;
  r.payload_format = "application/json";
  r.payload = payload;
  r.shard = shard;
  r.shard_count = count;
  return r;
}

// Every line within the width, every word kept and whole, the continuation indented; a word
// longer than a line stands alone.
TEST(TextWrap, LinesFitTheWidthAndKeepEveryWord) {
  std::string text;
  for (int k = 0; k < 60; ++k)
    text += (k ? " " : "") + std::string(static_cast<std::size_t>(1 + k % 9), 'a' + k % 26);
  const std::string long_word(120, 'x');
  const std::string out = report::wrap_text("  head: ", text + " " + long_word + " end", 4);
  std::istringstream lines(out);
  std::string line, words;
  for (int n = 0; std::getline(lines, line); ++n) {
    if (line.find(long_word) == std::string::npos) {
      EXPECT_LE(line.size(), report::kTextWidth) << line;
    }
    if (n > 0) {
      EXPECT_EQ(line.rfind("    ", 0), 0u) << line;
    }
    words += (n ? " " : "") + line.substr(n == 0 ? 8 : 4);
  }
  EXPECT_EQ(words, text + " " + long_word + " end");
  EXPECT_EQ(out.back(), '\n');
  EXPECT_EQ(report::wrap_text("short: ", "one line", 4), "short: one line\n");
}

// A statement's clauses split at "; " outside parentheses; each further one on its own line.
TEST(TextWrap, ClausesSplitOutsideParentheses) {
  const std::string statement =
      "explained: above the noise floor (a residual RMS 1, noise floor 2; b residual RMS 3); "
      "road_grade explains "
      "it; x refused: why (p; q)";
  const std::vector<std::string> parts = report::clauses(statement);
  ASSERT_EQ(parts.size(), 3u);
  EXPECT_EQ(parts[0],
            "explained: above the noise floor (a residual RMS 1, noise floor 2; b residual RMS 3)");
  EXPECT_EQ(parts[2], "x refused: why (p; q)");
  EXPECT_EQ(report::wrap_clauses("diagnosis: ", statement, 4),
            "diagnosis: " + parts[0] + "\n    road_grade explains it\n    x refused: why (p; q)\n");
}

TEST(StatusText, OneCounterPerLineWithWhatItCounts) {
  cli::ShardReplies one;
  one.add(status_reply(0, 0, R"({"chunks_stored":40,"chunks_folded":40,"future_counter":3})"));
  const std::string text = cli::status_text(one);
  EXPECT_EQ(text.find('{'), std::string::npos) << text;
  EXPECT_NE(text.find("chunks stored durably (acknowledged)"), std::string::npos) << text;
  EXPECT_NE(text.find("chunks folded into estimates"), std::string::npos) << text;
  EXPECT_NE(text.find("future_counter"), std::string::npos) << text;  // unknown: by its name
  EXPECT_EQ(cli::line_count(text), 3u) << text;

  cli::ShardReplies two;
  two.add(status_reply(1, 2, R"({"chunks_stored":7})"));
  const std::string partial = cli::status_text(two);
  EXPECT_NE(partial.find("shard 1/2\n  chunks stored durably"), std::string::npos) << partial;
  EXPECT_NE(partial.find("shard 0/2: did not answer"), std::string::npos) << partial;
}

// Issue 20: servers sharing one PostgreSQL store answer as shard 0/1 with who holds what; the
// text is the counters, then one line per server: its id, how many vehicles, which.
TEST(StatusText, ServersOfASharedStoreAsATable) {
  cli::ShardReplies one;
  one.add(status_reply(0, 1, R"({"chunks_stored":40,"server":"b-2","servers":[)"
                             R"({"id":"a-1","vehicles":["car-1","car-3"]},{"id":"b-2","vehicles":[]}]})"));
  const std::string text = cli::status_text(one);
  EXPECT_EQ(text.find('{'), std::string::npos) << text;
  EXPECT_NE(text.find("chunks stored durably (acknowledged)"), std::string::npos) << text;
  EXPECT_NE(text.find("answered by b-2\nSERVER  VEHICLES\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\na-1     2 car-1 car-3\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nb-2     0\n"), std::string::npos) << text;
}

// Issue 16 item 4: per model what the run identifies and what it cannot with the signal to move;
// then each manoeuvre once, with every parameter of every model it would bring.
TEST(ExcitationReport, GroupsWhatTheRunCannotIdentifyByTheManoeuvreThatWould) {
  report::ExcitationReport r{"car", "sine-steer", {}, {"clutch_slip: not run: no clutch_clamp_load"}};
  auto wheel = table(1, 160.0, 24.0);  // mass 15 % (poorly identified), SCx not excited
  wheel.parameters[0].status = ls::ParameterStatus::kPoorlyIdentified;
  wheel.parameters[0].relative_std_percent = 15.0;
  auto engine = wheel;
  engine.model = "longitudinal_engine";
  engine.parameters[1].status = ls::ParameterStatus::kImplausible;
  engine.parameters[1].reason = "-6.7 m^2 outside (0, 2]";
  const std::string accelerate = "d_vx (accelerate, brake)", coast = "vx over a wide range (coast down from high speed)";
  r.models = {{wheel, {accelerate, coast}}, {engine, {accelerate, coast}}};

  const auto needs = report::manoeuvre_needs(r);
  ASSERT_EQ(needs.size(), 2u);
  EXPECT_EQ(needs[0].excited_by, accelerate);
  EXPECT_EQ(needs[0].poorly_identified, (std::vector<std::string>{"longitudinal_wheel.mass", "longitudinal_engine.mass"}));
  EXPECT_EQ(needs[1].excited_by, coast);
  // An implausible value is a model error, not a manoeuvre's: not listed under one.
  EXPECT_EQ(needs[1].not_excited, (std::vector<std::string>{"longitudinal_wheel.SCx"}));

  const std::string text = report::format_excitation_text(r);
  EXPECT_NE(text.find("car / run sine-steer: what this run identifies\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  longitudinal_wheel: identifies 0 of 2\n"), std::string::npos) << text;
  EXPECT_NE(text.find("    not excited: SCx (needs " + coast + ")\n"), std::string::npos) << text;
  EXPECT_NE(text.find("    poorly identified: mass (15 %; needs more " + accelerate + ")\n"), std::string::npos) << text;
  EXPECT_NE(text.find("implausible, a model error or a missing effect rather than the manoeuvre (dynid residual): SCx"),
            std::string::npos) << text;
  EXPECT_NE(text.find("  clutch_slip: not run: no clutch_clamp_load\n"), std::string::npos) << text;
  EXPECT_NE(text.find("  " + coast + ": longitudinal_wheel.SCx\n"), std::string::npos) << text;

  const auto json = nlohmann::json::parse(report::excitation_json(r));
  EXPECT_EQ(json["models"][1]["parameters"][1]["status"], "implausible");
  EXPECT_EQ(json["models"][0]["parameters"][1]["excited_by"], coast);
  EXPECT_EQ(json["manoeuvres"][0]["poorly_identified"].size(), 2u);
}

TEST(ExcitationReport, SaysSoWhenEveryParameterIsIdentified) {
  report::ExcitationReport r{"car", "r", {{table(1, 1500.0, 3.0), {"d_vx (accelerate, brake)", ""}}}, {}};
  r.models[0].table.parameters[1].status = ls::ParameterStatus::kIdentified;
  const std::string text = report::format_excitation_text(r);
  EXPECT_NE(text.find("identifies 2 of 2: mass, SCx"), std::string::npos) << text;
  EXPECT_NE(text.find("Every parameter this run can excite is identified."), std::string::npos) << text;
}

// Two tables on one grid, as an export has them: a channel both hold, times where only one has a
// row, a value without a unit, a NaN, and values that need all 17 digits.
report::Mdf4Document two_tables() {
  report::Mdf4Document d;
  d.start_ns = 1700000000123456789;
  d.comment = "dynid export of run car/r1: models a, b; not exported: c: <no row>";
  d.tables.push_back({"a.force",
                      "a with no effect",
                      {0.08, 0.16, 0.24},
                      {{"vx", "m/s", "preprocessed", {10.0, 10.1, 1.0 / 3.0}},
                       {"a.force.residual", "N", "", {0.1, -0.2, std::nan("")}}}});
  d.tables.push_back(
      {"b.yaw",
       "",
       {0.16, 0.32},
       {{"vx", "m/s", "", {10.1, 10.2}}, {"gain", "", "dimensionless", {2.0 / 7.0, -1e-300}}}});
  return d;
}

can::Mdf4File read_back(const std::string& bytes) {
  return can::Mdf4File(std::vector<std::uint8_t>(bytes.begin(), bytes.end()), "export");
}

TEST(Export, TheWrittenFileReadsBackThroughTheProductsReader) {
  const report::Mdf4Document d = two_tables();
  const can::Mdf4File file = read_back(report::write_mdf4(d));
  EXPECT_EQ(file.version(), "4.10");
  EXPECT_FALSE(file.unfinalized());
  EXPECT_EQ(file.start_ns(), d.start_ns);
  EXPECT_EQ(file.comment(), d.comment);
  ASSERT_EQ(file.data_groups().size(), d.tables.size());
  for (std::size_t t = 0; t < d.tables.size(); ++t) {
    const report::Mdf4Table& table = d.tables[t];
    ASSERT_EQ(file.data_groups()[t].groups.size(), 1U);
    const can::Mdf4ChannelGroup& group = file.data_groups()[t].groups[0];
    EXPECT_EQ(group.name, table.name);
    EXPECT_EQ(group.cycle_count, table.time_s.size());
    ASSERT_NE(group.master(), nullptr);
    EXPECT_EQ(group.master()->name, "time");
    EXPECT_EQ(group.master()->unit, "s");
    std::vector<std::string> names;
    for (const report::Mdf4Column& column : table.columns) {
      ASSERT_NE(group.find(column.name), nullptr) << column.name;
      EXPECT_EQ(group.find(column.name)->unit, column.unit);
      names.push_back(column.name);
    }
    const can::Mdf4Signals signals = file.read_signals(t, 0, names);
    EXPECT_EQ(signals.time, table.time_s);
    for (std::size_t c = 0; c < names.size(); ++c)
      for (std::size_t k = 0; k < table.time_s.size(); ++k) {
        const double written = table.columns[c].values[k], read = signals.values[c][k];
        if (std::isnan(written))
          EXPECT_TRUE(std::isnan(read));
        else
          EXPECT_EQ(read, written) << names[c] << " at " << k;  // bit for bit: float64 stored
      }
  }
}

TEST(Export, TheCsvTableJoinsTheGroupsOnTheirTimes) {
  const can::Mdf4File file = read_back(report::write_mdf4(two_tables()));
  std::istringstream csv(cli::export_csv(file));
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "time [s],vx [m/s],a.force.residual [N],gain");
  std::vector<std::vector<std::string>> rows;
  while (std::getline(csv, line)) {
    std::vector<std::string> cells;
    std::istringstream fields(line + ",");
    for (std::string cell; std::getline(fields, cell, ',');) cells.push_back(cell);
    rows.push_back(cells);
  }
  ASSERT_EQ(rows.size(), 4U);  // 0.08, 0.16 (both tables), 0.24, 0.32
  const auto value = [](const std::string& cell) { return std::strtod(cell.c_str(), nullptr); };
  EXPECT_EQ(value(rows[0][0]), 0.08);
  EXPECT_EQ(rows[0][3], "");  // b has no row at 0.08
  EXPECT_EQ(value(rows[1][1]), 10.1);
  EXPECT_EQ(value(rows[1][2]), -0.2);
  EXPECT_EQ(value(rows[1][3]), 2.0 / 7.0);  // the shortest text that reads back to the double
  EXPECT_EQ(value(rows[2][1]), 1.0 / 3.0);
  EXPECT_TRUE(std::isnan(value(rows[2][2])));
  EXPECT_EQ(rows[3][2], "");  // a has no row at 0.32
  EXPECT_EQ(value(rows[3][3]), -1e-300);
  const std::string summary = cli::export_summary(file);
  EXPECT_NE(summary.find("a.force: 3 rows from 0.08 to 0.24 s, 2 columns"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("not exported: c: <no row>"), std::string::npos) << summary;
}

TEST(Export, AColumnOfTheWrongLengthOrARepeatedNameIsTheCallersBug) {
  report::Mdf4Document d = two_tables();
  d.tables[1].columns[0].values.pop_back();
  EXPECT_THROW(report::write_mdf4(d), std::invalid_argument);
  d = two_tables();
  d.tables[0].columns[1].name = "vx";
  EXPECT_THROW(report::write_mdf4(d), std::invalid_argument);
}

// An export past a reply's limit comes in parts of whole tables, each file within the limit, and
// the CLI joins them into the file the server would have written, byte for byte.
TEST(Export, PartsPastAReplysLimitJoinIntoTheWholeFile) {
  report::Mdf4Document d = two_tables();
  const std::string whole = report::write_mdf4(d);
  const std::size_t limit = whole.size() - 1;
  const auto parts = report::export_parts(d.tables, limit, d.comment);
  ASSERT_EQ(parts.size(), 2U);
  std::vector<can::Mdf4File> files;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const std::string bytes = report::write_mdf4({d.start_ns, d.comment, parts[k]});
    EXPECT_LE(bytes.size(), limit);
    files.push_back(read_back(bytes));
  }
  EXPECT_EQ(cli::joined_export(files), whole);
  EXPECT_EQ(report::export_parts(d.tables, whole.size(), d.comment).size(), 1U);
  EXPECT_THROW(report::export_parts(d.tables, 400, d.comment),
               InputError);  // a table alone is more
  EXPECT_EQ(cli::part_count("application/x-mdf4; part=1/3"), 3U);
  EXPECT_EQ(cli::part_count("application/x-mdf4"), 1U);
  EXPECT_THROW(cli::part_count("application/x-mdf4; part=1/2000000"), std::runtime_error);
}

}  // namespace
}  // namespace dynid::test
