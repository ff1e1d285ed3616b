#include "hrg_gyro/core/calibration/triad/triad_result_files.h"

#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/stat.h>

#include <cerrno>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "core/testing/output_directory_test_base.h"
#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/model/triad_file.h"

namespace hrg_gyro {
namespace core {
namespace {

namespace fs = std::filesystem;
using fault_injection::OutputFileStep;

TriadOutcome acceptedOutcome() {
  TriadOutcome o;
  o.accepted = true;
  o.axis_names = {{"x", "y", "z"}};
  for (int i = 0; i < 3; ++i) {
    o.axes[i].accepted = true;
    o.axes[i].parameters.scale_factor = HarmonicModel(-0.3 - 0.01 * i);
    o.axes[i].parameters.earth_rate.latitude = 0.97;
    o.axes[i].parameters.calibration.source = "session.bag";
  }
  o.triad.axis_to_body << 1.0, 2e-5, -1e-5, -3e-5, 1.0, 4e-5, 1e-5, -2e-5, 1.0;
  o.triad.bias << 1e-8, 2e-8, -1e-8;
  o.triad.calibration.source = "session.bag";
  return o;
}

class TriadResultFilesTest : public OutputDirectoryTestBase {
 protected:
  void SetUp() override {
    OutputDirectoryTestBase::SetUp();
    paths_.triad = dir_ + "/triad.yaml";
    for (int i = 0; i < 3; ++i) paths_.axes[i] = dir_ + "/" + std::string(1, "xyz"[i]) + ".yaml";
  }
  TriadResultPaths paths_;
};

TEST_F(TriadResultFilesTest, WritesTheFourFilesThatReadBackAsCalibrated) {
  const TriadOutcome o = acceptedOutcome();
  const std::vector<std::string> written = saveTriadResult(o, paths_);
  ASSERT_EQ(written.size(), 4u);
  EXPECT_EQ(written.back(), paths_.triad);  // the file that ties the axes together goes last
  for (int i = 0; i < 3; ++i) EXPECT_EQ(loadParameterFile(paths_.axes[i]), o.axes[i].parameters);
  EXPECT_EQ(loadTriadFile(paths_.triad), o.triad);
  EXPECT_EQ(listing(), (std::set<std::string>{"triad.yaml", "x.yaml", "y.yaml", "z.yaml"}));

  // A second run replaces them and keeps the first as .bak.
  TriadOutcome again = o;
  again.triad.bias(0) = 5e-8;
  saveTriadResult(again, paths_);
  EXPECT_EQ(loadTriadFile(paths_.triad), again.triad);
  EXPECT_EQ(loadTriadFile(paths_.triad + ".bak"), o.triad);
  EXPECT_EQ(loadParameterFile(paths_.axes[0] + ".bak"), o.axes[0].parameters);
}

TEST_F(TriadResultFilesTest, ARefusedOrInvalidResultTouchesNothing) {
  TriadOutcome refused = acceptedOutcome();
  refused.accepted = false;
  refused.reason = "positions";
  EXPECT_THROW(saveTriadResult(refused, paths_), std::runtime_error);
  EXPECT_TRUE(listing().empty());

  // The triad is checked before any axis file is written: a misalignment beyond the loader's limit.
  TriadOutcome invalid = acceptedOutcome();
  invalid.triad.axis_to_body(0, 1) = 0.5;
  try {
    saveTriadResult(invalid, paths_);
    FAIL() << "an invalid triad was written";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("axis_to_body"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(listing().empty());

  TriadResultPaths same = paths_;
  same.axes[2] = same.axes[1];
  EXPECT_THROW(saveTriadResult(acceptedOutcome(), same), std::runtime_error);
  EXPECT_TRUE(listing().empty());
}

/// Every file of the directory with its content (and inode): what a failed write must leave as it was.
std::map<std::string, std::pair<std::string, ino_t>> snapshot(const std::string& dir) {
  std::map<std::string, std::pair<std::string, ino_t>> state;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::ifstream in(e.path(), std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    struct stat st {};
    ::lstat(e.path().c_str(), &st);
    state[e.path().filename().string()] = {text.str(), st.st_ino};
  }
  return state;
}

/// The next calibration: every file's content differs from acceptedOutcome()'s.
TriadOutcome nextOutcome() {
  TriadOutcome next = acceptedOutcome();
  for (int i = 0; i < 3; ++i) next.axes[i].parameters.scale_factor = HarmonicModel(-0.31 - 0.01 * i);
  next.triad.bias(1) = 7e-8;
  return next;
}

class TriadResultSetTest : public TriadResultFilesTest {
 protected:
  /// An old set with its backups: two saves of different outcomes, the second over the first.
  void SetUp() override {
    TriadResultFilesTest::SetUp();
    TriadOutcome first = acceptedOutcome();
    first.triad.bias(2) = -3e-8;
    saveTriadResult(first, paths_);
    saveTriadResult(acceptedOutcome(), paths_);
    old_ = snapshot(dir_);
    ASSERT_EQ(old_.size(), 8u);  // four files, four .bak
  }
  /// The set written with `fault` injected: it must fail with a message holding `fragments`, and leave
  /// the old set, its backups and nothing else exactly as they were (the same inodes, too).
  void expectOldSetWhole(const fault_injection::OutputFileFault& fault, const std::vector<std::string>& fragments,
                         const std::string& label) {
    fault_injection::setOutputFileFault(fault);
    try {
      saveTriadResult(nextOutcome(), paths_);
      ADD_FAILURE() << label << ": the injected failure was not reported";
    } catch (const BackupNotKept& e) {
      ADD_FAILURE() << label << ": reported as written: " << e.what();
    } catch (const std::runtime_error& e) {
      for (const std::string& f : fragments)
        EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << label << ": " << e.what();
    }
    fault_injection::setOutputFileFault({});
    EXPECT_EQ(snapshot(dir_), old_) << label;
  }
  std::array<std::string, 4> targets() const {
    return {{paths_.axes[0], paths_.axes[1], paths_.axes[2], paths_.triad}};
  }
  std::map<std::string, std::pair<std::string, ino_t>> old_;
};

// A full disk, a failed sync or a failed backup link at any member, the first, a middle one or the
// last: nothing is renamed before every member is complete, so the old set stays whole.
TEST_F(TriadResultSetTest, AFailureBeforeTheRenamesLeavesTheOldSetWhole) {
  for (const OutputFileFault& c : faultsBeforeTheRename()) {
    for (const std::string& failing : {paths_.axes[0], paths_.axes[1], paths_.triad}) {
      expectOldSetWhole([&](OutputFileStep step,
                            const std::string& target) { return step == c.step && target == failing ? c.error : 0; },
                        {c.message, failing, "nothing of the set was replaced"},
                        failing + " step " + std::to_string(static_cast<int>(c.step)));
    }
  }
  // Every member's write fails (a disk that is full from the start).
  expectOldSetWhole([](OutputFileStep step, const std::string&) { return step == OutputFileStep::kWrite ? ENOSPC : 0; },
                    {"No space left on device", paths_.axes[0]}, "every write");
}

// The read-back of a member fails (its temporary damaged on the disk after it was written): the old
// set stays whole.
TEST_F(TriadResultSetTest, AFailedReadBackLeavesTheOldSetWhole) {
  for (const std::string& failing : {paths_.axes[1], paths_.triad}) {
    const std::string base = fs::path(failing).filename().string() + ".tmp.";
    expectOldSetWhole(
        [&](OutputFileStep step, const std::string& target) {
          if (step != OutputFileStep::kSync || target != failing) return 0;
          for (const auto& e : fs::directory_iterator(dir_)) {
            if (e.path().filename().string().rfind(base, 0) == 0) fs::resize_file(e.path(), 0);  // its content gone
          }
          return 0;
        },
        {failing}, "read-back of " + failing);
  }
}

// A rename fails after others succeeded: those are put back from the versions linked aside, so the
// old set, its backups and their inodes are as they were.
TEST_F(TriadResultSetTest, AFailedRenamePutsBackTheFilesAlreadyRenamed) {
  for (const std::string& failing : {paths_.axes[0], paths_.axes[2], paths_.triad}) {
    const std::string put_back = failing == paths_.axes[0] ? "nothing of the set was replaced" : "were put back";
    expectOldSetWhole(
        [&](OutputFileStep step, const std::string& target) {
          return step == OutputFileStep::kRename && target == failing ? EIO : 0;
        },
        {"cannot rename", failing, put_back}, "rename of " + failing);
  }
}

// Files that did not exist: a failed rename removes the members already renamed.
TEST_F(TriadResultFilesTest, AFailedRenameOfANewSetLeavesNoFile) {
  fault_injection::setOutputFileFault([&](OutputFileStep step, const std::string& target) {
    return step == OutputFileStep::kRename && target == paths_.triad ? EXDEV : 0;
  });
  EXPECT_THROW(saveTriadResult(acceptedOutcome(), paths_), std::runtime_error);
  fault_injection::setOutputFileFault({});
  EXPECT_TRUE(listing().empty());
}

// Putting one back fails as well: the message names it and where its previous version is; nothing
// else is lost.
TEST_F(TriadResultSetTest, AFileThatCannotBePutBackIsNamedWithItsPreviousVersion) {
  fault_injection::setOutputFileFault([&](OutputFileStep step, const std::string& target) {
    if (step == OutputFileStep::kRename && target == paths_.triad) return EIO;
    return step == OutputFileStep::kRestore && target == paths_.axes[1] ? EIO : 0;
  });
  std::string what;
  try {
    saveTriadResult(nextOutcome(), paths_);
    FAIL() << "the injected failure was not reported";
  } catch (const std::runtime_error& e) {
    what = e.what();
  }
  fault_injection::setOutputFileFault({});
  EXPECT_NE(what.find("the set is mixed"), std::string::npos) << what;
  EXPECT_NE(what.find("could not put back the previous '" + paths_.axes[1] + "'"), std::string::npos) << what;
  EXPECT_NE(what.find("put back: " + paths_.axes[2] + ", " + paths_.axes[0]), std::string::npos) << what;
  const std::string marker = "the previous one is '";
  const std::size_t at = what.find(marker);
  ASSERT_NE(at, std::string::npos) << what;
  const std::string kept = what.substr(at + marker.size(), what.find('\'', at + marker.size()) - at - marker.size());
  const auto now = snapshot(dir_);
  for (const auto& kv : old_) {
    if (kv.first == "y.yaml") continue;
    EXPECT_EQ(now.at(kv.first), kv.second) << kv.first;
  }
  EXPECT_EQ(loadParameterFile(paths_.axes[1]), nextOutcome().axes[1].parameters);
  EXPECT_EQ(now.at(fs::path(kept).filename().string()), old_.at("y.yaml"));  // the previous y, whole
  EXPECT_EQ(now.size(), old_.size() + 1);
}

// After every rename, a backup that cannot be kept: the new set is in place (BackupNotKept says so).
TEST_F(TriadResultSetTest, ABackupNotKeptAfterTheRenamesLeavesTheNewSet) {
  fault_injection::setOutputFileFault([&](OutputFileStep step, const std::string& target) {
    return step == OutputFileStep::kKeepBackup && target == paths_.axes[1] ? EIO : 0;
  });
  try {
    saveTriadResult(nextOutcome(), paths_);
    FAIL() << "the injected failure was not reported";
  } catch (const BackupNotKept& e) {
    EXPECT_NE(std::string(e.what()).find("the set was written"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(paths_.axes[1] + ".bak"), std::string::npos) << e.what();
  }
  fault_injection::setOutputFileFault({});
  const TriadOutcome next = nextOutcome();
  for (int i = 0; i < 3; ++i) EXPECT_EQ(loadParameterFile(paths_.axes[i]), next.axes[i].parameters);
  EXPECT_EQ(loadTriadFile(paths_.triad), next.triad);
  const auto now = snapshot(dir_);
  EXPECT_EQ(now.at("x.yaml.bak").first, old_.at("x.yaml").first);
  EXPECT_EQ(now.at("y.yaml.bak").first, old_.at("y.yaml.bak").first);  // the earlier backup stays
  EXPECT_EQ(now.at("triad.yaml.bak").first, old_.at("triad.yaml").first);
  EXPECT_EQ(now.size(), 8u);
}

// The inputs a triad calibration reads, each with some content: the priors, the bag, the settings.
void writeInputs(const std::string& dir) {
  for (const char* name : {"triad.yaml", "x.yaml", "y.yaml", "z.yaml", "session.bag", "settings.yaml"}) {
    std::ofstream(dir + "/" + name) << "content\n";
  }
}

// The four outputs in a directory of their own (created).
TriadResultPaths outputsIn(const std::string& dir) {
  fs::create_directory(dir);
  TriadResultPaths outs;
  outs.triad = dir + "/triad.yaml";
  for (int i = 0; i < 3; ++i) outs.axes[i] = dir + "/" + std::string(1, "xyz"[i]) + ".yaml";
  return outs;
}

// `paths` with one output moved: slot 0..2 an axis, 3 the triad file.
TriadResultPaths withSlot(TriadResultPaths paths, int slot, const std::string& path) {
  (slot < 3 ? paths.axes[slot] : paths.triad) = path;
  return paths;
}

// The paths' rule, by file identity: an output may be its own prior, never another input or output.
TEST_F(TriadResultFilesTest, AnOutputMayRefreshItsOwnPriorOnly) {
  writeInputs(dir_);
  const std::string bag = dir_ + "/session.bag", settings = dir_ + "/settings.yaml";
  fs::create_symlink("x.yaml", dir_ + "/link_to_x.yaml");
  fs::create_hard_link(dir_ + "/y.yaml", dir_ + "/hard_y.yaml");
  fs::create_directory(dir_ + "/sub");
  const TriadResultPaths priors = paths_;

  // Each output its own prior (also through a link or another spelling), the nominal triad: accepted.
  EXPECT_NO_THROW(checkTriadPaths(paths_, priors, {bag, settings}, {dir_ + "/report.yaml"}));
  TriadResultPaths spelled = paths_;
  spelled.axes[0] = dir_ + "/link_to_x.yaml";
  spelled.axes[1] = dir_ + "/sub/../hard_y.yaml";
  EXPECT_NO_THROW(checkTriadPaths(spelled, priors, {bag, settings}));
  TriadResultPaths nominal = priors;
  nominal.triad.clear();
  EXPECT_NO_THROW(checkTriadPaths(paths_, nominal, {bag, ""}, {""}));

  // Outputs elsewhere, one of them then put on an input.
  const TriadResultPaths outs = outputsIn(dir_ + "/out");
  EXPECT_NO_THROW(checkTriadPaths(outs, priors, {bag, settings}, {dir_ + "/out/report.yaml"}));
  auto with = [&](int slot, const std::string& path) { return withSlot(outs, slot, path); };
  struct Case {
    TriadResultPaths out;
    std::string report;
    std::string output, input;  // what the message names
  };
  const std::vector<Case> refused{
      {with(3, paths_.axes[0]), "", paths_.axes[0], paths_.axes[0]},  // --out an axis's prior
      {with(0, paths_.triad), "", paths_.triad, paths_.triad},        // an axis's output: the triad prior
      {with(0, paths_.axes[2]), "", paths_.axes[2], paths_.axes[2]},  // another axis's prior
      {with(1, dir_ + "/link_to_x.yaml"), "", dir_ + "/link_to_x.yaml", paths_.axes[0]},      // ... through a link
      {with(0, dir_ + "/hard_y.yaml"), "", dir_ + "/hard_y.yaml", paths_.axes[1]},            // ... a hard link
      {with(2, dir_ + "/sub/../x.yaml"), "", dir_ + "/sub/../x.yaml", paths_.axes[0]},        // ... dir/../
      {with(1, bag), "", bag, bag},                                                           // the bag
      {with(3, settings), "", settings, settings},                                            // the settings
      {outs, paths_.axes[1], paths_.axes[1], paths_.axes[1]},                                 // the report over a prior
      {outs, bag, bag, bag},                                                                  // the report over the bag
      {with(2, outs.axes[0]), "", outs.axes[0], outs.axes[0]},                                // two outputs on one file
      {with(2, dir_ + "/sub/../out/x.yaml"), "", outs.axes[0], dir_ + "/sub/../out/x.yaml"},  // ... a new one
      {outs, outs.triad, outs.triad, outs.triad},                                             // the report on an output
  };
  for (const Case& c : refused) {
    try {
      checkTriadPaths(c.out, priors, {bag, settings}, {c.report});
      ADD_FAILURE() << "accepted: output " << c.output << " over " << c.input;
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("'" + c.output + "'"), std::string::npos) << what;
      EXPECT_NE(what.find("'" + c.input + "'"), std::string::npos) << what;
    }
  }
}

// An output's backup may be neither an input nor another output.
TEST_F(TriadResultFilesTest, ABackupIsNeitherAnInputNorAnotherOutput) {
  writeInputs(dir_);
  const std::string bag = dir_ + "/session.bag";
  const TriadResultPaths priors = paths_, outs = outputsIn(dir_ + "/out");
  auto with = [&](int slot, const std::string& path) { return withSlot(outs, slot, path); };
  TriadResultPaths from_backup = priors;
  from_backup.triad = paths_.triad + ".bak";  // "recalibrate from the backup, into the file"
  std::ofstream(from_backup.triad) << "content\n";
  try {
    checkTriadPaths(paths_, from_backup, {bag});
    ADD_FAILURE() << "the triad file's backup, an input, accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("keeps its previous version as '" + paths_.triad + ".bak'"), std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(checkTriadPaths(paths_, from_backup, {bag}, {}, false));  // written without backups
  EXPECT_THROW(checkTriadPaths(with(3, outs.axes[0] + ".bak"), {}, {}), std::runtime_error);
  EXPECT_THROW(checkTriadPaths(outs, {}, {}, {outs.axes[2] + ".bak"}), std::runtime_error);
  // saveTriadResult applies the rule among its four files: nothing written.
  const auto before = snapshot(dir_);
  EXPECT_THROW(saveTriadResult(acceptedOutcome(), with(3, outs.axes[0] + ".bak")), std::runtime_error);
  EXPECT_EQ(snapshot(dir_), before);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
