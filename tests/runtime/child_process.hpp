// A child program for end-to-end tests: spawned with its output in a log file, stopped with
// SIGTERM (then SIGKILL) by its own pid when the test ends.
#pragma once

#include <sys/types.h>

#include <string>
#include <vector>

namespace autodrive::child_process {

class Child {
 public:
  Child(const std::vector<std::string> &argv, const std::string &log_path);
  ~Child() { stop(); }
  Child(const Child &) = delete;
  Child &operator=(const Child &) = delete;
  bool running();
  void stop();
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_ = -1;
};

}  // namespace autodrive::child_process
