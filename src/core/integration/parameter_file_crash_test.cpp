// The calibrator never leaves a partial parameter file: a writer process is killed (SIGKILL) at
// random points while it rewrites the file over and over, and after every kill the file (and its
// backup) must load and equal one of the two parameter sets written, never a mixture or a fragment.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <random>
#include <set>
#include <string>
#include <thread>

#include "hrg_gyro/core/model/parameter_file.h"

namespace hrg_gyro {
namespace core {
namespace {

GyroParameters variant(double k0) {
  GyroParameters p;
  p.scale_factor = HarmonicModel({2, 4, 6, 8}, k0, {1e-4, -2e-5, 3e-6, 1e-7}, {-5e-5, 1e-5, 0.0, 2e-7});
  p.drift = HarmonicModel({2, 4}, 1e-5, {2e-5, 1e-6}, {-1e-5, 0.0});
  p.calibration.method = ParameterOrigin::calibratedBy(CalibrationMethodKind::kDualRate);
  p.calibration.notes = std::string(4000, 'x');  // a file of several pages: many write() points
  return p;
}

TEST(ParameterFileCrash, SigkillDuringWritesNeverLeavesAPartialFile) {
  char dir_template[] = "/tmp/hrg_gyro_crash_XXXXXX";
  ASSERT_NE(::mkdtemp(dir_template), nullptr);
  const std::string path = std::string(dir_template) + "/params.yaml";
  const GyroParameters a = variant(-0.56), b = variant(-0.57);
  // Two saves first: the backup exists from the second on. (With one, a child killed before it
  // finished its first save left no .bak: a fresh-clone run failed that way in round 0.)
  saveParameterFile(path, b);
  saveParameterFile(path, a);
  std::mt19937 rng(42);
  std::uniform_int_distribution<int> delay_us(0, 30000);
  int kills_during_writes = 0;
  for (int round = 0; round < 60; ++round) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      for (unsigned i = 0;; ++i) saveParameterFile(path, i % 2 ? a : b);  // until killed
    }
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    if (WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) ++kills_during_writes;
    GyroParameters now;
    ASSERT_NO_THROW(now = loadParameterFile(path)) << "round " << round;
    EXPECT_TRUE(now == a || now == b) << "round " << round;
    GyroParameters backup;
    ASSERT_NO_THROW(backup = loadParameterFile(path + ".bak")) << "round " << round;
    EXPECT_TRUE(backup == a || backup == b) << "round " << round;
  }
  EXPECT_EQ(kills_during_writes, 60);
  // A kill can leave temporaries (params.yaml.tmp.<pid>.XXXXXX); they are never read, and the next
  // write removes them, since their writers are gone.
  saveParameterFile(path, a);
  std::set<std::string> listing;
  for (const auto& entry : std::filesystem::directory_iterator(dir_template)) listing.insert(entry.path().filename());
  EXPECT_EQ(listing, (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
  std::filesystem::remove_all(dir_template);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
