// dynid-test-postgres: the tests' own PostgreSQL server (postgres_cluster.hpp) for scripts
// (bench/load/run-load.sh's PostgreSQL runs and its ctest): starts it, prints the URI of its
// database "dynid" on one line of stdout, and holds it until SIGTERM, SIGINT or SIGHUP arrives,
// its parent process dies, or --max-seconds pass; then stops it and removes its folder. A
// SIGKILL leaves that to PostgresCluster's cleaner process: no server outlives its script.
//
//   dynid-test-postgres [--max-seconds S]     (default 3600)
//
// Exit status 0 after a clean stop, 1 when the server could not be started (the tool's output
// on stderr), 2 on a bad command line.
#include <signal.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <exception>
#include <string>

#include "postgres_cluster.hpp"

int main(int argc, char** argv) {
  long max_seconds = 3600;
  if (argc == 3 && std::strcmp(argv[1], "--max-seconds") == 0) {
    char* end = nullptr;
    max_seconds = std::strtol(argv[2], &end, 10);
    if (*end != '\0' || max_seconds < 1) argc = -1;
  }
  if (argc != 1 && argc != 3) {
    std::fprintf(stderr, "usage: dynid-test-postgres [--max-seconds S]\n");
    return 2;
  }
  const pid_t parent = getppid();
  prctl(PR_SET_PDEATHSIG, SIGTERM);  // default action: die; the cleaner then stops the server
  if (getppid() != parent) return 1;
  try {
    dynid::store::test::PostgresCluster cluster;
    // Blocked only now: pg_ctl and the server (started above) must not inherit the mask.
    sigset_t stop;
    sigemptyset(&stop);
    for (const int s : {SIGTERM, SIGINT, SIGHUP}) sigaddset(&stop, s);
    sigprocmask(SIG_BLOCK, &stop, nullptr);
    std::printf("%s\n", cluster.uri("dynid").c_str());
    std::fflush(stdout);
    const timespec limit{max_seconds, 0};
    if (sigtimedwait(&stop, nullptr, &limit) < 0)
      std::fprintf(stderr, "dynid-test-postgres: stopping after --max-seconds %ld\n", max_seconds);
    return 0;  // ~PostgresCluster stops the server and removes the folder
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dynid-test-postgres: %s\n", e.what());
    return 1;
  }
}
