#include "child_process.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <unistd.h>

#include <cstring>
#include <stdexcept>

extern char** environ;

namespace dynid::test {
namespace {

// The file actions, destroyed on every path.
class FileActions {
 public:
  FileActions() { posix_spawn_file_actions_init(&actions_); }
  ~FileActions() { posix_spawn_file_actions_destroy(&actions_); }
  FileActions(const FileActions&) = delete;
  FileActions& operator=(const FileActions&) = delete;
  posix_spawn_file_actions_t* get() { return &actions_; }

 private:
  posix_spawn_file_actions_t actions_;
};

void require(int result, const std::string& what) {
  if (result != 0) throw std::runtime_error(what + ": " + std::strerror(result));
}

}  // namespace

pid_t spawn_child(const std::vector<std::string>& argv, const ChildOutput& output, bool search_path) {
  if (argv.empty()) throw std::runtime_error("spawn_child: no program");
  FileActions actions;
  const std::string what = "cannot start " + argv[0];
  if (!output.file.empty()) {
    const int flags = O_WRONLY | O_CREAT | (output.append ? O_APPEND : O_TRUNC);
    require(posix_spawn_file_actions_addopen(actions.get(), STDOUT_FILENO, output.file.c_str(), flags, 0644),
            what);
    if (output.stderr_to_file)
      require(posix_spawn_file_actions_adddup2(actions.get(), STDOUT_FILENO, STDERR_FILENO), what);
  }
  if (output.stdout_fd >= 0)
    require(posix_spawn_file_actions_adddup2(actions.get(), output.stdout_fd, STDOUT_FILENO), what);
  if (output.stderr_fd >= 0)
    require(posix_spawn_file_actions_adddup2(actions.get(), output.stderr_fd, STDERR_FILENO), what);
  std::vector<std::string> copy = argv;  // posix_spawn takes char* const[]
  std::vector<char*> c_argv;
  for (auto& a : copy) c_argv.push_back(a.data());
  c_argv.push_back(nullptr);
  pid_t pid = -1;
  const int result = search_path
                         ? posix_spawnp(&pid, c_argv[0], actions.get(), nullptr, c_argv.data(), environ)
                         : posix_spawn(&pid, c_argv[0], actions.get(), nullptr, c_argv.data(), environ);
  require(result, what);
  return pid;
}

}  // namespace dynid::test
