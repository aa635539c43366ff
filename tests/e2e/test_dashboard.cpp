// dynid-dashboard in a real browser (label browser): headless Chromium driven over the DevTools
// protocol (--remote-debugging-pipe) opens a model's page while dynid-car replays a simulated run
// into an in-process server; the page's rows, value and ±2σ band are read from the DOM twice, and
// must have moved without a reload. Without the token nothing but a 401 comes back. Screenshots of
// the fleet, of the run and of the model's page are written to the build tree
// (dashboard-screenshots/).
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <thread>
#include <tuple>

#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "e2e_fixture.hpp"

// After Eigen (e2e_fixture.hpp): httplib.h brings glibc's `_res` macro.
#include <httplib.h>

extern char** environ;

namespace dynid::e2e {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;
constexpr const char* kToken = "dashboard-test-token-0123456789";

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string chromium() {
  for (const char* p : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (fs::exists(p)) return p;
  return "";
}

// SIGTERM, then up to `patience` for the child to exit; SIGKILL after it. True if it exited.
bool stop_within(pid_t pid, std::chrono::seconds patience) {
  kill(pid, SIGTERM);
  int status = 0;
  for (const auto until = Clock::now() + patience; Clock::now() < until;) {
    if (waitpid(pid, &status, WNOHANG) == pid) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  kill(pid, SIGKILL);
  waitpid(pid, &status, 0);
  return false;
}

// The dashboard as a child; its port read from its first line.
struct Dashboard {
  pid_t pid = -1;
  int port = 0;
  Dashboard(const TempDir& dir) {
    std::ofstream(dir.file("token")) << kToken << "\n";
    pid = test::spawn_child({DYNID_DASHBOARD_EXE, "--listen", "127.0.0.1:0", "--token-file",
                             dir.file("token"), "--cyclone-config", loopback_config(), "--domain",
                             std::to_string(domain()), "--poll", "0.5"},
                            {.file = dir.file("dashboard.log")});
    const std::regex listening("listening on http://127\\.0\\.0\\.1:([0-9]+)/");
    for (const auto until = Clock::now() + std::chrono::seconds(30);
         Clock::now() < until && port == 0;) {
      std::smatch m;
      const std::string log = read_file(dir.file("dashboard.log"));
      if (std::regex_search(log, m, listening)) port = std::stoi(m[1]);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  }
  ~Dashboard() {
    if (pid > 0 && !stop_within(pid, std::chrono::seconds(10)))
      ADD_FAILURE() << "the dashboard did not stop within 10 s of SIGTERM (killed)";
  }
};

// Headless Chromium over the DevTools protocol on a pipe: commands on its fd 3, replies and
// events, each ended by '\0', on its fd 4.
class Browser {
 public:
  explicit Browser(const std::string& profile) {
    int to[2], from[2];
    if (pipe2(to, O_CLOEXEC) != 0 || pipe2(from, O_CLOEXEC) != 0) throw std::runtime_error("pipe2");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, to[0], 3);
    posix_spawn_file_actions_adddup2(&actions, from[1], 4);
    const int devnull = open("/dev/null", O_WRONLY | O_CLOEXEC);
    posix_spawn_file_actions_adddup2(&actions, devnull, 2);
    const std::string dir = "--user-data-dir=" + profile;
    std::vector<std::string> args{chromium(),
                                  "--headless",
                                  "--no-sandbox",
                                  "--disable-gpu",
                                  "--remote-debugging-pipe",
                                  "--window-size=1400,1000",
                                  dir};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    if (posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), environ) != 0)
      throw std::runtime_error("spawn chromium");
    posix_spawn_file_actions_destroy(&actions);
    close(to[0]), close(from[1]), close(devnull);
    out_ = to[1], in_ = from[0];
  }
  ~Browser() {
    close(out_), close(in_);
    stop_within(pid_, std::chrono::seconds(10));
  }

  // One command; its result (events before it are dropped).
  json call(const std::string& method, const json& params = json::object(),
            const std::string& session = "") {
    json message = {{"id", ++id_}, {"method", method}, {"params", params}};
    if (!session.empty()) message["sessionId"] = session;
    const std::string text = message.dump() + std::string(1, '\0');
    if (write(out_, text.data(), text.size()) != static_cast<ssize_t>(text.size()))
      throw std::runtime_error("write to chromium");
    for (;;) {
      const json reply = next();
      if (reply.value("id", 0) != id_) continue;
      if (reply.contains("error")) throw std::runtime_error(method + ": " + reply["error"].dump());
      return reply["result"];
    }
  }

 private:
  json next() {
    for (;;) {
      if (const std::size_t end = buffer_.find('\0'); end != std::string::npos) {
        json message = json::parse(buffer_.substr(0, end));
        buffer_.erase(0, end + 1);
        return message;
      }
      char chunk[65536];
      const ssize_t n = read(in_, chunk, sizeof chunk);
      if (n <= 0) throw std::runtime_error("chromium closed its pipe");
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }
  pid_t pid_ = -1;
  int out_ = -1, in_ = -1;
  int id_ = 0;
  std::string buffer_;
};

std::string base64_decode(const std::string& in) {
  static const std::string digits =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned bits = 0;
  int count = 0;
  for (const char c : in) {
    const std::size_t d = digits.find(c);
    if (d == std::string::npos) continue;  // '=' and line breaks
    bits = (bits << 6) | static_cast<unsigned>(d);
    if ((count += 6) >= 8) out.push_back(static_cast<char>((bits >> (count -= 8)) & 0xFF));
  }
  return out;
}

// What the page shows of the model: rows, the first parameter's value, its band's path, and the
// marker a reload would clear.
struct PageRead {
  long rows = -1;
  std::string value, band;
  bool same_document = false;
};

PageRead read_page(Browser& b, const std::string& session) {
  const json r = b.call("Runtime.evaluate",
                        {{"returnByValue", true},
                         {"expression",
                          "(() => { const rows = document.getElementById('rows');"
                          "  const band = document.querySelector('path[id^=band-]');"
                          "  const value = document.querySelector('td[id^=value-]');"
                          "  return {rows: rows ? Number(rows.textContent) : -1, band: band ? "
                          "band.getAttribute('d') : '',"
                          "          value: value ? value.textContent : '', marker: "
                          "window.dynidTestMarker === 7}; })()"}},
                        session);
  const json v = r["result"]["value"];
  return {v.value("rows", -1L), v.value("value", ""), v.value("band", ""),
          v.value("marker", false)};
}

template <typename Predicate>
bool eventually(Predicate done, std::chrono::seconds patience) {
  for (const auto until = Clock::now() + patience; Clock::now() < until;) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return done();
}

TEST(Dashboard, WithoutTheTokenEveryRouteAnswers401AndNoData) {
  TempDir dir;
  Dashboard dashboard(dir);
  ASSERT_GT(dashboard.port, 0) << read_file(dir.file("dashboard.log"));
  httplib::Client client("127.0.0.1", dashboard.port);
  for (const char* path :
       {"/", "/api/fleet", "/api/history?vehicle=a&run=b&model=c", "/api/run?vehicle=a", "/events",
        "/login?token=wrong-token-of-enough-length"}) {
    const auto res = client.Get(path);
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->status, 401) << path;
    EXPECT_EQ(res->body.find("vehicles"), std::string::npos) << path;
    EXPECT_EQ(res->body.find("<script"), std::string::npos) << path;
  }
  const auto wrong =
      client.Get("/api/fleet", {{"Authorization", "Bearer not-the-token-but-as-long-as-it"}});
  ASSERT_TRUE(wrong);
  EXPECT_EQ(wrong->status, 401);
  const auto right = client.Get("/api/fleet", {{"Authorization", std::string("Bearer ") + kToken}});
  ASSERT_TRUE(right);
  EXPECT_EQ(right->status, 200);
  EXPECT_TRUE(json::parse(right->body).contains("vehicles"));
  const auto login = client.Get((std::string("/login?token=") + kToken).c_str());
  ASSERT_TRUE(login);
  EXPECT_EQ(login->status, 303);
  EXPECT_NE(login->get_header_value("Set-Cookie").find("HttpOnly"), std::string::npos);
}

// Exit status and output of the dashboard started with `args` (it must end by itself).
std::pair<int, std::string> dashboard_exit(const TempDir& dir,
                                           const std::vector<std::string>& args) {
  std::vector<std::string> argv{DYNID_DASHBOARD_EXE, "--listen", "127.0.0.1:0"};
  argv.insert(argv.end(), args.begin(), args.end());
  const std::string log = dir.file("refused.log");
  fs::remove(log);
  const pid_t pid = test::spawn_child(argv, {.file = log});
  int status = 0;
  waitpid(pid, &status, 0);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(log)};
}

