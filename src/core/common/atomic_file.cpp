#include "hrg_gyro/core/common/atomic_file.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "hrg_gyro/core/common/direct_file_buffer.h"
#include "hrg_gyro/core/common/output_directory.h"

namespace hrg_gyro {
namespace core {
namespace fault_injection {
namespace {
OutputFileFault& currentFault() {
  static OutputFileFault fault;
  return fault;
}
}  // namespace
void setOutputFileFault(OutputFileFault fault) { currentFault() = std::move(fault); }
}  // namespace fault_injection

namespace {

using fault_injection::OutputFileStep;

/// errno injected for `step`, 0 when the step should proceed normally.
int injectedFault(OutputFileStep step, const std::string& target) {
  const auto& fault = fault_injection::currentFault();
  return fault ? fault(step, target) : 0;
}

std::string errnoText(int error) { return std::strerror(error); }

[[noreturn]] void fail(const std::string& what, int error) { throw std::runtime_error(what + ": " + errnoText(error)); }

constexpr int kMaxLinkHops = 40;
/// A temporary whose writer is gone is removed once it is older than the current write. One whose
/// writer's process id is still in use (possibly reused by another process) only after this long.
constexpr time_t kStaleAfterSeconds = 24 * 3600;
/// Names written by the earlier version of the writer (<file>.tmp.XXXXXX and <file>.bak.tmp) carry
/// no process id; its writes took milliseconds, so an hour-old one is certainly abandoned.
constexpr time_t kLegacyStaleAfterSeconds = 3600;

std::string baseNameOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

bool allDigits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}
/// An OutputFileOptions::temporary_suffix: empty, or a dot followed by letters, digits and dots.
bool isTemporarySuffix(const std::string& s) {
  return s.empty() || (s.size() <= 16 && s[0] == '.' && std::all_of(s.begin(), s.end(), [](unsigned char c) {
                         return std::isalnum(c) != 0 || c == '.';
                       }));
}
bool isMkstempSuffix(const std::string& s) {
  return s.size() == 6 && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isalnum(c) != 0; });
}

/// The process id in a temporary's name written by this facility: <base>.tmp.<pid>.XXXXXX or
/// <base>.bak.tmp.<pid>.XXXXXX. 0 for a legacy name (<base>.tmp.XXXXXX, <base>.bak.tmp), -1 for a
/// name that is not one of ours (never touched).
long temporaryOwner(const std::string& name, const std::string& base) {
  if (name == base + ".bak.tmp") return 0;
  for (const std::string& prefix : {base + ".tmp.", base + ".bak.tmp."}) {
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    const std::size_t dot = rest.find('.');
    if (dot == std::string::npos) return isMkstempSuffix(rest) && prefix == base + ".tmp." ? 0 : -1;
    const std::string pid = rest.substr(0, dot), suffix = rest.substr(dot + 1);
    // The six random characters, then possibly the writer's temporary_suffix (".png").
    const std::string random = suffix.substr(0, 6), extension = suffix.size() > 6 ? suffix.substr(6) : "";
    if (pid.size() > 9 || !allDigits(pid) || !isMkstempSuffix(random) || !isTemporarySuffix(extension)) return -1;
    const long owner = std::strtol(pid.c_str(), nullptr, 10);
    return owner > 0 ? owner : -1;
  }
  return -1;
}

bool processIsGone(long pid) { return ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH; }

/// Removes temporaries of `target` left by killed writes: ours by name only, regular files only,
/// older than the current write, and whose writer process is gone (or very old).
void removeStaleTemporaries(const std::string& target, const timespec& write_start) {
  const std::string dir = directoryOf(target), base = baseNameOf(target);
  DIR* listing = ::opendir(dir.c_str());
  if (listing == nullptr) return;  // creating the temporary will report the problem
  const long self = static_cast<long>(::getpid());
  while (const dirent* entry = ::readdir(listing)) {
    const std::string name = entry->d_name;
    const long owner = temporaryOwner(name, base);
    if (owner < 0 || owner == self) continue;  // not ours, or a concurrent write of this process
    const std::string path = dir + "/" + name;
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
    const bool older = st.st_mtim.tv_sec < write_start.tv_sec ||
                       (st.st_mtim.tv_sec == write_start.tv_sec && st.st_mtim.tv_nsec < write_start.tv_nsec);
    if (!older) continue;  // written since this write began
    const time_t age = write_start.tv_sec - st.st_mtim.tv_sec;
    const bool stale = owner == 0 ? age > kLegacyStaleAfterSeconds : (processIsGone(owner) || age > kStaleAfterSeconds);
    if (stale) ::unlink(path.c_str());
  }
  ::closedir(listing);
}

