// The output-file facility: whole-or-nothing replacement that keeps the replaced file's mode,
// owner and symbolic link, unique temporaries for concurrent writers, stale temporaries cleaned,
// failures at every step leaving the old file intact; sets of files (AtomicOutputSet: their members;
// the triad's set is tested in triad_result_files_test.cpp); checkDistinct; the bounded reader.
#include "hrg_gyro/core/common/atomic_file.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/testing/concurrent_writers.h"
#include "core/testing/output_directory_test_base.h"

namespace hrg_gyro {
namespace core {
namespace {

const OutputFileOptions kKeepBackup{true, ""};

namespace fs = std::filesystem;
using fault_injection::OutputFileStep;

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

struct stat statOf(const std::string& path) {
  struct stat st {};
  EXPECT_EQ(::lstat(path.c_str(), &st), 0) << path;
  return st;
}

class AtomicFileTest : public OutputDirectoryTestBase {};

TEST_F(AtomicFileTest, NewFileGetsTheDocumentedModeNarrowedByTheUmask) {
  const mode_t old_umask = ::umask(027);
  writeFileAtomically(at("a.txt"), "one\n");
  ::umask(022);
  writeFileAtomically(at("b.txt"), "two\n");
  ::umask(old_umask);
  EXPECT_EQ(statOf(at("a.txt")).st_mode & 07777, kNewOutputFileMode & ~027);
  EXPECT_EQ(statOf(at("b.txt")).st_mode & 07777, 0644u);
  EXPECT_EQ(readText(at("a.txt")), "one\n");
}

TEST_F(AtomicFileTest, ReplacedFileKeepsItsModeOwnerAndGroup) {
  const std::string path = at("params.yaml");
  writeText(path, "old\n");
  ASSERT_EQ(::chmod(path.c_str(), 0640), 0);
  const bool root = ::geteuid() == 0;
  if (root) {
    ASSERT_EQ(::chown(path.c_str(), 4321, 8765), 0);
  }
  writeFileAtomically(path, "new\n", kKeepBackup);
  EXPECT_EQ(readText(path), "new\n");
  const struct stat st = statOf(path);
  EXPECT_EQ(st.st_mode & 07777, 0640u) << "a 0640 file must not become world-readable";
  if (root) {
    EXPECT_EQ(st.st_uid, 4321u);
    EXPECT_EQ(st.st_gid, 8765u);
  }
  // The backup is the old file itself (same mode, same owner).
  EXPECT_EQ(readText(path + ".bak"), "old\n");
  EXPECT_EQ(statOf(path + ".bak").st_mode & 07777, 0640u);
}

TEST_F(AtomicFileTest, SymbolicLinkStaysALinkAndItsTargetIsReplaced) {
  fs::create_directories(at("deployed"));
  fs::create_directories(at("run"));
  const std::string target = at("deployed/params.yaml"), link = at("run/params.yaml");
  writeText(target, "old\n");
  ASSERT_EQ(::chmod(target.c_str(), 0600), 0);
  ASSERT_EQ(::symlink("../deployed/params.yaml", link.c_str()), 0);  // relative, as deployment tools make them
  AtomicOutputFile file(link, kKeepBackup);
  EXPECT_EQ(file.targetPath(), at("run/../deployed/params.yaml"));
  file.write("new\n");
  file.commit();
  EXPECT_TRUE(S_ISLNK(statOf(link).st_mode)) << "the link must stay a link";
  EXPECT_EQ(fs::read_symlink(link).string(), "../deployed/params.yaml");
  EXPECT_EQ(readText(target), "new\n") << "readers of the link's target must see the new file";
  EXPECT_EQ(statOf(target).st_mode & 07777, 0600u);
  // The backup sits beside the target, as a regular file; nothing else appears beside the link.
  EXPECT_EQ(readText(target + ".bak"), "old\n");
  EXPECT_TRUE(S_ISREG(statOf(target + ".bak").st_mode));
  EXPECT_EQ(listing(at("run")), (std::set<std::string>{"params.yaml"}));
  EXPECT_EQ(listing(at("deployed")), (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
}

TEST_F(AtomicFileTest, ChainsOfLinksAndDanglingLinksAreFollowed) {
  writeText(at("real"), "old\n");
  ASSERT_EQ(::symlink(at("real").c_str(), at("hop1").c_str()), 0);
  ASSERT_EQ(::symlink("hop1", at("hop2").c_str()), 0);
  writeFileAtomically(at("hop2"), "new\n");
  EXPECT_EQ(readText(at("real")), "new\n");
  EXPECT_TRUE(S_ISLNK(statOf(at("hop2")).st_mode));
  // A link to a file that does not exist yet creates that file.
  ASSERT_EQ(::symlink("later", at("dangling").c_str()), 0);
  writeFileAtomically(at("dangling"), "created\n");
  EXPECT_EQ(readText(at("later")), "created\n");
  EXPECT_TRUE(S_ISLNK(statOf(at("dangling")).st_mode));
  // A loop is refused with a message, not followed forever.
  ASSERT_EQ(::symlink("loop_b", at("loop_a").c_str()), 0);
  ASSERT_EQ(::symlink("loop_a", at("loop_b").c_str()), 0);
  try {
    writeFileAtomically(at("loop_a"), "x");
    ADD_FAILURE() << "a link loop was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("symbolic links"), std::string::npos) << e.what();
  }
}

TEST_F(AtomicFileTest, RefusesToReplaceSomethingThatIsNotARegularFile) {
  fs::create_directories(at("dir"));
  ASSERT_EQ(::mkfifo(at("fifo").c_str(), 0644), 0);
  for (const auto& [path, kind] : {std::pair<std::string, std::string>{at("dir"), "a directory"},
                                   {at("fifo"), "a FIFO"},
                                   {"/dev/full", "a character device"}}) {
    try {
      writeFileAtomically(path, "x");
      ADD_FAILURE() << path << " was replaced";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(kind), std::string::npos) << e.what();
    }
  }
  EXPECT_TRUE(fs::is_directory(at("dir")));
  EXPECT_TRUE(fs::is_fifo(at("fifo")));
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
}

TEST_F(AtomicFileTest, ConcurrentWritersUseTheirOwnTemporaries) {
  const std::string path = at("params.yaml");
  writeText(path, "original\n");
  AtomicOutputFile first(path, kKeepBackup), second(path, kKeepBackup);
  EXPECT_NE(first.temporaryPath(), second.temporaryPath());
  first.write("first\n");
  second.write("second\n");
  first.commit();
  second.commit();
  EXPECT_EQ(readText(path), "second\n");
  EXPECT_EQ(readText(path + ".bak"), "first\n");
  EXPECT_EQ(listing(), (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
}

// A second writer runs its whole write (with backup) while the first holds its backup temporary
// link and is about to rename: with a shared backup temporary name one of them failed.
TEST_F(AtomicFileTest, BackupTemporariesAreUniqueToo) {
  const std::string path = at("params.yaml");
  writeText(path, "original\n");
  bool nested_done = false;
  fault_injection::setOutputFileFault([&](OutputFileStep step, const std::string&) {
    if (step == OutputFileStep::kRename && !nested_done) {
      nested_done = true;
      writeFileAtomically(path, "second\n", kKeepBackup);
    }
    return 0;
  });
  EXPECT_NO_THROW(writeFileAtomically(path, "first\n", kKeepBackup));
  EXPECT_TRUE(nested_done);
  EXPECT_EQ(readText(path), "first\n");
  EXPECT_EQ(readText(path + ".bak"), "original\n");  // what the first writer replaced, as it saw it
  EXPECT_EQ(listing(), (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
}

// Two processes rewrite one file with backups as fast as they can: neither may ever fail.
TEST_F(AtomicFileTest, TwoProcessesWritingOneFileBothSucceed) {
  const std::string path = at("params.yaml");
  writeText(path, "a\n");
  const std::vector<bool> ok = testing::runConcurrentWriters(2, [&](int c) {
    for (int i = 0; i < 300; ++i) writeFileAtomically(path, c == 0 ? "a\n" : "b\n", kKeepBackup);
  });
  EXPECT_EQ(ok, std::vector<bool>(2, true)) << "a writer failed (see its message above)";
  const std::string now = readText(path), backup = readText(path + ".bak");
  EXPECT_TRUE(now == "a\n" || now == "b\n") << now;
  EXPECT_TRUE(backup == "a\n" || backup == "b\n") << backup;
  EXPECT_EQ(listing(), (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
}

TEST_F(AtomicFileTest, StaleTemporariesOfKilledWritersAreRemovedAtTheNextWrite) {
  // A process id that is certainly gone: a child that has exited and been reaped.
  const pid_t gone = ::fork();
  ASSERT_GE(gone, 0);
  if (gone == 0) ::_exit(0);
  ASSERT_EQ(::waitpid(gone, nullptr, 0), gone);
  const std::string g = std::to_string(gone), alive = std::to_string(::getppid());
  const std::set<std::string> stale = {"params.yaml.tmp." + g + ".Ab12Cd", "params.yaml.bak.tmp." + g + ".zZ09aa",
                                       "params.yaml.tmp.Xy34Zw" /* earlier writer's name, an hour old */,
                                       "params.yaml.bak.tmp" /* ditto */};
  const std::set<std::string> kept = {
      "params.yaml.tmp." + alive + ".Ab12Cd",  // its writer may still be at work
      "params.yaml.tmp.notes",                 // not one of our names
      "other.yaml.tmp." + g + ".Ab12Cd",       // another file's
      "params.yaml.tmp." + g + ".recent",      // ours and orphaned, but written after this write began
  };
  const auto old_enough = fs::file_time_type::clock::now() - std::chrono::hours(2);
  for (const auto& name : stale) {
    writeText(at(name), "leftover");
    fs::last_write_time(at(name), old_enough);
  }
  for (const auto& name : kept) {
    writeText(at(name), "keep");
    if (name.find("recent") == std::string::npos)
      fs::last_write_time(at(name), old_enough);
    else
      fs::last_write_time(at(name), fs::file_time_type::clock::now() + std::chrono::seconds(30));
  }
  writeFileAtomically(at("params.yaml"), "new\n");
  std::set<std::string> expected = kept;
  expected.insert("params.yaml");
  EXPECT_EQ(listing(), expected);
}

TEST_F(AtomicFileTest, ContentWrittenByNameThroughASuffixedTemporaryIsCommitted) {
  // Another program (a plotter choosing its format by the extension, rosbag) writes the temporary
  // by name; commit() gives it the mode and renames it, discard() removes it.
  writeText(at("plot.png"), "old");
  {
    AtomicOutputFile file(at("plot.png"), OutputFileOptions{false, ".png"});
    EXPECT_EQ(file.temporaryPath().substr(file.temporaryPath().size() - 4), ".png");
    EXPECT_EQ(file.temporaryPath().rfind(at("plot.png.tmp."), 0), 0u);
    writeText(file.temporaryPath(), "drawn");
    EXPECT_EQ(readText(at("plot.png")), "old");
    file.commit();
  }
  EXPECT_EQ(readText(at("plot.png")), "drawn");
  EXPECT_EQ(listing(), std::set<std::string>{"plot.png"});
  {
    AtomicOutputFile file(at("plot.png"), OutputFileOptions{false, ".png"});
    writeText(file.temporaryPath(), "half");
  }
  EXPECT_EQ(readText(at("plot.png")), "drawn");
  EXPECT_EQ(listing(), std::set<std::string>{"plot.png"});
  EXPECT_THROW(AtomicOutputFile(at("x"), OutputFileOptions{false, "/../y"}), std::invalid_argument);
  // A suffixed temporary of a killed writer is recognised as ours and removed at the next write.
  const pid_t gone = ::fork();
  ASSERT_GE(gone, 0);
  if (gone == 0) ::_exit(0);
  ASSERT_EQ(::waitpid(gone, nullptr, 0), gone);
  const std::string stale = "plot.png.tmp." + std::to_string(gone) + ".Ab12Cd.png";
  writeText(at(stale), "leftover");
  fs::last_write_time(at(stale), fs::file_time_type::clock::now() - std::chrono::hours(2));
  writeFileAtomically(at("plot.png"), "again");
  EXPECT_EQ(listing(), std::set<std::string>{"plot.png"});
}

// A failure at each step (a full disk, a failing sync, a refused verification, a failing backup or
// rename) leaves the old file exactly as it was, and no temporary behind.
TEST_F(AtomicFileTest, FailureAtAnyStepLeavesTheOldFileIntact) {
  const std::string path = at("params.yaml");
  writeText(path, "old content\n");
  writeText(path + ".bak", "older content\n");
  const ino_t inode = statOf(path).st_ino;
  std::vector<OutputFileFault> faults = faultsBeforeTheRename();
  faults.push_back({OutputFileStep::kRename, EXDEV, "cross-device"});
  for (const OutputFileFault& c : faults) {
    fault_injection::setOutputFileFault(
        [&](OutputFileStep step, const std::string&) { return step == c.step ? c.error : 0; });
    try {
      writeFileAtomically(path, std::string(200000, 'n'), kKeepBackup);
      ADD_FAILURE() << "no failure reported for step " << static_cast<int>(c.step);
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
    EXPECT_EQ(readText(path), "old content\n");
    EXPECT_EQ(statOf(path).st_ino, inode);
    EXPECT_EQ(readText(path + ".bak"), "older content\n");
    EXPECT_EQ(listing(), (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
  }
  fault_injection::setOutputFileFault({});
  EXPECT_THROW(writeFileAtomically(path, "refused", {}, [](const std::string&) { throw std::runtime_error("no"); }),
               std::runtime_error);
  EXPECT_EQ(readText(path), "old content\n");
  EXPECT_EQ(listing(), (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
  // Abandoned without commit (an exception in the caller): nothing changes either.
  {
    AtomicOutputFile abandoned(path);
    abandoned.write("half");
  }
  EXPECT_EQ(readText(path), "old content\n");
  EXPECT_EQ(listing(), (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
}

/// The open-file flags of the descriptor this process holds on `path` (from /proc), -1 if none.
long openFlagsOf(const std::string& path) {
  for (const auto& e : fs::directory_iterator("/proc/self/fd")) {
    std::error_code error;
    if (fs::read_symlink(e.path(), error).string() != path) continue;
    std::ifstream info("/proc/self/fdinfo/" + e.path().filename().string());
    std::string key;
    std::string value;
    while (info >> key >> value) {
      if (key == "flags:") return std::stol(value, nullptr, 8);
    }
  }
  return -1;
}

// Direct output (whole blocks around the page cache, the last partial block through it): every byte
// arrives, whatever the sizes of the file and of the pieces it is written in, flushes included.
TEST_F(AtomicFileTest, DirectOutputKeepsEveryByteWhateverTheSizes) {
  OutputFileOptions direct;
  direct.direct_io = true;
  const std::string path = at("session.csv");
  const std::size_t mib = std::size_t{1} << 20;
  const int probe = ::open(at("probe").c_str(), O_WRONLY | O_CREAT | O_DIRECT | O_CLOEXEC, 0600);
  const bool takesDirectIo = probe >= 0;
  if (probe >= 0) ::close(probe);
  ::unlink(at("probe").c_str());
  for (std::size_t size : {std::size_t{0}, std::size_t{1}, std::size_t{4095}, std::size_t{4096}, std::size_t{4097},
                           mib - 1, mib, mib + 4097, 3 * mib + 5}) {
    std::string content(size, ' ');
    for (std::size_t i = 0; i < size; ++i) content[i] = static_cast<char>('a' + (i * 131 + size) % 26);
    AtomicOutputFile file(path, direct);
    if (size == 0 && takesDirectIo) {
      // Where the file system takes O_DIRECT, the direct path is the one under test.
      EXPECT_NE(openFlagsOf(file.temporaryPath()) & O_DIRECT, 0);
    }
    std::size_t done = 0, piece = 0;
    const std::size_t pieces[] = {1, 7, 4096, 65537, 1000003};
    while (done < size) {
      const std::size_t n = std::min(pieces[piece++ % 5], size - done);
      file.stream().write(content.data() + done, static_cast<std::streamsize>(n));
      if (piece == 3) file.stream().flush();
      done += n;
    }
    file.commit();
    EXPECT_EQ(readText(path), content) << size;
    EXPECT_EQ(listing(), (std::set<std::string>{"session.csv"})) << size;
  }
}

// The last step, <file>.bak, fails after the rename: reported as such (BackupNotKept), the new file
// in place and the earlier backup kept.
TEST_F(AtomicFileTest, ABackupThatCannotBeKeptIsReportedAfterTheNewFileIsInPlace) {
  const std::string path = at("params.yaml");
  writeText(path, "old content\n");
  writeText(path + ".bak", "older content\n");
  fault_injection::setOutputFileFault(
      [](OutputFileStep step, const std::string&) { return step == OutputFileStep::kKeepBackup ? EIO : 0; });
  try {
    writeFileAtomically(path, "new content\n", kKeepBackup);
    ADD_FAILURE() << "the backup's failure was not reported";
  } catch (const BackupNotKept& e) {
    EXPECT_NE(std::string(e.what()).find("could not be kept as '" + path + ".bak'"), std::string::npos) << e.what();
  }
  EXPECT_EQ(readText(path), "new content\n");
  EXPECT_EQ(readText(path + ".bak"), "older content\n");
  EXPECT_EQ(listing(), (std::set<std::string>{"params.yaml", "params.yaml.bak"}));
}

// A set's members: never two on one file, nor one on another's backup (its rollback and its .bak
// would overwrite each other); refused when added, nothing created.
TEST_F(AtomicFileTest, ASetRefusesMembersThatAreOneFileOrAnothersBackup) {
  writeText(at("a.yaml"), "a\n");
  fs::create_symlink("a.yaml", at("link.yaml"));
  {
    AtomicOutputSet set;
    set.add(at("a.yaml"), kKeepBackup).write("new a\n");
    EXPECT_THROW(set.add(at("link.yaml"), kKeepBackup), std::runtime_error);
    EXPECT_THROW(set.add(at("a.yaml.bak"), {}), std::runtime_error);
    set.add(at("b.yaml"), {}).write("b\n");
    EXPECT_THROW(set.add(dir_ + "/./b.yaml", {}), std::runtime_error);
  }  // abandoned: nothing written
  EXPECT_EQ(readText(at("a.yaml")), "a\n");
  EXPECT_EQ(listing(), (std::set<std::string>{"a.yaml", "link.yaml"}));
  AtomicOutputSet set;
  set.add(at("a.yaml"), kKeepBackup).write("new a\n");
  set.add(at("b.yaml"), {}).write("b\n");
  set.commit();
  EXPECT_EQ(readText(at("a.yaml")), "new a\n");
  EXPECT_EQ(readText(at("a.yaml.bak")), "a\n");
  EXPECT_EQ(readText(at("b.yaml")), "b\n");
  EXPECT_EQ(listing(), (std::set<std::string>{"a.yaml", "a.yaml.bak", "b.yaml", "link.yaml"}));
}

TEST_F(AtomicFileTest, DirectOutputThatFailsLeavesTheOldFileIntact) {
  OutputFileOptions direct;
  direct.direct_io = true;
  const std::string path = at("session.csv");
  writeText(path, "old content\n");
  for (std::size_t size : {std::size_t{100}, std::size_t{3} << 20}) {  // failing at commit, and while writing
    fault_injection::setOutputFileFault(
        [](OutputFileStep step, const std::string&) { return step == OutputFileStep::kWrite ? ENOSPC : 0; });
    AtomicOutputFile file(path, direct);
    file.write(std::string(size, 'x'));
    try {
      file.commit();
      ADD_FAILURE() << "no failure reported for " << size << " bytes";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos) << e.what();
    }
    EXPECT_EQ(readText(path), "old content\n");
    EXPECT_EQ(listing(), (std::set<std::string>{"session.csv"}));
  }
}

TEST_F(AtomicFileTest, MissingDirectoryIsReported) {
  try {
    writeFileAtomically(at("no/such/dir/params.yaml"), "x");
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no/such/dir/params.yaml"), std::string::npos) << e.what();
  }
}

TEST_F(AtomicFileTest, CheckDistinctRefusesAnOutputThatIsAnInputOrAnotherOutput) {
  writeText(at("in.bag"), "data");
  fs::create_directories(at("sub"));
  ASSERT_EQ(::symlink(at("in.bag").c_str(), at("link.bag").c_str()), 0);
  ASSERT_EQ(::link(at("in.bag").c_str(), at("hard.bag").c_str()), 0);
  ASSERT_EQ(::symlink(at("sub").c_str(), at("sublink").c_str()), 0);
  auto refusal = [](const std::vector<std::string>& in, const std::vector<std::string>& out) -> std::string {
    try {
      checkDistinct(in, out);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NO_THROW(checkDistinct({at("in.bag")}, {at("out.yaml"), at("out.csv")}));
  const std::string same = refusal({at("in.bag")}, {at("out.yaml"), at("in.bag")});
  EXPECT_NE(same.find("'" + at("in.bag") + "'"), std::string::npos) << same;
  EXPECT_NE(same.find("same file as input"), std::string::npos) << same;
  EXPECT_NE(refusal({at("in.bag")}, {at("link.bag")}), "") << "a link to the input";
  EXPECT_NE(refusal({at("in.bag")}, {at("hard.bag")}), "") << "a hard link to the input";
  EXPECT_NE(refusal({at("in.bag")}, {dir_ + "/./sub/../in.bag"}), "") << "another spelling of the input";
  // Two outputs that do not exist yet, spelled differently (one through a linked directory).
  const std::string twice = refusal({at("in.bag")}, {at("sub/out.yaml"), at("sublink/out.yaml")});
  EXPECT_NE(twice.find("are the same file"), std::string::npos) << twice;
  EXPECT_NE(twice.find(at("sub/out.yaml")), std::string::npos) << twice;
  EXPECT_NE(twice.find(at("sublink/out.yaml")), std::string::npos) << twice;
}

/// Runs `body` in a child process and reports how it ended within `limit`; a child still running
/// then is killed (so that a read that would hang fails the test instead of hanging it).
std::string runWithin(std::chrono::milliseconds limit, const std::function<std::string()>& body) {
  int fds[2];
  if (::pipe(fds) != 0) return "pipe failed";
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(fds[0]);
    const std::string outcome = body();
    if (::write(fds[1], outcome.data(), outcome.size()) < 0) ::_exit(2);
    ::_exit(0);
  }
  ::close(fds[1]);
  const auto deadline = std::chrono::steady_clock::now() + limit;
  int status = 0;
  while (::waitpid(child, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(child, SIGKILL);
      ::waitpid(child, &status, 0);
      ::close(fds[0]);
      return "still running after the time limit";
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::string outcome;
  char buffer[512];
  ssize_t n;
  while ((n = ::read(fds[0], buffer, sizeof buffer)) > 0) outcome.append(buffer, static_cast<std::size_t>(n));
  ::close(fds[0]);
  return outcome;
}

std::string readOutcome(const std::string& path, std::size_t limit) {
  try {
    return "read " + std::to_string(readBoundedRegularFile(path, limit, "parameter file").size()) + " bytes";
  } catch (const std::runtime_error& e) {
    return e.what();
  }
}

TEST_F(AtomicFileTest, BoundedReaderRefusesFifosDevicesAndDirectoriesAtOnce) {
  ASSERT_EQ(::mkfifo(at("fifo").c_str(), 0644), 0);  // no writer: an ordinary open would wait forever
  fs::create_directories(at("dir"));
  const std::chrono::seconds limit(5);
  const std::string fifo = runWithin(limit, [&] { return readOutcome(at("fifo"), 1 << 20); });
  EXPECT_NE(fifo.find("is a FIFO"), std::string::npos) << fifo;
  const std::string zero = runWithin(limit, [&] { return readOutcome("/dev/zero", 1 << 20); });
  EXPECT_NE(zero.find("is a character device"), std::string::npos) << zero;
  const std::string dir = readOutcome(at("dir"), 1 << 20);
  EXPECT_NE(dir.find("is a directory, not a parameter file"), std::string::npos) << dir;
  const std::string missing = readOutcome(at("missing"), 1 << 20);
  EXPECT_NE(missing.find("No such file"), std::string::npos) << missing;
}

TEST_F(AtomicFileTest, OpeningForReadingRefusesWhatIsNotARegularFileWithoutBlocking) {
  ASSERT_EQ(::mkfifo(at("fifo").c_str(), 0644), 0);
  fs::create_directories(at("dir"));
  auto outcome = [](const std::string& path) -> std::string {
    try {
      std::uint64_t size = 0;
      const int fd = openRegularFileForReading(path, "bag", &size);
      char first = 0;
      const bool read_one = ::read(fd, &first, 1) == 1;
      const int flags = ::fcntl(fd, F_GETFL);
      ::close(fd);
      return "opened " + std::to_string(size) + " bytes" + (read_one ? ", first '" + std::string(1, first) + "'" : "") +
             ((flags & O_NONBLOCK) != 0 ? ", non-blocking" : "");
    } catch (const std::runtime_error& e) {
      return e.what();
    }
  };
  const std::chrono::seconds limit(5);
  const std::string fifo = runWithin(limit, [&] { return outcome(at("fifo")); });
  EXPECT_NE(fifo.find("is a FIFO (named pipe), not a regular file: refusing to read it as a bag"), std::string::npos)
      << fifo;
  const std::string null = runWithin(limit, [&] { return outcome("/dev/null"); });
  EXPECT_NE(null.find("is a character device"), std::string::npos) << null;
  EXPECT_NE(outcome(at("dir")).find("is a directory, not a bag"), std::string::npos);
  EXPECT_NE(outcome(at("missing")).find("cannot read bag '" + at("missing") + "': No such file"), std::string::npos);
  // A regular file: its size, and a descriptor that reads (and blocks) as an ordinary one.
  writeText(at("regular"), "xyz");
  EXPECT_EQ(outcome(at("regular")), "opened 3 bytes, first 'x'");
}

TEST_F(AtomicFileTest, BoundedReaderEnforcesItsLimit) {
  writeText(at("exact"), std::string(1000, 'x'));
  writeText(at("over"), std::string(1001, 'x'));
  writeText(at("empty"), "");
  EXPECT_EQ(readBoundedRegularFile(at("exact"), 1000, "file"), std::string(1000, 'x'));
  EXPECT_EQ(readBoundedRegularFile(at("empty"), 1000, "file"), "");
  const std::string over = readOutcome(at("over"), 1000);
  EXPECT_NE(over.find("1001 bytes, above the limit of 1000 bytes"), std::string::npos) << over;
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