TEST(Dashboard, ABadTokenOrConfigurationIsRefusedWithItsReason) {
  TempDir dir;
  std::ofstream(dir.file("short")) << "too-short\n";
  std::ofstream(dir.file("token")) << kToken << "\n";
  const auto [short_status, short_out] = dashboard_exit(dir, {"--token-file", dir.file("short")});
  EXPECT_EQ(short_status, 2);
  EXPECT_NE(short_out.find("at least 16 characters; it has 9"), std::string::npos) << short_out;
  const auto [missing_status, missing_out] =
      dashboard_exit(dir, {"--token-file", dir.file("nothing")});
  EXPECT_EQ(missing_status, 2);
  EXPECT_NE(missing_out.find("cannot be read"), std::string::npos) << missing_out;
  const auto [config_status, config_out] =
      dashboard_exit(dir, {"--token-file", dir.file("token"), "--cyclone-config", "<Nonsense/>"});
  EXPECT_EQ(config_status, 2);
  EXPECT_NE(config_out.find("cannot join DDS"), std::string::npos) << config_out;
}

// The run of a user: the simulator's swept-sine steering run (40 s), replayed by dynid-car in real
// time with the test car's profile into the server, the dashboard's page open on one of its models.
TEST(Dashboard, AReplayedRunsEstimatesAndBandMoveOnThePageWithoutAReload) {
  ASSERT_FALSE(chromium().empty())
      << "Chromium is not installed (deploy/setup.sh installs the package 'chromium')";
  TempDir dir;
  InProcessServer server(server_options(dir.file("store.db")));
  Dashboard dashboard(dir);
  ASSERT_GT(dashboard.port, 0) << read_file(dir.file("dashboard.log"));
  const std::string source = DYNID_SOURCE_DIR;
  const pid_t sim =
      test::spawn_child({DYNID_SIM_EXE, "--scenario", source + "/deploy/scenarios/sine_steer.toml",
                         "--out", dir.file("run")},
                        {.file = dir.file("sim.log")});
  int sim_status = 0;
  waitpid(sim, &sim_status, 0);
  ASSERT_TRUE(WIFEXITED(sim_status) && WEXITSTATUS(sim_status) == 0)
      << read_file(dir.file("sim.log"));
  const pid_t car = test::spawn_child(
      {DYNID_CAR_EXE, "--profile", source + "/deploy/profiles/testcar.toml", "--cyclone-config",
       loopback_config(), "--domain", std::to_string(domain()), "--replay",
       dir.file("run") + "/can.log", "--spool", dir.file("spool"), "--run", "run-d"},
      {.file = dir.file("car.log")});
  struct Stop {
    pid_t pid;
    ~Stop() { stop_within(pid, std::chrono::seconds(10)); }
  } stop_car{car};

  // A model of the replayed run the dashboard received: its page is opened.
  httplib::Client client("127.0.0.1", dashboard.port);
  const httplib::Headers auth{{"Authorization", std::string("Bearer ") + kToken}};
  std::string model;
  ASSERT_TRUE(eventually(
      [&] {
        const auto res = client.Get("/api/fleet", auth);
        if (!res || res->status != 200) return false;
        const json fleet =
            json::parse(res->body);  // kept: a range over a temporary's member dangles
        for (const json& m : fleet["models"])
          if (m["vehicle"] == "dynid-testcar" && m["model"] == "lateral_bicycle")
            model = m["model"];
        return !model.empty();
      },
      std::chrono::seconds(30)))
      << "no estimate of the replayed run reached the dashboard; it shows "
      << client.Get("/api/fleet", auth)->body << "\nthe car: " << read_file(dir.file("car.log"));
  Browser browser(dir.file("chromium-profile"));
  const std::string target =
      browser.call("Target.createTarget", {{"url", "about:blank"}})["targetId"];
  const std::string session =
      browser.call("Target.attachToTarget", {{"targetId", target}, {"flatten", true}})["sessionId"];
  const std::string base = "http://127.0.0.1:" + std::to_string(dashboard.port);
  const std::string view = "%23%2Fmodel%3Fvehicle%3Ddynid-testcar%26run%3Drun-d%26model%3D" + model;
  browser.call("Page.navigate", {{"url", base + "/login?token=" + kToken + "&view=" + view}},
               session);
  PageRead first;
  ASSERT_TRUE(eventually(
      [&] { return (first = read_page(browser, session)).rows > 0 && !first.band.empty(); },
      std::chrono::seconds(30)))
      << "the model's page never showed its rows and band";
  browser.call("Runtime.evaluate", {{"expression", "window.dynidTestMarker = 7"}}, session);

  PageRead second;
  ASSERT_TRUE(eventually([&] { return (second = read_page(browser, session)).rows > first.rows; },
                         std::chrono::seconds(30)))
      << "the page's rows stayed at " << first.rows << " while the run was replayed";
  EXPECT_TRUE(second.same_document) << "the page was reloaded: its marker is gone";
  EXPECT_NE(second.band, first.band) << "the ±2σ band did not move";
  EXPECT_FALSE(second.value.empty());

  // Screenshots to look at (the fleet, a run, the model's page), in the build tree, each taken
  // once its view has drawn.
  const fs::path shots = fs::path(DYNID_SCREENSHOT_DIR);
  fs::create_directories(shots);
  browser.call("Emulation.setDeviceMetricsOverride",
               {{"width", 1400}, {"height", 1300}, {"deviceScaleFactor", 1}, {"mobile", false}},
               session);
  const std::vector<std::tuple<std::string, std::string, std::string>> views{
      {"fleet", "#/", "#fleet-models"},
      {"run", "#/run?vehicle=dynid-testcar&run=run-d", "#run-health"},
      {"model", "#/model?vehicle=dynid-testcar&run=run-d&model=" + model, "path[id^=band-]"}};
  for (const auto& [name, hash, drawn] : views) {
    browser.call("Page.navigate", {{"url", base + "/" + hash}}, session);
    const std::string ready = "document.querySelector('" + drawn + "') !== null";
    EXPECT_TRUE(eventually(
        [&] {
          return browser
              .call("Runtime.evaluate", {{"expression", ready}, {"returnByValue", true}},
                    session)["result"]
              .value("value", false);
        },
        std::chrono::seconds(20)))
        << name << ": " << drawn << " never drawn";
    const std::string png =
        base64_decode(browser.call("Page.captureScreenshot", {{"format", "png"}}, session)["data"]);
    std::ofstream((shots / (name + ".png")).string(), std::ios::binary) << png;
    EXPECT_GT(png.size(), 10000u) << name;
  }
}

}  // namespace
}  // namespace dynid::e2e
