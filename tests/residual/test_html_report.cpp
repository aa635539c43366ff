// The residual loop's HTML report in a real browser (issue 6, item 3): a simulated run with an
// undeclared road grade, screened and compared, written as one self-contained page, opened by
// Debian's headless Chromium. The page marks how many of its images the browser decoded
// (residual_html.hpp); the test reads the rendered DOM and checks all of them, and keeps a
// screenshot. Chromium is installed by deploy/setup.sh (deploy/packages.txt): without it this
// test fails, it does not skip.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <unistd.h>

#include "dynid/model/registry.hpp"
#include "dynid/report/residual_html.hpp"
#include "dynid/residual/diagnosis.hpp"
#include "residual_test_support.hpp"
#include "sim_product_path.hpp"
#include "sim_test_support.hpp"

namespace dynid::residual {
namespace {

namespace fs = std::filesystem;

std::string run_command(const std::string& command) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.append(buffer, n);
  ::pclose(pipe);
  return out;
}

std::string chromium() {
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (fs::exists(p)) return p;
  return "";
}

TEST(HtmlReport, OpensInHeadlessChromiumWithEveryPlotDecoded) {
  const std::string browser = chromium();
  ASSERT_FALSE(browser.empty()) << "Chromium is not installed (deploy/setup.sh installs the package 'chromium')";
  const std::string scenario = sim::test::load_scenario_text("acceleration.toml") +
                               "\n[road]\ngrade = [[0.0, 0.0], [60.0, 0.04], [160.0, -0.03], [260.0, 0.05], "
                               "[380.0, -0.02], [520.0, 0.03], [5000.0, 0.0]]\n";
  const sim::Run run = sim::test::run(scenario, 71);
  const ingest::ModelSpec spec = sim::test::model_spec("longitudinal_wheel", {});
  const test::ProcessedRun processed = test::process(run, spec, true);
  const auto model = model::make_model(spec.model, spec.constants);
  const double rate = processed.announcement.sample_rate_hz;
  const int odmf = processed.announcement.preprocessing.odmf;
  const ScreenResult screen = screen_effects(*model, {}, processed.segments, rate, odmf);
  ASSERT_NE(screen.best(), nullptr);
  const EffectComparison cmp = compare_effect(*model, {}, screen.best()->effect, processed.segments, rate, odmf);

  const fs::path dir = fs::temp_directory_path() / ("dynid-html-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path page = dir / "report.html";
  const Diagnosis diagnosis = diagnose(*model, {}, processed.recorded);
  report::HtmlReportInput input{"simulated acceleration run with a road grade", &screen, &cmp};
  input.diagnosis = &diagnosis;
  const std::string html = report::residual_html(input);
  // The correlation plot with its bounds and the floor at every time scale (with the diagnosis).
  EXPECT_NE(html.find("Cross-correlation of the residual of group longitudinal"), std::string::npos);
  EXPECT_NE(html.find("over its noise floor at every time scale"), std::string::npos);
  EXPECT_NE(html.find("<h2>Diagnosis</h2>"), std::string::npos);
  std::ofstream(page) << html;
  const std::string flags = " --headless --no-sandbox --disable-gpu --hide-scrollbars --virtual-time-budget=5000 ";
  const std::string dom =
      run_command(browser + flags + "--dump-dom 'file://" + page.string() + "' 2>/dev/null");
  const fs::path shot = DYNID_REPORT_SCREENSHOT;
  std::error_code ignored;
  fs::remove(shot, ignored);
  (void)run_command(browser + flags + "--window-size=1100,3700 --screenshot='" + shot.string() + "' 'file://" +
                    page.string() + "' >/dev/null 2>&1");
  fs::remove_all(dir, ignored);

  std::smatch m;
  ASSERT_TRUE(std::regex_search(dom, m, std::regex("data-images=\"([0-9]+)/([0-9]+)\"")))
      << "the page did not report its images; DOM starts: " << dom.substr(0, 300);
  std::printf("Chromium decoded %s of %s images; screenshot %s\n", m[1].str().c_str(), m[2].str().c_str(),
              shot.c_str());
  EXPECT_EQ(m[1].str(), m[2].str());
  // Residual against time, against the effect, spectrum, correlations, the floor's scales.
  EXPECT_GE(std::stoi(m[2].str()), 5);
  ASSERT_TRUE(fs::exists(shot));
  EXPECT_GT(fs::file_size(shot), 20000U);
}

// An added step located by the screen is marked on the residual plots: its time and 95 % set
// in the caption (the shaded set and the line are drawn by the same gnuplot commands).
TEST(HtmlReport, MarksALocatedStepOnTheResidualPlots) {
  const sim::Run run = sim::test::run(sim::test::load_scenario_text("acceleration.toml"), 72);
  const ingest::ModelSpec spec = sim::test::model_spec("longitudinal_wheel", {});
  const test::ProcessedRun processed = test::process(run, spec, true);
  const auto model = model::make_model(spec.model, spec.constants);
  const double rate = processed.announcement.sample_rate_hz;
  const int odmf = processed.announcement.preprocessing.odmf;
  const EffectComparison cmp = compare_effect(*model, {}, "step:mass@20s", processed.segments, rate, odmf);
  CandidateScore located;
  located.effect = "step:mass@20s";
  located.located_from_s = 18.5;
  located.located_to_s = 21.25;
  const std::string page = report::residual_html({"a located step", nullptr, &cmp, &located});
  EXPECT_NE(page.find("the located step at 20 s (line), its 95 % set 18.50-21.25 s (shaded)"), std::string::npos);
  located.effect = "drift:mass";  // not a step: nothing to mark
  EXPECT_EQ(report::residual_html({"a drift", nullptr, &cmp, &located}).find("located step"), std::string::npos);
}

}  // namespace
}  // namespace dynid::residual