/// The process umask, read without changing it (changing it would race with other threads that
/// create files). Linux reports it in /proc/self/status; without /proc the common 022 is assumed.
mode_t processUmask() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.compare(0, 6, "Umask:") == 0) return static_cast<mode_t>(std::strtol(line.c_str() + 6, nullptr, 8)) & 0777;
  }
  return 022;
}

int writeAll(int fd, const char* data, std::size_t size) {
  std::size_t done = 0;
  while (done < size) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    done += static_cast<std::size_t>(n);
  }
  return 0;
}

void syncDirectory(const std::string& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;  // best effort: the rename itself has already happened
  ::fsync(fd);
  ::close(fd);
}

/// A unique temporary beside `target`: <target><infix>.<pid>.XXXXXX<suffix>, created 0600 by
/// mkstemp so that nobody else can read it while it is written.
int createTemporary(const std::string& target, const std::string& infix, std::string* name,
                    const std::string& suffix = "") {
  std::string pattern = target + infix + "." + std::to_string(::getpid()) + ".XXXXXX" + suffix;
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  const int fd = ::mkostemps(buffer.data(), static_cast<int>(suffix.size()), O_CLOEXEC);
  if (fd < 0) fail("cannot create a temporary file beside '" + target + "'", errno);
  name->assign(buffer.data());
  return fd;
}

/// Copies the old file's owner, group and mode onto `fd`. Owner and group need privileges the
/// writer may not have (EPERM): then the group alone is tried, then nothing.
int copyMetadata(int fd, uid_t uid, gid_t gid, mode_t mode) {
  if (::fchown(fd, uid, gid) != 0 && errno == EPERM) ::fchown(fd, static_cast<uid_t>(-1), gid);
  // After fchown: changing the owner clears set-user-id bits, which the mode then restores.
  return ::fchmod(fd, mode & 07777) == 0 ? 0 : errno;
}

/// First half of keeping <target>.bak: the current target under a unique temporary name, as a hard
/// link (a copy with the same mode and owner where links are impossible). Returns that name, or ""
/// when there is no target yet. The target itself is not touched.
std::string prepareBackup(const std::string& target) {
  struct stat st {};
  if (::lstat(target.c_str(), &st) != 0) return "";  // nothing to back up yet
  const std::string backup = target + ".bak";
  if (const int injected = injectedFault(OutputFileStep::kBackup, target))
    fail("cannot keep backup '" + backup + "'", injected);
  std::string temporary;
  // mkstemp reserves a unique name; the hard link then takes its place (link never overwrites).
  ::close(createTemporary(target, ".bak.tmp", &temporary));
  try {
    ::unlink(temporary.c_str());
    if (::link(target.c_str(), temporary.c_str()) != 0) {
      const int link_error = errno;
      if (link_error == EEXIST) fail("cannot create backup '" + temporary + "'", link_error);
      const int copy = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
      if (copy < 0) fail("cannot create backup '" + temporary + "'", errno);
      std::ifstream in(target, std::ios::binary);
      std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      int error = in.bad() ? EIO : writeAll(copy, content.data(), content.size());
      if (error == 0) error = copyMetadata(copy, st.st_uid, st.st_gid, st.st_mode);
      if (error == 0 && ::fsync(copy) != 0) error = errno;
      ::close(copy);
      if (error != 0) fail("cannot write backup '" + temporary + "'", error);
    }
  } catch (...) {
    ::unlink(temporary.c_str());
    throw;
  }
  return temporary;
}

