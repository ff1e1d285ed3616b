// Test helper: runs `write(c)` in `count` forked child processes at once and reports whether each
// one returned normally (an exception is printed with the writer's number and counts as failure).
// Used by the tests of writers that must never collide (atomic files, parameter files).
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <exception>
#include <functional>
#include <vector>

namespace hrg_gyro {
namespace core {
namespace testing {

/// True for every child that finished its writes without an exception.
inline std::vector<bool> runConcurrentWriters(int count, const std::function<void(int)>& write) {
  std::vector<pid_t> children;
  for (int c = 0; c < count; ++c) {
    const pid_t pid = ::fork();
    if (pid == 0) {
      try {
        write(c);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "writer %d: %s\n", c, e.what());
        ::_exit(1);
      }
      ::_exit(0);
    }
    children.push_back(pid);
  }
  std::vector<bool> ok;
  for (const pid_t child : children) {
    int status = 0;
    ok.push_back(child > 0 && ::waitpid(child, &status, 0) == child && WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  return ok;
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro
