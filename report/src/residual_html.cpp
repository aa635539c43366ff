#include "dynid/report/residual_html.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "dynid/report/residual_report.hpp"

extern char** environ;

namespace dynid::report {
namespace {

namespace fs = std::filesystem;

// A scratch folder for gnuplot's data, script and images, removed with its contents.
class Scratch {
 public:
  Scratch() {
    std::string pattern = (fs::temp_directory_path() / "dynid-report-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("report: cannot create a temporary folder");
    path_ = pattern;
  }
  ~Scratch() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  Scratch(const Scratch&) = delete;
  Scratch& operator=(const Scratch&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string base64(const std::string& bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const auto b0 = static_cast<unsigned char>(bytes[i]);
    const auto b1 = i + 1 < bytes.size() ? static_cast<unsigned char>(bytes[i + 1]) : 0U;
    const auto b2 = i + 2 < bytes.size() ? static_cast<unsigned char>(bytes[i + 2]) : 0U;
    const unsigned triple = (static_cast<unsigned>(b0) << 16U) | (static_cast<unsigned>(b1) << 8U) | b2;
    out += kAlphabet[(triple >> 18U) & 63U];
    out += kAlphabet[(triple >> 12U) & 63U];
    out += i + 1 < bytes.size() ? kAlphabet[(triple >> 6U) & 63U] : '=';
    out += i + 2 < bytes.size() ? kAlphabet[triple & 63U] : '=';
  }
  return out;
}

// Runs `gnuplot script` in `dir`; throws naming gnuplot and quoting its stderr on failure.
void run_gnuplot(const std::string& program, const fs::path& dir, const fs::path& script) {
  const fs::path err = dir / "gnuplot.err";
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  std::string arg0 = program;
  std::string arg1 = script.string();
  char* argv[] = {arg0.data(), arg1.data(), nullptr};
  pid_t pid = 0;
  const int spawned = ::posix_spawnp(&pid, program.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0)
    throw std::runtime_error("report: cannot run '" + program + "' (is gnuplot installed?): " + std::strerror(spawned));
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("report: gnuplot failed: " + read_file(err));
}

// One figure: gnuplot commands over data files written beside them.
struct Figure {
  std::string caption;
  std::string commands;  // after the terminal and output lines
  std::string png;       // file name
};

void write_columns(const fs::path& file, const std::vector<const Eigen::VectorXd*>& columns,
                   const std::vector<double>* first = nullptr) {
  std::ofstream out(file);
  const Eigen::Index n = columns.empty() ? 0 : columns.front()->size();
  for (Eigen::Index i = 0; i < n; ++i) {
    if (first != nullptr) out << fmt::format("{:.9g} ", (*first)[static_cast<std::size_t>(i)]);
    for (const Eigen::VectorXd* c : columns) out << fmt::format("{:.9g} ", (*c)(i));
    out << '\n';
  }
}

const residual::ResidualSeries* series_of(const residual::ModelFit& fit, const std::string& group) {
  for (const residual::ResidualSeries& s : fit.series)
    if (s.group == group) return &s;
  return nullptr;
}

// A located step to mark on the residual-against-time plots: its time and 95 % set.
struct StepMark {
  double time_s = 0.0, from_s = 0.0, to_s = 0.0;
};

std::optional<StepMark> step_mark(const residual::CandidateScore* added) {
  const std::string prefix = "step:";
  if (added == nullptr || added->effect.rfind(prefix, 0) != 0 || !std::isfinite(added->located_from_s) ||
      !std::isfinite(added->located_to_s))
    return std::nullopt;
  const auto at = added->effect.rfind('@');
  if (at == std::string::npos) return std::nullopt;
  char* end = nullptr;
  const double t = std::strtod(added->effect.c_str() + at + 1, &end);
  if (end == added->effect.c_str() + at + 1 || !std::isfinite(t)) return std::nullopt;
  return StepMark{t, added->located_from_s, added->located_to_s};
}

std::vector<Figure> figures_for_group(const fs::path& dir, const residual::ModelFit& before,
                                      const residual::ModelFit* after, const std::string& effect,
                                      const residual::ResidualSeries& b, std::size_t index,
                                      const std::optional<StepMark>& mark) {
  std::vector<Figure> out;
  const residual::ResidualSeries* a = after != nullptr ? series_of(*after, b.group) : nullptr;
  const std::string tag = fmt::format("g{}", index);
  write_columns(dir / (tag + "-before.dat"), {&b.residual}, &b.time_s);
  std::string plot = fmt::format("plot '{}-before.dat' using 1:2 with lines lw 1 title 'before'", tag);
  if (a != nullptr) {
    write_columns(dir / (tag + "-after.dat"), {&a->residual}, &a->time_s);
    plot += fmt::format(", '{}-after.dat' using 1:2 with lines lw 1 title 'with {}'", tag, effect);
  }
  std::string caption = "Residual of group " + b.group + " against time";
  std::string marking, unmarking;
  if (mark) {
    caption += fmt::format("; the located step at {:g} s (line), its 95 % set {:.2f}-{:.2f} s (shaded)", mark->time_s,
                           mark->from_s, mark->to_s);
    marking = fmt::format(
        "set object 1 rect from {:.9g}, graph 0 to {:.9g}, graph 1 behind fc rgb '#ffe0e0' fs solid noborder\n"
        "set arrow 1 from {:.9g}, graph 0 to {:.9g}, graph 1 nohead lc rgb '#cc0000' dt 2\n",
        mark->from_s, mark->to_s, mark->time_s, mark->time_s);
    unmarking = "unset object 1\nunset arrow 1\n";
  }
  out.push_back({caption, "set xlabel 'time (s)'\nset ylabel 'residual'\n" + marking + plot + "\n" + unmarking,
                 tag + "-time.png"});
  if (a != nullptr && a->effect_contribution.size() == a->residual.size()) {
    // The residual before the effect against what the effect explains, row by row: only rows
    // of both fits (the effect's may leave some out) at the same times.
    std::ofstream pairs(dir / (tag + "-effect.dat"));
    std::size_t j = 0;
    for (std::size_t i = 0; i < a->time_s.size(); ++i) {
      while (j < b.time_s.size() && b.time_s[j] < a->time_s[i]) ++j;
      if (j < b.time_s.size() && b.time_s[j] == a->time_s[i])
        pairs << fmt::format("{:.9g} {:.9g}\n", a->effect_contribution(static_cast<Eigen::Index>(i)),
                             b.residual(static_cast<Eigen::Index>(j)));
    }
    out.push_back({"Residual of group " + b.group + " (before) against the fitted " + effect,
                   fmt::format("set xlabel 'fitted {} contribution'\nset ylabel 'residual before'\n"
                               "plot '{}-effect.dat' using 1:2 with points pt 7 ps 0.4 title 'rows', x title 'diagonal'\n",
                               effect, tag),
                   tag + "-effect.png"});
  }
  if (b.spectrum.frequency_hz.size() > 1) {
    write_columns(dir / (tag + "-spec-before.dat"), {&b.spectrum.frequency_hz, &b.spectrum.amplitude});
    std::string spec = fmt::format("plot '{}-spec-before.dat' using 1:2 with lines title 'before'", tag);
    if (a != nullptr && a->spectrum.frequency_hz.size() > 1) {
      write_columns(dir / (tag + "-spec-after.dat"), {&a->spectrum.frequency_hz, &a->spectrum.amplitude});
      spec += fmt::format(", '{}-spec-after.dat' using 1:2 with lines title 'with {}'", tag, effect);
    }
    out.push_back({"Amplitude spectrum of the residual of group " + b.group,
                   "set xlabel 'frequency (Hz)'\nset ylabel 'amplitude'\nset logscale y\n" + spec + "\nunset logscale y\n",
                   tag + "-spectrum.png"});
  }
  (void)before;
  return out;
}

// The residual's cross-correlation with the group's plotted channels against the lag, each with
// its significance bound (dashed, both signs) in the same colour.
std::optional<Figure> correlation_figure(const fs::path& dir, const residual::Signature& signature,
                                         const std::string& group, std::size_t index) {
  std::string plot;
  int colour = 0;
  for (const residual::CorrelationCurve& c : signature.curves) {
    if (c.group != group || c.lag_s.empty()) continue;
    const std::string file = fmt::format("g{}-corr{}.dat", index, ++colour);
    std::ofstream out(dir / file);
    for (std::size_t i = 0; i < c.lag_s.size(); ++i)
      out << fmt::format("{:.9g} {:.9g} {:.9g}\n", c.lag_s[i], c.correlation[i], c.bound[i]);
    plot += fmt::format("{}'{}' using 1:2 with linespoints pt 7 ps 0.4 lc {} title '{}', '' using 1:3 with lines dt 2 "
                        "lc {} notitle, '' using 1:(-$3) with lines dt 2 lc {} notitle",
                        plot.empty() ? "plot " : ", ", file, colour, c.channel, colour, colour);
  }
  if (plot.empty()) return std::nullopt;
  return Figure{"Cross-correlation of the residual of group " + group +
                    " with the channels nearest their bound, against the lag (> 0: the residual follows the "
                    "channel); dashed: each one's significance bound",
                "set xlabel 'lag (s)'\nset ylabel 'correlation'\n" + plot + "\n",
                fmt::format("g{}-correlation.png", index)};
}

// The floor test at every time scale: residual over floor (the rows' mean square, then the
// block sums) against the block's length, with each test's critical ratio.
std::optional<Figure> scales_figure(const fs::path& dir, const residual::NoiseFloor& floor, const std::string& group,
                                    std::size_t index) {
  const auto g = std::find_if(floor.groups.begin(), floor.groups.end(),
                              [&](const residual::GroupFloor& f) { return f.group == group; });
  if (g == floor.groups.end() || g->scales.empty() || !(g->upper_ratio > 0.0) || !(g->ratio > 0.0)) return std::nullopt;
  const double row_seconds = g->scales.front().block_seconds / g->scales.front().block_rows;
  const std::string file = fmt::format("g{}-scales.dat", index);
  std::ofstream out(dir / file);
  out << fmt::format("{:.9g} {:.9g} {:.9g}\n", row_seconds, g->ratio, g->upper_ratio);
  for (const residual::ScaleFloor& s : g->scales)
    if (s.ratio > 0.0) out << fmt::format("{:.9g} {:.9g} {:.9g}\n", s.block_seconds, s.ratio, s.upper_ratio);
  return Figure{"Residual of group " + group +
                    " over its noise floor at every time scale (a row, then sums over blocks of rows); the "
                    "model lacks nothing up to the critical ratio",
                fmt::format("set xlabel 'block length (s)'\nset ylabel 'residual / floor'\nset logscale xy\n"
                            "plot '{0}' using 1:2 with linespoints pt 7 title 'residual / floor', '{0}' using 1:3 "
                            "with linespoints dt 2 pt 6 title 'critical ratio', 1 lc rgb '#888888' notitle\n"
                            "unset logscale xy\n",
                            file),
                fmt::format("g{}-scales.png", index)};
}

std::string draw(const HtmlReportInput& in, const fs::path& dir, const residual::ModelFit& before,
                 const residual::ModelFit* after, const std::string& effect) {
  std::vector<Figure> figures;
  for (std::size_t g = 0; g < before.series.size(); ++g) {
    std::vector<Figure> f = figures_for_group(dir, before, after, effect, before.series[g], g, step_mark(in.added));
    figures.insert(figures.end(), f.begin(), f.end());
    if (in.diagnosis == nullptr) continue;
    if (auto c = correlation_figure(dir, in.diagnosis->signature, before.series[g].group, g)) figures.push_back(*c);
    if (auto s = scales_figure(dir, in.diagnosis->floor, before.series[g].group, g)) figures.push_back(*s);
  }
  std::string script = "set terminal pngcairo noenhanced size 900,420 font 'sans,10'\nset grid\nset key top right\n";
  for (const Figure& f : figures) script += "set output '" + f.png + "'\n" + f.commands;
  script += "unset output\n";
  const fs::path script_file = dir / "plots.gp";
  std::ofstream(script_file) << "cd '" << dir.string() << "'\n" << script;
  run_gnuplot(in.gnuplot, dir, script_file);
  std::string html;
  for (const Figure& f : figures)
    html += fmt::format("<figure><img alt=\"{0}\" src=\"data:image/png;base64,{1}\"><figcaption>{0}</figcaption></figure>\n",
                        html_escape(f.caption), base64(read_file(dir / f.png)));
  return html;
}

constexpr const char* kStyle =
    "body{font-family:sans-serif;margin:2em;max-width:1000px}pre{background:#f6f6f6;padding:1em;overflow-x:auto}"
    "figure{margin:1em 0}img{max-width:100%;border:1px solid #ddd}figcaption{color:#555;font-size:90%}";

// Marks <body data-images="k/n"> once the page has loaded: k images decoded of n.
constexpr const char* kImageCheck =
    "<script>window.addEventListener('load',function(){var i=document.images,k=0;"
    "for(var j=0;j<i.length;j++){if(i[j].complete&&i[j].naturalWidth>0)k++;}"
    "document.body.setAttribute('data-images',k+'/'+i.length);});</script>";

}  // namespace

std::string html_escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string residual_html(const HtmlReportInput& in) {
  const residual::ModelFit* before = in.comparison != nullptr ? &in.comparison->before
                                     : in.screen != nullptr   ? &in.screen->fit
                                                              : nullptr;
  if (before == nullptr) throw std::invalid_argument("residual_html: neither a screen nor a comparison");
  std::string body = "<h1>dynid residual report: " + html_escape(in.title) + "</h1>\n";
  if (in.diagnosis != nullptr)
    body += "<h2>Diagnosis</h2>\n<p><b>" + html_escape(residual::verdict_name(in.diagnosis->verdict)) + "</b>: " +
            html_escape(in.diagnosis->statement()) + "</p>\n";
  if (in.screen != nullptr)
    body += "<h2>What the model lacks</h2>\n<p><b>" + html_escape(in.screen->verdict()) + "</b></p>\n<pre>" +
            html_escape(format_screen_text(*in.screen)) + "</pre>\n";
  if (in.comparison != nullptr)
    body += "<h2>Before and after adding " + html_escape(in.comparison->effect) + "</h2>\n<pre>" +
            html_escape(format_comparison_text(*in.comparison)) + "</pre>\n";
  Scratch scratch;
  body += "<h2>Plots</h2>\n" + draw(in, scratch.path(), *before,
                                      in.comparison != nullptr ? &in.comparison->after : nullptr,
                                      in.comparison != nullptr ? in.comparison->effect : "");
  return "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>dynid: " + html_escape(in.title) +
         "</title><style>" + kStyle + "</style>" + kImageCheck + "</head>\n<body>\n" + body + "</body></html>\n";
}

}  // namespace dynid::report