/// Second half, after the new file is in place: the prepared backup becomes <target>.bak. Done
/// after the target's rename so that a failed write never changes <target>.bak either.
void finishBackup(const std::string& target, const std::string& temporary) {
  const std::string backup = target + ".bak";
  int error = injectedFault(OutputFileStep::kKeepBackup, target);
  if (error == 0 && ::rename(temporary.c_str(), backup.c_str()) != 0) error = errno;
  // rename() between two links of one file succeeds without removing the source: remove it here.
  ::unlink(temporary.c_str());
  if (error != 0) {
    throw BackupNotKept("'" + target + "' was written, but its previous version could not be kept as '" + backup +
                        "': " + errnoText(error));
  }
}

timespec now() {
  timespec t{};
  ::clock_gettime(CLOCK_REALTIME, &t);
  return t;
}

const char* kindOf(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "not a regular file";
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The stream buffer: its put area is a DirectFileBuffer's memory, written to the temporary's
// descriptor (with direct_io, whole blocks around the page cache until finish()); it remembers the
// first error.
class AtomicOutputFile::Buffer : public std::streambuf {
 public:
  Buffer(int fd, std::string target, bool direct)
      : target_(std::move(target)), file_(fd, direct ? std::size_t{1} << 20 : std::size_t{1} << 16, direct) {
    resetPut();
  }
  int error() const { return error_; }
  /// Writes what is buffered (with direct I/O, the whole blocks only; the rest stays buffered).
  bool flushAll() { return flush(false); }
  /// Writes everything, the last partial block included.
  bool finish() { return flush(true); }

 protected:
  int_type overflow(int_type ch) override {
    if (!flushAll()) return traits_type::eof();
    if (!traits_type::eq_int_type(ch, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(ch);
      pbump(1);
    }
    return traits_type::not_eof(ch);
  }
  int sync() override { return flushAll() ? 0 : -1; }

 private:
  bool flush(bool all) {
    if (error_ != 0) return false;
    file_.setSize(static_cast<std::size_t>(pptr() - pbase()));
    if (file_.size() == 0) return true;
    error_ = injectedFault(OutputFileStep::kWrite, target_);
    if (error_ == 0) error_ = file_.write(all);
    resetPut();
    return error_ == 0;
  }
  /// The put area over the buffer's memory, after what it still holds.
  void resetPut() {
    setp(file_.data(), file_.data() + file_.capacity());
    pbump(static_cast<int>(file_.size()));
  }

  std::string target_;
  DirectFileBuffer file_;
  int error_ = 0;
};

AtomicOutputFile::AtomicOutputFile(const std::string& path, const OutputFileOptions& options)
    : requested_path_(path), options_(options) {
  if (path.empty()) throw std::runtime_error("empty output file name");
  if (!isTemporarySuffix(options.temporary_suffix)) {
    throw std::invalid_argument("temporary suffix '" + options.temporary_suffix +
                                "' is not a dot and letters or digits");
  }
  target_path_ = resolveOutputTarget(path);
  struct stat st {};
  if (::stat(target_path_.c_str(), &st) == 0) {
    if (!S_ISREG(st.st_mode)) {
      throw std::runtime_error("refusing to replace '" + target_path_ + "': it is " + kindOf(st.st_mode) +
                               ", not a regular file");
    }
    target_existed_ = true;
    target_mode_ = st.st_mode;
    target_uid_ = st.st_uid;
    target_gid_ = st.st_gid;
  } else if (errno != ENOENT) {
    fail("cannot inspect '" + target_path_ + "'", errno);
  }
  removeStaleTemporaries(target_path_, now());
  fd_ = createTemporary(target_path_, ".tmp", &temporary_path_, options.temporary_suffix);
  buffer_ = std::make_unique<Buffer>(fd_, target_path_, options.direct_io);
  stream_ = std::make_unique<std::ostream>(buffer_.get());
}

AtomicOutputFile::~AtomicOutputFile() { discard(); }

std::ostream& AtomicOutputFile::stream() {
  if (finished_)
    throw std::logic_error("AtomicOutputFile for '" + target_path_ + "' is already committed or discarded");
  return *stream_;
}

void AtomicOutputFile::write(const std::string& text) {
  stream().write(text.data(), static_cast<std::streamsize>(text.size()));
}

void AtomicOutputFile::discard() noexcept {
  if (finished_) return;
  finished_ = true;
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (!published_ && !temporary_path_.empty()) ::unlink(temporary_path_.c_str());
  if (!previous_.empty()) ::unlink(previous_.c_str());
  previous_.clear();
}

std::string AtomicOutputFile::unchanged() const { return target_existed_ ? " (the existing file is unchanged)" : ""; }

void AtomicOutputFile::commit(const Verifier& verify) {
  prepare(verify, options_.keep_backup);
  publish();
  complete();
}

void AtomicOutputFile::prepare(const Verifier& verify, bool keep_previous) {
  if (finished_ || published_)
    throw std::logic_error("AtomicOutputFile for '" + target_path_ + "' is already committed or discarded");
  try {
    if (!buffer_->finish() || !*stream_) {
      fail("cannot write '" + target_path_ + "'" + unchanged(), buffer_->error() != 0 ? buffer_->error() : EIO);
    }
    const int metadata_error = target_existed_ ? copyMetadata(fd_, target_uid_, target_gid_, target_mode_)
                                               : (::fchmod(fd_, kNewOutputFileMode & ~processUmask()) == 0 ? 0 : errno);
    if (metadata_error != 0) fail("cannot set the mode of '" + temporary_path_ + "'" + unchanged(), metadata_error);
    int sync_error = injectedFault(OutputFileStep::kSync, target_path_);
    if (sync_error == 0 && ::fsync(fd_) != 0) sync_error = errno;
    if (sync_error != 0) fail("cannot sync '" + temporary_path_ + "'" + unchanged(), sync_error);
    if (verify) verify(temporary_path_);
    if (keep_previous) previous_ = prepareBackup(target_path_);
  } catch (...) {
    discard();
    throw;
  }
}

void AtomicOutputFile::publish() {
  int rename_error = injectedFault(OutputFileStep::kRename, target_path_);
  if (rename_error == 0 && ::rename(temporary_path_.c_str(), target_path_.c_str()) != 0) rename_error = errno;
  if (rename_error != 0) {
    discard();
    fail("cannot rename '" + temporary_path_ + "' over '" + target_path_ + "'" + unchanged(), rename_error);
  }
  published_ = true;
  ::close(fd_);
  fd_ = -1;
}

void AtomicOutputFile::restore() {
  finished_ = true;
  const std::string previous = previous_;
  previous_.clear();
  int error = injectedFault(OutputFileStep::kRestore, target_path_);
  if (previous.empty()) {  // there was no file: the new one goes
    if (error == 0 && ::unlink(target_path_.c_str()) != 0 && errno != ENOENT) error = errno;
    if (error != 0) fail("could not remove the new '" + target_path_ + "' (there was none before)", error);
  } else {
    if (error == 0 && ::rename(previous.c_str(), target_path_.c_str()) != 0) error = errno;
    if (error != 0) {
      fail("could not put back the previous '" + target_path_ + "' (it holds the new version; the previous one is '" +
               previous + "')",
           error);
    }
  }
  syncDirectory(directoryOf(target_path_));
}

void AtomicOutputFile::complete() {
  finished_ = true;
  const std::string previous = previous_;
  previous_.clear();
  try {
    if (!previous.empty() && options_.keep_backup) finishBackup(target_path_, previous);
    if (!previous.empty() && !options_.keep_backup) ::unlink(previous.c_str());
  } catch (...) {
    syncDirectory(directoryOf(target_path_));
    throw;
  }
  syncDirectory(directoryOf(target_path_));
}

// ---------------------------------------------------------------------------------------------

AtomicOutputFile& AtomicOutputSet::add(const std::string& path, const OutputFileOptions& options,
                                       AtomicOutputFile::Verifier verify) {
  if (committed_) throw std::logic_error("AtomicOutputSet: '" + path + "' added after the commit");
  for (const Member& m : members_) {
    const std::string& other = m.file->requestedPath();
    if (sameFile(path, other)) {
      throw std::runtime_error("outputs '" + other + "' and '" + path + "' are the same file");
    }
    if (options.keep_backup && sameFile(backupPathOf(path), other)) {
      throw std::runtime_error("output '" + path + "' keeps its previous version as '" + backupPathOf(path) +
                               "', the same file as output '" + other + "'");
    }
    if (m.file->options_.keep_backup && sameFile(backupPathOf(other), path)) {
      throw std::runtime_error("output '" + other + "' keeps its previous version as '" + backupPathOf(other) +
                               "', the same file as output '" + path + "'");
    }
  }
  members_.push_back({std::make_unique<AtomicOutputFile>(path, options), std::move(verify)});
  return *members_.back().file;
}

std::string AtomicOutputSet::names() const {
  std::string list;
  for (const Member& m : members_) list += (list.empty() ? "" : ", ") + m.file->requestedPath();
  return list;
}

void AtomicOutputSet::commit() {
  if (committed_) throw std::logic_error("AtomicOutputSet committed twice");
  committed_ = true;
  const std::size_t n = members_.size();
  // 1. Every member complete, synced, verified and its current version linked aside.
  for (std::size_t k = 0; k < n; ++k) {
    try {
      members_[k].file->prepare(members_[k].verify, true);
    } catch (const std::exception& e) {
      for (Member& m : members_) m.file->discard();
      throw std::runtime_error(std::string(e.what()) + "; nothing of the set was replaced (" + names() + ")");
    }
  }
  // 2. The renames; a failed one puts back those already renamed, the last first.
  for (std::size_t k = 0; k < n; ++k) {
    try {
      members_[k].file->publish();
    } catch (const std::exception& e) {
      std::string restored, not_restored;
      for (std::size_t j = k; j-- > 0;) {
        try {
          members_[j].file->restore();
          restored += (restored.empty() ? "" : ", ") + members_[j].file->requestedPath();
        } catch (const std::exception& r) {
          not_restored += std::string("; ") + r.what();
        }
      }
      for (std::size_t j = k; j < n; ++j) members_[j].file->discard();
      std::string outcome;
      if (not_restored.empty()) {
        outcome = restored.empty() ? "; nothing of the set was replaced (" + names() + ")"
                                   : "; the files already replaced were put back (" + restored +
                                         "): the set is as it was (" + names() + ")";
      } else {
        outcome = "; the set is mixed" + not_restored + (restored.empty() ? "" : "; put back: " + restored);
      }
      throw std::runtime_error(std::string(e.what()) + outcome);
    }
  }
  // 3. The backups; the new set is in place whatever happens here.
  std::string not_kept;
  for (Member& m : members_) {
    try {
      m.file->complete();
    } catch (const std::exception& e) {
      not_kept += std::string(not_kept.empty() ? "" : "; ") + e.what();
    }
  }
  if (!not_kept.empty()) throw BackupNotKept("the set was written (" + names() + "), but " + not_kept);
}

void writeFileAtomically(const std::string& path, const std::string& contents, const OutputFileOptions& options,
                         const AtomicOutputFile::Verifier& verify) {
  AtomicOutputFile file(path, options);
  file.write(contents);
  file.commit(verify);
}

std::string resolveOutputTarget(const std::string& path) {
  std::string current = path;
  for (int hops = 0;; ++hops) {
    struct stat st {};
    if (::lstat(current.c_str(), &st) != 0) {
      if (errno == ENOENT) return current;  // a new file (its directory is checked on creation)
      fail("cannot inspect '" + current + "'", errno);
    }
    if (!S_ISLNK(st.st_mode)) return current;
    if (hops == kMaxLinkHops) throw std::runtime_error("too many levels of symbolic links from '" + path + "'");
    std::vector<char> buffer(PATH_MAX + 1);
    const ssize_t n = ::readlink(current.c_str(), buffer.data(), buffer.size() - 1);
    if (n < 0) fail("cannot read symbolic link '" + current + "'", errno);
    const std::string link(buffer.data(), static_cast<std::size_t>(n));
    current = link.front() == '/' ? link : directoryOf(current) + "/" + link;
  }
}

namespace {

/// What "the same file" means for checkDistinct.
struct FileIdentity {
  bool exists = false;
  dev_t device = 0;
  ino_t inode = 0;
  std::string resolved;  // for a file that does not exist yet

  bool sameAs(const FileIdentity& other) const {
    if (exists != other.exists) return false;
    return exists ? device == other.device && inode == other.inode : resolved == other.resolved;
  }
};

FileIdentity identify(const std::string& path) {
  FileIdentity id;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    id.exists = true;
    id.device = st.st_dev;
    id.inode = st.st_ino;
    return id;
  }
  const std::string target = resolveOutputTarget(path);
  const std::string dir = directoryOf(target);
  char* real = ::realpath(dir.c_str(), nullptr);
  id.resolved = (real != nullptr ? std::string(real) : dir) + "/" + baseNameOf(target);
  std::free(real);
  return id;
}

}  // namespace

std::string backupPathOf(const std::string& path) { return resolveOutputTarget(path) + ".bak"; }

bool sameFile(const std::string& a, const std::string& b) { return identify(a).sameAs(identify(b)); }

void checkDistinct(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs) {
  std::vector<FileIdentity> input_ids, output_ids;
  for (const auto& p : inputs) input_ids.push_back(identify(p));
  for (const auto& p : outputs) output_ids.push_back(identify(p));
  for (std::size_t o = 0; o < outputs.size(); ++o) {
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      if (output_ids[o].sameAs(input_ids[i])) {
        throw std::runtime_error("output '" + outputs[o] + "' is the same file as input '" + inputs[i] +
                                 "': writing it would destroy what is being read");
      }
    }
    for (std::size_t other = 0; other < o; ++other) {
      if (output_ids[o].sameAs(output_ids[other])) {
        throw std::runtime_error("outputs '" + outputs[other] + "' and '" + outputs[o] + "' are the same file");
      }
    }
  }
}

