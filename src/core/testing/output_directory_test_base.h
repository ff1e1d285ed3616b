// Test support: a fresh temporary directory for each test of the atomic output files (the atomic file
// itself, the triad's result set), removed afterwards with any injected write fault cleared.
#pragma once

#include <gtest/gtest.h>
#include <stdlib.h>

#include <cerrno>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/atomic_file.h"

namespace hrg_gyro {
namespace core {

/// A write fault to inject (fault_injection::setOutputFileFault) and the words its error message must hold.
struct OutputFileFault {
  fault_injection::OutputFileStep step;
  int error;
  const char* message;
};

/// The faults before a file's rename: a full disk, a failing sync, a failing backup link.
inline std::vector<OutputFileFault> faultsBeforeTheRename() {
  using fault_injection::OutputFileStep;
  return {{OutputFileStep::kWrite, ENOSPC, "No space left on device"},
          {OutputFileStep::kSync, EIO, "Input/output error"},
          {OutputFileStep::kBackup, EDQUOT, "quota"}};
}

class OutputDirectoryTestBase : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = "/tmp/hrg_output_directory_test_XXXXXX";
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    fault_injection::setOutputFileFault({});
    std::filesystem::remove_all(dir_);
  }
  std::string at(const std::string& name) const { return dir_ + "/" + name; }
  /// Every name in `dir` (default: the test directory).
  std::set<std::string> listing(const std::string& dir = "") const {
    std::set<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(dir.empty() ? dir_ : dir))
      names.insert(e.path().filename().string());
    return names;
  }
  std::string dir_;
};

}  // namespace core
}  // namespace hrg_gyro
