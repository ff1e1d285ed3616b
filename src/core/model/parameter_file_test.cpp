// Parameter file: round trips, key-by-key rejections with the key named, atomic save with backup.
#include "hrg_gyro/core/model/parameter_file.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/testing/concurrent_writers.h"
#include "core/testing/uniform_draws.h"

namespace hrg_gyro {
namespace core {
namespace {

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class TempDir {
 public:
  TempDir() {
    char tmpl[] = "/tmp/hrg_param_test_XXXXXX";
    path_ = mkdtemp(tmpl);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string file(const std::string& name) const { return path_ + "/" + name; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

GyroParameters sampleParameters() {
  GyroParameters p;
  p.scale_factor = HarmonicModel({2, 4, 6, 8}, -0.5583127, {-3.3e-4, 7.501e-4, 1.0 / 3.0 * 1e-5, -2e-7},
                                 {2.2e-4, 1e-6, -5e-7, 0.1 / 7.0 * 1e-4});
  p.drift = HarmonicModel({2, 4}, 1.0e-5, {2.0e-5, 3e-7}, {-1.0e-5, 0.0});
  p.correction.p = {1.1e-3, -2.2e-3, 4.5e-4, -3.3e-4};
  p.earth_rate.latitude = 0.9302;
  p.calibration.method = ParameterOrigin::calibratedBy(CalibrationMethodKind::kDualRate);
  p.calibration.time = "2026-11-21T10:00:00Z";
  p.calibration.source = "live";
  p.calibration.notes = "test: \"quoted\", colon: yes";
  return p;
}

// A valid text to mutate key by key.
const char* kValid = R"(schema_version: 1
scale_factor:
  orders: [2, 4]
  mean: -0.56
  cos: [1.0e-3, 2.0e-4]
  sin: [0.0, -1.0e-4]
drift:
  orders: [2]
  mean: 1.0e-5
  cos: [2.0e-5]
  sin: [0.0]
correction_matrix:
  p: [0.0, 0.0, 0.0, 0.0]
earth_rate:
  enabled: true
  latitude: 0.9
)";

std::string replaced(const std::string& from, const std::string& to) {
  std::string s = kValid;
  const auto pos = s.find(from);
  EXPECT_NE(pos, std::string::npos) << from;
  return s.replace(pos, from.size(), to);
}

// Expects a ConfigError whose key is `key` and whose message contains `fragment`.
void expectRejected(const std::string& text, const std::string& key, const std::string& fragment) {
  try {
    parseParameterText(text);
    ADD_FAILURE() << "accepted, expected rejection of " << key;
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(ParameterFileTest, ValidTextParses) {
  const GyroParameters p = parseParameterText(kValid);
  EXPECT_EQ(p.scale_factor.orders(), (std::vector<int>{2, 4}));
  EXPECT_DOUBLE_EQ(p.scale_factor(0.0), -0.56 + 1e-3 + 2e-4);
  EXPECT_DOUBLE_EQ(p.drift.meanAt(NAN), 1e-5);
  EXPECT_TRUE(p.earth_rate.enabled);
  EXPECT_TRUE(p.calibration.method.isNone());
}

TEST(ParameterFileTest, RoundTripIsExact) {
  testing::UniformDraws u(1);
  for (int trial = 0; trial < 50; ++trial) {
    GyroParameters p = sampleParameters();
    p.scale_factor =
        HarmonicModel({2, 4}, -0.3 - 0.3 * std::abs(u()), {1e-3 * u(), 1e-4 * u()}, {1e-3 * u(), std::ldexp(u(), -40)});
    p.correction.p = {1e-3 * u(), 1e-3 * u(), 1e-3 * u(), 1e-3 * u()};
    const std::string text = emitParameters(p);
    const GyroParameters back = parseParameterText(text);
    EXPECT_TRUE(back == p) << text;
    EXPECT_EQ(emitParameters(back), text);
  }
}

TEST(ParameterFileTest, FrequencyDependentRoundTrip) {
  GyroParameters p = sampleParameters();
  Eigen::MatrixXd v(3, 3);
  v << -0.56, -0.5601, -0.5603, 1e-3, 1.1e-3, 1.3e-3, -2e-4, -2.5e-4, -2.7e-4;
  p.scale_factor = HarmonicModel({2}, FrequencyInterpolator({4990.0, 5000.0, 5010.5}), v);
  const std::string text = emitParameters(p);
  const GyroParameters back = parseParameterText(text);
  EXPECT_TRUE(back == p) << text;
  EXPECT_TRUE(back.scale_factor.frequencyDependent());
}

TEST(ParameterFileTest, EmittedFileIsCommented) {
  const std::string text = emitParameters(sampleParameters());
  EXPECT_NE(text.find("# hrg_gyro parameter file"), std::string::npos);
  EXPECT_NE(text.find("rad/s of electrical angle"), std::string::npos);
  EXPECT_NE(text.find("(E - P) Z"), std::string::npos);
}

TEST(ParameterFileTest, RejectsBadKeysNamingThem) {
  expectRejected(replaced("schema_version: 1\n", ""), "schema_version", "missing");
  expectRejected(replaced("schema_version: 1", "schema_version: 2"), "schema_version", "unsupported");
  expectRejected(replaced("  mean: -0.56", "  mean: 0.0"), "scale_factor.mean", "non-zero");
  expectRejected(replaced("  mean: -0.56", "  mean: 0.56"), "scale_factor.mean", "negative");
  expectRejected(replaced("  mean: -0.56", "  mean: abc"), "scale_factor.mean", "expected a number");
  expectRejected(replaced("  mean: -0.56", "  mean: .nan"), "scale_factor.mean", "finite");
  expectRejected(replaced("  mean: -0.56", "  mean: .inf"), "scale_factor.mean", "finite");
  expectRejected(replaced("  orders: [2, 4]", "  orders: [2, 3]"), "scale_factor.orders[1]", "odd");
  expectRejected(replaced("  orders: [2, 4]", "  orders: [4, 2]"), "scale_factor.orders[1]", "increasing");
  expectRejected(replaced("  orders: [2, 4]", "  orders: [2, 4.5]"), "scale_factor.orders[1]", "integer");
  expectRejected(replaced("  cos: [1.0e-3, 2.0e-4]", "  cos: [1.0e-3]"), "scale_factor.cos", "expected 2 entries");
  expectRejected(replaced("  sin: [0.0, -1.0e-4]", "  sin: 0.0"), "scale_factor.sin", "expected a list");
  expectRejected(replaced("  cos: [1.0e-3, 2.0e-4]", "  cos: [0.2, 0.2]"), "scale_factor", "keeps its sign");
  expectRejected(replaced("  mean: 1.0e-5", "  mean: 1.0"), "drift", "plausible");
  expectRejected(replaced("  p: [0.0, 0.0, 0.0, 0.0]", "  p: [0.0, 0.0, 0.0]"), "correction_matrix.p", "expected 4");
  expectRejected(replaced("  latitude: 0.9", "  latitude: 2.0"), "earth_rate.latitude", "pi/2");
  expectRejected(replaced("  enabled: true", "  enabled: maybe"), "earth_rate.enabled", "true or false");
  expectRejected(replaced("scale_factor:", "scale_factr:"), "scale_factr", "unknown key");
  expectRejected(replaced("  orders: [2]", "  orders: [2]\n  extra: 1"), "drift.extra", "unknown key");
  expectRejected(replaced("  orders: [2, 4]", "  orders: [2, 4]\n  frequency_nodes: [5000.0, 4990.0]"),
                 "scale_factor.frequency_nodes[1]", "strictly increasing");
  expectRejected(replaced("  orders: [2, 4]", "  orders: [2, 4]\n  frequency_nodes: [4990.0, 5000.0]"),
                 "scale_factor.mean", "one per frequency node");
  expectRejected("", "", "YAML map");
  // Found by the fuzzer: text that is not UTF-8 would not read back as written.
  expectRejected(std::string(kValid) + "calibration:\n  notes: \"a\xff\"\n", "calibration.notes", "UTF-8");
  expectRejected(std::string(kValid) + "calibration:\n  time: \"\xc0\xaf\"\n", "calibration.time", "UTF-8");
  EXPECT_NO_THROW(
      parseParameterText(std::string(kValid) + "calibration:\n  notes: \"d\xc3\xa9j\xc3\xa0 vu \xe2\x9c\x93\"\n"));
  // Found by the fuzzer: a map or a list used as a key escaped as a yaml-cpp conversion error.
  expectRejected(replaced("earth_rate:", "{e: 0}: 1\nearth_rate:"), "", "plain names");
  expectRejected(replaced("  enabled: true", "  [a, b]: 1\n  enabled: true"), "earth_rate", "plain names");
  expectRejected("scale_factor: [1, 2", "", "syntax error");
}

// Every node may be within limits while the spline between them is not: a plateau of large cos 2theta
// values at two nodes bulges to 0.32 between them (|K0|/2 = 0.28). Piecewise-linear interpolation
// of the same nodes cannot overshoot and is accepted.
TEST(ParameterFileTest, SplineOvershootBetweenNodesIsRejected) {
  const std::string sf =
      "scale_factor:\n  orders: [2]\n  frequency_nodes: [4990.0, 5000.0, 5010.0, 5020.0]\n"
      "  mean: [-0.56, -0.56, -0.56, -0.56]\n  cos: [[0.0, 0.279, 0.279, 0.0]]\n"
      "  sin: [[0.0, 0.0, 0.0, 0.0]]\n";
  const std::string old_sf =
      "scale_factor:\n  orders: [2, 4]\n  mean: -0.56\n  cos: [1.0e-3, 2.0e-4]\n"
      "  sin: [0.0, -1.0e-4]\n";
  ASSERT_NE(std::string(kValid).find(old_sf), std::string::npos);
  const std::string spline = replaced(old_sf, sf);
  expectRejected(spline, "scale_factor", "between frequency nodes 1 and 2");
  const std::string linear = replaced(old_sf, sf + "  interpolation: piecewise_linear\n");
  EXPECT_NO_THROW(parseParameterText(linear));
}

TEST(ParameterFileTest, TruncatedFilesAreRejected) {
  const std::string text = emitParameters(sampleParameters());
  for (std::size_t cut : {std::size_t(0), text.size() / 4, text.size() / 2, text.size() * 3 / 4}) {
    EXPECT_THROW(parseParameterText(text.substr(0, cut)), ConfigError) << cut;
  }
}

TEST(ParameterFileTest, UnreadablePathIsReportedWithThePath) {
  try {
    loadParameterFile("/nonexistent/dir/params.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/params.yaml"), std::string::npos);
  }
}

TEST(ParameterFileTest, AtomicSaveKeepsBackupAndLeavesNoTemporaries) {
  TempDir dir;
  const std::string path = dir.file("params.yaml");
  GyroParameters first = sampleParameters();
  saveParameterFile(path, first);
  EXPECT_TRUE(loadParameterFile(path) == first);
  GyroParameters second = first;
  second.correction.p[0] = 5e-4;
  saveParameterFile(path, second);
  EXPECT_TRUE(loadParameterFile(path) == second);
  EXPECT_TRUE(loadParameterFile(path + ".bak") == first);
  // Only the file and its backup remain.
  std::set<std::string> listing;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) listing.insert(entry.path().filename());
  EXPECT_EQ(listing, (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
}

TEST(ParameterFileTest, RefusesToWriteInvalidParametersAndKeepsTheOldFile) {
  TempDir dir;
  const std::string path = dir.file("params.yaml");
  saveParameterFile(path, sampleParameters());
  const std::string before = readText(path);
  GyroParameters bad = sampleParameters();
  bad.scale_factor = HarmonicModel(0.3);  // wrong sign
  EXPECT_THROW(saveParameterFile(path, bad), std::runtime_error);
  EXPECT_EQ(readText(path), before);
}

TEST(ParameterFileTest, UnwritableDirectoryFailsCleanly) {
  if (geteuid() == 0) {
    // root ignores directory permissions; use a path whose directory does not exist instead.
    EXPECT_THROW(saveParameterFile("/nonexistent/dir/params.yaml", sampleParameters()), std::runtime_error);
    return;
  }
  TempDir dir;
  const std::string path = dir.file("params.yaml");
  saveParameterFile(path, sampleParameters());
  chmod(dir.path().c_str(), 0555);
  EXPECT_THROW(saveParameterFile(path, sampleParameters()), std::runtime_error);
  chmod(dir.path().c_str(), 0755);
}

// A frequency-dependent scale factor with `nodes` nodes, spaced 1 Hz from 4990 Hz.
std::string withFrequencyNodes(std::size_t nodes) {
  std::string list, means, zeros;
  for (std::size_t j = 0; j < nodes; ++j) {
    const std::string sep = j == 0 ? "" : ", ";
    list += sep + std::to_string(4990 + j) + ".0";
    means += sep + "-0.56";
    zeros += sep + "0.0";
  }
  return replaced("  orders: [2, 4]\n  mean: -0.56\n  cos: [1.0e-3, 2.0e-4]\n  sin: [0.0, -1.0e-4]\n",
                  "  orders: [2]\n  frequency_nodes: [" + list + "]\n  mean: [" + means + "]\n  cos: [[" + zeros +
                      "]]\n  sin: [[" + zeros + "]]\n");
}

TEST(ParameterFileTest, DuplicateKeysAreRefusedWithTheirPath) {
  // yaml-cpp keeps the first of two equal keys; the second must not be dropped without a word.
  expectRejected(std::string(kValid) + "earth_rate:\n  enabled: false\n  latitude: 0.1\n", "earth_rate",
                 "more than once");
  expectRejected(replaced("  mean: -0.56", "  mean: -0.56\n  mean: -0.57"), "scale_factor.mean", "more than once");
  expectRejected(replaced("  latitude: 0.9", "  latitude: 0.9\n  enabled: false"), "earth_rate.enabled",
                 "more than once");
}

TEST(ParameterFileTest, FrequencyNodeCountIsLimitedBeforeAnyWork) {
  EXPECT_NO_THROW(parseParameterText(withFrequencyNodes(kMaxFrequencyNodes)));
  expectRejected(withFrequencyNodes(kMaxFrequencyNodes + 1), "scale_factor.frequency_nodes",
                 "at most 64 frequency nodes");
  // 20000 nodes used to end in bad_alloc after minutes of cubic work: now refused at once.
  const std::string huge = withFrequencyNodes(20000);
  const auto start = std::chrono::steady_clock::now();
  expectRejected(huge, "scale_factor.frequency_nodes", "got 20000");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
}

TEST(ParameterFileTest, ScaleFactorMeanMustBePhysical) {
  // -1e308 made the output stop integrating, -1e-300 made the processor reject most samples.
  for (const char* k0 : {"-1.0e308", "-1.0e-300", "-2.5", "-0.005"}) {
    expectRejected(replaced("  mean: -0.56", std::string("  mean: ") + k0), "scale_factor.mean",
                   "|K0| must be in [0.01, 2.0]");
  }
  for (const char* k0 : {"-0.01", "-2.0", "-0.3", "-1.12"}) {
    EXPECT_NO_THROW(parseParameterText(replaced("  mean: -0.56", std::string("  mean: ") + k0))) << k0;
  }
  // The same bound at every frequency node.
  const std::string nodes =
      replaced("  orders: [2, 4]\n  mean: -0.56\n  cos: [1.0e-3, 2.0e-4]\n  sin: [0.0, -1.0e-4]\n",
               "  orders: [2]\n  frequency_nodes: [4990.0, 5010.0]\n  interpolation: piecewise_linear\n"
               "  mean: [-0.56, -1.0e-300]\n  cos: [[0.0, 0.0]]\n  sin: [[0.0, 0.0]]\n");
  expectRejected(nodes, "scale_factor.mean", "at frequency node 1");
}

/// Runs loadParameterFile(path) in a child limited to 5 s and 512 MiB; returns its message, or how
/// the child died (a read that hangs or grows without bound fails the test instead of the machine).
std::string loadInChild(const std::string& path) {
  int fds[2];
  if (::pipe(fds) != 0) return "pipe failed";
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(fds[0]);
    ::alarm(5);
    const rlimit memory{512u << 20, 512u << 20};
    ::setrlimit(RLIMIT_AS, &memory);
    std::string outcome = "loaded";
    try {
      loadParameterFile(path);
    } catch (const ConfigError& e) {
      outcome = e.what();
    } catch (const std::exception& e) {
      outcome = std::string("not a ConfigError: ") + e.what();
    }
    if (::write(fds[1], outcome.data(), outcome.size()) < 0) ::_exit(2);
    ::_exit(0);
  }
  ::close(fds[1]);
  std::string outcome;
  char buffer[512];
  ssize_t n;
  while ((n = ::read(fds[0], buffer, sizeof buffer)) > 0) outcome.append(buffer, static_cast<std::size_t>(n));
  ::close(fds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  if (WIFSIGNALED(status)) return "child killed by signal " + std::to_string(WTERMSIG(status));
  return outcome;
}

TEST(ParameterFileTest, OnlyABoundedRegularFileIsRead) {
  TempDir dir;
  ASSERT_EQ(::mkfifo(dir.file("fifo.yaml").c_str(), 0644), 0);
  const std::string fifo = loadInChild(dir.file("fifo.yaml"));
  EXPECT_NE(fifo.find("is a FIFO"), std::string::npos) << fifo;
  const std::string zero = loadInChild("/dev/zero");
  EXPECT_NE(zero.find("is a character device"), std::string::npos) << zero;
  const std::string directory = loadInChild(dir.path());
  EXPECT_NE(directory.find("is a directory, not a parameter file"), std::string::npos) << directory;
  // Size: a valid file padded with a comment to exactly the limit loads; one byte more is refused.
  std::string text = kValid;
  const std::string padding = "#" + std::string(kMaxParameterFileBytes - text.size() - 2, 'x') + "\n";
  text += padding;
  {
    std::ofstream(dir.file("limit.yaml"), std::ios::binary) << text;
    std::ofstream(dir.file("over.yaml"), std::ios::binary) << text << "\n";
  }
  ASSERT_EQ(std::filesystem::file_size(dir.file("limit.yaml")), kMaxParameterFileBytes);
  EXPECT_NO_THROW(loadParameterFile(dir.file("limit.yaml")));
  const std::string over = loadInChild(dir.file("over.yaml"));
  EXPECT_NE(over.find("above the limit of 1048576 bytes"), std::string::npos) << over;
}

TEST(ParameterFileTest, SaveKeepsTheModeAndTheSymbolicLink) {
  TempDir dir;
  std::filesystem::create_directories(dir.file("deployed"));
  const std::string target = dir.file("deployed/params.yaml"), link = dir.file("params.yaml");
  saveParameterFile(target, sampleParameters());
  ASSERT_EQ(::chmod(target.c_str(), 0640), 0);
  ASSERT_EQ(::symlink("deployed/params.yaml", link.c_str()), 0);
  GyroParameters second = sampleParameters();
  second.correction.p[0] = 5e-4;
  saveParameterFile(link, second);
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_TRUE(loadParameterFile(target) == second);
  EXPECT_TRUE(loadParameterFile(target + ".bak") == sampleParameters());
  EXPECT_FALSE(std::filesystem::exists(link + ".bak"));
  struct stat st {};
  ASSERT_EQ(::stat(target.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640u);
}

// Two calibrators saving one file: before, they collided on one fixed backup temporary name.
TEST(ParameterFileTest, TwoWritersOfOneFileBothSucceed) {
  TempDir dir;
  const std::string path = dir.file("params.yaml");
  GyroParameters a = sampleParameters(), b = sampleParameters();
  b.correction.p[0] = 5e-4;
  saveParameterFile(path, a);
  const std::vector<bool> ok = testing::runConcurrentWriters(2, [&](int c) {
    for (int i = 0; i < 150; ++i) saveParameterFile(path, c == 0 ? a : b);
  });
  EXPECT_EQ(ok, std::vector<bool>(2, true)) << "a writer failed (see its message above)";
  const GyroParameters now = loadParameterFile(path), backup = loadParameterFile(path + ".bak");
  EXPECT_TRUE(now == a || now == b);
  EXPECT_TRUE(backup == a || backup == b);
  std::set<std::string> listing;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) listing.insert(entry.path().filename());
  EXPECT_EQ(listing, (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
}

TEST(ParameterFileTest, ShippedConfigurationFilesAreValid) {
  const std::string root = HRG_GYRO_SOURCE_DIR;
  for (const char* name : {"config/params_uncalibrated.yaml"}) {
    EXPECT_NO_THROW(loadParameterFile(root + "/" + name)) << name;
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