int openRegularFileForReading(const std::string& path, const std::string& what, std::uint64_t* size) {
  auto refuseKind = [&](mode_t mode) {
    if (S_ISDIR(mode)) throw std::runtime_error("'" + path + "' is a directory, not a " + what);
    if (!S_ISREG(mode))
      throw std::runtime_error("'" + path + "' is " + kindOf(mode) + ", not a regular file: refusing to read it as a " +
                               what);
  };
  // stat before open: opening a FIFO blocks until a writer comes, opening some devices has effects.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) fail("cannot read " + what + " '" + path + "'", errno);
  refuseKind(st.st_mode);
  // O_NONBLOCK: should the path have been swapped for a FIFO since the stat, open must not hang.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
  if (fd < 0) fail("cannot read " + what + " '" + path + "'", errno);
  try {
    if (::fstat(fd, &st) != 0) fail("cannot read " + what + " '" + path + "'", errno);
    refuseKind(st.st_mode);
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags < 0 || ::fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) != 0) {
      fail("cannot read " + what + " '" + path + "'", errno);
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  if (size != nullptr) *size = static_cast<std::uint64_t>(st.st_size);
  return fd;
}

std::string readBoundedRegularFile(const std::string& path, std::size_t max_bytes, const std::string& what) {
  auto refuseSize = [&](const std::string& size) {
    throw std::runtime_error("'" + path + "' is " + size + ", above the limit of " + std::to_string(max_bytes) +
                             " bytes for a " + what);
  };
  std::uint64_t file_size = 0;
  const int fd = openRegularFileForReading(path, what, &file_size);
  std::string content;
  try {
    if (file_size > max_bytes) refuseSize(std::to_string(file_size) + " bytes");
    // Sized by the stat, grown (never past one byte more than allowed) should the file have grown.
    content.resize(static_cast<std::size_t>(std::min<std::uint64_t>(max_bytes, file_size)) + 1);
    std::size_t done = 0;
    while (true) {
      if (done == content.size()) {
        if (done > max_bytes) break;
        content.resize(std::min(max_bytes + 1, 2 * content.size()));
      }
      const ssize_t n = ::read(fd, &content[done], content.size() - done);
      if (n < 0) {
        if (errno == EINTR) continue;
        fail("error while reading " + what + " '" + path + "'", errno);
      }
      if (n == 0) break;
      done += static_cast<std::size_t>(n);
    }
    if (done > max_bytes) refuseSize("more than " + std::to_string(max_bytes) + " bytes (it grew while being read)");
    content.resize(done);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return content;
}

}  // namespace core
}  // namespace hrg_gyro
