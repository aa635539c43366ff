#include "postgres_cluster.hpp"

#include "child_process.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <libpq-fe.h>
#include <netinet/in.h>
#include <pwd.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

namespace dynid::store::test {

namespace {

const char* const kUnprivileged = "nobody";

bool running_as_root() {
  return geteuid() == 0;
}

// Runs argv (as the unprivileged user when we are root), its output appended to `log`; returns
// its exit status.
int run(std::vector<std::string> argv, const std::string& log) {
  if (running_as_root())
    argv.insert(argv.begin(), {"/usr/sbin/runuser", "-u", kUnprivileged, "--"});
  const pid_t child = dynid::test::spawn_child(argv, {.file = log}, /*search_path=*/true);
  int status = 0;
  waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A loopback port that was free a moment ago (start() retries should another process take it).
int free_port() {
  const int s = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof address;
  if (s < 0 || bind(s, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      getsockname(s, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    if (s >= 0) close(s);
    throw std::runtime_error("no free loopback port");
  }
  close(s);
  return ntohs(address.sin_port);
}

// The folder, owned by whoever runs the server: initdb wants to own (and be alone in) its
// data directory.
std::string make_folder() {
  std::string pattern = (std::filesystem::temp_directory_path() / "dynid-pg-XXXXXX").string();
  if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
  if (running_as_root()) {
    const passwd* user = getpwnam(kUnprivileged);
    if (!user || chown(pattern.c_str(), user->pw_uid, user->pw_gid) != 0)
      throw std::runtime_error("cannot give " + pattern + " to user " + kUnprivileged);
  }
  return pattern;
}

std::string tool(const char* name) {
  return std::string(DYNID_PG_BINDIR) + "/" + name;
}

}  // namespace

PostgresCluster::PostgresCluster() : dir_(make_folder()) {
  start_cleaner();
  try {
    const std::string log = dir_ + "/initdb.log";
    // --no-sync: only initdb's own final fsync of the fresh files; the server runs with fsync on.
    if (run({tool("initdb"), "-D", dir_ + "/data", "-U", "dynid", "--auth=trust", "-E", "UTF8",
             "--no-locale", "--no-sync", "--no-instructions"},
            log) != 0) {
      throw std::runtime_error("initdb failed: " + read_text(log));
    }
    start();
    sql(uri("postgres"), "CREATE DATABASE dynid");
  } catch (...) {
    end_cleaner();
    throw;
  }
}

PostgresCluster::~PostgresCluster() {
  end_cleaner();
}

// A process that waits until the test process's end of a pipe closes (at exit, or when the
// test is killed, e.g. by ctest's timeout), then stops the server and removes the folder: no
// server outlives its test. Detached (its own session, reparented, output to /dev/null), so
// whatever kills the test and its process tree does not kill it, and nobody waits for its
// output. The pipe is close-on-exec, so the server (started through pg_ctl) does not hold it.
void PostgresCluster::start_cleaner() {
  int ends[2];
  if (pipe2(ends, O_CLOEXEC) != 0) throw std::runtime_error("pipe2 failed");
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    close(ends[1]);
    if (setsid() < 0 || fork() != 0) _exit(0);  // the intermediate exits: the cleaner is orphaned
    const int null = open("/dev/null", O_RDWR);
    for (const int fd : {STDIN_FILENO, STDOUT_FILENO, STDERR_FILENO}) dup2(null, fd);
    char byte = 0;
    for (;;) {
      const ssize_t n = read(ends[0], &byte, 1);
      if (n == 0 || (n < 0 && errno != EINTR)) break;
    }
    stop("immediate");
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
    _exit(0);
  }
  close(ends[0]);
  waitpid(child, nullptr, 0);
  cleaner_pipe_ = ends[1];
}

// Hands the cleaning to the cleaner and waits (10 s at most) until it has removed the folder.
void PostgresCluster::end_cleaner() {
  close(cleaner_pipe_);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::filesystem::exists(dir_) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
}

void PostgresCluster::start() {
  const std::string log = dir_ + "/pg_ctl.log";
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int port = port_ != 0 && attempt == 0 ? port_ : free_port();
    const std::string settings = "-c listen_addresses=127.0.0.1 -c port=" + std::to_string(port) +
                                 " -c unix_socket_directories=" + dir_;
    if (run({tool("pg_ctl"), "-D", dir_ + "/data", "-l", dir_ + "/server.log", "-w", "-t", "30",
             "-o", settings, "start"},
            log) == 0) {
      port_ = port;
      return;
    }
  }
  throw std::runtime_error("pg_ctl start failed: " + read_text(log) +
                           read_text(dir_ + "/server.log"));
}

void PostgresCluster::stop(const char* mode) {
  run({tool("pg_ctl"), "-D", dir_ + "/data", "-m", mode, "-w", "stop"}, dir_ + "/pg_ctl.log");
}

void PostgresCluster::crash_and_restart() {
  stop("immediate");
  start();
}

std::string PostgresCluster::uri(const std::string& database) const {
  return "postgresql://dynid@127.0.0.1:" + std::to_string(port_) + "/" + database;
}

void PostgresCluster::sql(const std::string& at, const std::string& statement) const {
  const std::unique_ptr<PGconn, decltype(&PQfinish)> conn(PQconnectdb(at.c_str()), &PQfinish);
  if (PQstatus(conn.get()) != CONNECTION_OK)
    throw std::runtime_error("connect " + at + ": " + PQerrorMessage(conn.get()));
  const std::unique_ptr<PGresult, decltype(&PQclear)> result(PQexec(conn.get(), statement.c_str()),
                                                             &PQclear);
  const ExecStatusType status = PQresultStatus(result.get());
  if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK)
    throw std::runtime_error(statement + ": " + PQresultErrorMessage(result.get()));
}

std::string PostgresCluster::fresh_store(const std::string& prefix) {
  const std::string schema = prefix + "_" + std::to_string(++stores_);
  sql(uri("dynid"), "CREATE SCHEMA " + schema);
  return uri("dynid") + "?options=-csearch_path%3D" + schema;
}

PostgresCluster& cluster() {
  static PostgresCluster instance;
  return instance;
}

}  // namespace dynid::store::test
