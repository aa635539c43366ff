#pragma once
// PostgresCluster: a real PostgreSQL server of the test's own, in a temporary folder.
//
// Contract: the constructor runs Debian's initdb and `pg_ctl start` (binaries in
// DYNID_PG_BINDIR) on a free loopback port: the server listens on 127.0.0.1 only, its unix
// socket lies in the temporary folder, it trusts local connections as user "dynid", and it runs
// with fsync on (the durability the store relies on is the real one). When the test runs as
// root, which initdb refuses, the server's files belong to and its programs run as the
// unprivileged user "nobody" (through runuser). A failure to start throws std::runtime_error
// carrying the tool's output. The destructor stops the server (immediate: its data is thrown
// away) and removes the folder; so does a child process of its own if the test process dies
// first (killed by a timeout, a crash): no server outlives its test.
#include <string>

namespace dynid::store::test {

class PostgresCluster {
 public:
  PostgresCluster();
  ~PostgresCluster();
  PostgresCluster(const PostgresCluster&) = delete;
  PostgresCluster& operator=(const PostgresCluster&) = delete;

  /// postgresql://dynid@127.0.0.1:<port>/<database>
  std::string uri(const std::string& database) const;
  /// A place for a new store: an empty schema `prefix_<n>` (n counts up) of the database
  /// "dynid", as a URI whose search_path is that schema. (A schema, not a database: creating a
  /// database copies and syncs its template, ~0.2 s per test.)
  std::string fresh_store(const std::string& prefix = "store");
  /// Runs SQL (no result wanted) at a URI as the superuser; throws std::runtime_error.
  void sql(const std::string& at, const std::string& statement) const;

  /// Stops the server as a crash would (pg_ctl stop -m immediate: no shutdown checkpoint, so
  /// the next start recovers from the WAL), then starts it again on the same port.
  void crash_and_restart();

 private:
  void start();
  void stop(const char* mode);
  void start_cleaner();
  void end_cleaner();

  std::string dir_;
  int port_ = 0;
  int stores_ = 0;
  int cleaner_pipe_ = -1;  // closing it starts the cleaner
};

/// The one cluster of the test process, started on first use, stopped at exit.
PostgresCluster& cluster();

}  // namespace dynid::store::test
