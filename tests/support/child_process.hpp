#pragma once
// Starting a child program from a test, safely from a multithreaded process.
//
// The tests start programs (dynid, dynid-server, peers, PostgreSQL's tools) while threads of
// their own run: an in-process server, DDS, the sanitizers' allocator. After fork() only the
// forking thread exists in the child, and any lock another thread held (malloc's, the
// sanitizer allocator's) stays locked forever: a child that allocates before exec (building its
// argv, say) can hang and never run the program. posix_spawn does the fork and exec with no user
// code between them, and its file actions (open, dup2, close) are done by the C library in the
// child with system calls only. Every program a test starts goes through here.
#include <sys/types.h>

#include <string>
#include <vector>

namespace dynid::test {

// Where the child's standard output and error go. Unset (-1 / empty): inherited.
struct ChildOutput {
  std::string file;           // stdout (and stderr if to_file_too) to this file
  bool append = true;         // else truncated
  bool stderr_to_file = true;
  int stdout_fd = -1;         // stdout to this descriptor (e.g. a pipe's write end)
  int stderr_fd = -1;         // stderr to this descriptor
};

// Starts argv[0] with arguments argv[1..] and returns its pid. With search_path, argv[0] is
// looked up in PATH (as execvp does); otherwise it is a path. Throws std::runtime_error when the
// program cannot be started (naming it and the reason). Descriptors opened without close-on-exec
// are inherited as usual: open pipes with pipe2(..., O_CLOEXEC), so that a child holds only what
// `output` gives it.
pid_t spawn_child(const std::vector<std::string>& argv, const ChildOutput& output = {},
                  bool search_path = false);

}  // namespace dynid::test
