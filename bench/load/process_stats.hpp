#pragma once
// ProcessStats: what the load benchmark reads about the server process from /proc (Linux).
//
// read_process_stats(pid): CPU time used so far (utime + stime of /proc/<pid>/stat, seconds),
// resident memory now (VmRSS) and its peak (VmHWM) from /proc/<pid>/status, in bytes. Throws
// InputError naming the file when the process does not exist or a field is missing.
// read_process_stats(pids): the same, summed over the processes.
#include <sys/types.h>

#include <cstdint>
#include <vector>

namespace dynid::load {

struct ProcessStats {
  double cpu_seconds = 0.0;
  std::uint64_t rss_bytes = 0;
  std::uint64_t peak_rss_bytes = 0;
};

ProcessStats read_process_stats(pid_t pid);
/// The sum over several processes (servers sharing the vehicles); peak RSS is the sum of each
/// one's peak (an upper bound on the peak of the sum). Zeros for none.
ProcessStats read_process_stats(const std::vector<pid_t>& pids);

/// Least-squares slope of y against x (units of y per unit of x); 0 for fewer than 2 points.
double slope(const std::vector<double>& x, const std::vector<double>& y);

/// The q-quantile (0..1) of `values` by the nearest-rank method; NaN when empty.
double quantile(std::vector<double> values, double q);

}  // namespace dynid::load
