// Files written whole or not at all, and files read with a bound.
//
// AtomicOutputFile is the one way the core (and the tools) replace a file: the new content goes to
// a uniquely named temporary beside the target, is flushed to disk and only then renamed over the
// target. A reader therefore finds the complete old file or the complete new one; a failure at any
// step (disk full, verification refused, a kill) leaves an existing file untouched. A target that is
// a symbolic link is followed: the file the link points to is replaced and the link stays a link.
// The replaced file keeps its mode (and, where the writer may set them, its owner and group).
// Temporaries that a killed writer left behind are removed by the next write of the same file.
// AtomicOutputSet replaces several files as one set: every file complete, synced and verified, and
// every current version linked aside, before the first rename; a rename that fails puts back those
// already renamed.
//
// readBoundedRegularFile is the matching reader for configuration: regular files only (no FIFO,
// device or directory), never more than a stated number of bytes. openRegularFileForReading is its
// first half, for inputs read as a stream (logs, bags): a regular file, opened without blocking.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace core {

/// Mode given to a file that did not exist before, narrowed by the process umask like any newly
/// created file (umask 022: 0644, umask 027: 0640, umask 077: 0600). A replaced file keeps its own.
constexpr mode_t kNewOutputFileMode = 0644;

struct OutputFileOptions {
  /// Keep the replaced file as <target>.bak, beside the (link-resolved) target.
  bool keep_backup = false;
  /// Appended to the temporary's name (".png"): for content written by another program that
  /// chooses its format by the name's extension. Letters, digits and dots only.
  std::string temporary_suffix;
  /// For large outputs written through stream(): whole blocks go to the device around the page
  /// cache (O_DIRECT, where the file system has it). commit() syncs the file anyway, so the cache
  /// would only hold a second copy; filling it costs system time, and the sync then waits for all of
  /// it at once.
  bool direct_io = false;
};

class AtomicOutputSet;

/// Thrown when every file was replaced but a previous version could not be kept as <file>.bak (the
/// last step of a commit): the new content is in place.
struct BackupNotKept : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class AtomicOutputFile {
 public:
  /// Called with the temporary's path after it is complete and synced, before it replaces the
  /// target; throwing aborts the write (the target stays as it was).
  using Verifier = std::function<void(const std::string& temporary_path)>;

  /// Resolves `path`, refuses a target that exists and is not a regular file, removes stale
  /// temporaries of earlier killed writes and creates the temporary. Throws std::runtime_error.
  explicit AtomicOutputFile(const std::string& path, const OutputFileOptions& options = {});
  /// Not committed: the temporary is removed and the target left as it was.
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  /// Where the content goes. Write errors are reported by commit(), naming the target. Content may
  /// instead be written to temporaryPath() by name (a rosbag::Bag, a plotting program), as long as
  /// the file is truncated and rewritten in place, not replaced; commit() then syncs and renames it.
  std::ostream& stream();
  void write(const std::string& text);

  /// Flushes the temporary, gives it the old file's mode (owner and group where allowed), syncs
  /// it, runs `verify`, links the old file under a backup temporary if asked, renames the
  /// temporary over the target, then the backup temporary to <target>.bak, and syncs the
  /// directory. Throws std::runtime_error on any failure, after removing the temporaries; up to
  /// the target's rename the target and its backup are untouched. A failure of the last step
  /// (<target>.bak) is a BackupNotKept: the target is then already replaced.
  void commit(const Verifier& verify = {});
  /// Drops the temporary; the target is untouched. Safe to call more than once.
  void discard() noexcept;

  const std::string& requestedPath() const { return requested_path_; }
  /// The file that commit() replaces: requestedPath() with symbolic links followed.
  const std::string& targetPath() const { return target_path_; }
  const std::string& temporaryPath() const { return temporary_path_; }

 private:
  friend class AtomicOutputSet;
  class Buffer;

  // commit()'s steps, which AtomicOutputSet runs file by file across the set.
  /// Every step before the rename: flush, mode, sync, `verify`, and with `keep_previous` the current
  /// target linked under the backup's temporary name. On failure the temporaries are removed.
  void prepare(const Verifier& verify, bool keep_previous);
  /// The temporary renamed over the target. On failure the temporaries are removed.
  void publish();
  /// After publish(): the previous version renamed back over the target (or the new file removed
  /// where there was none). On failure the previous version stays under its temporary name, which
  /// the message gives.
  void restore();
  /// After publish(): the previous version becomes <target>.bak (keep_backup) or is dropped, and the
  /// directory is synced. Throws BackupNotKept.
  void complete();
  /// " (the existing file is unchanged)" when there was one.
  std::string unchanged() const;

  std::string requested_path_, target_path_, temporary_path_;
  std::string previous_;  // the current target's link (or copy) under the backup's temporary name
  OutputFileOptions options_;
  bool target_existed_ = false;
  mode_t target_mode_ = 0;
  uid_t target_uid_ = 0;
  gid_t target_gid_ = 0;
  int fd_ = -1;
  bool published_ = false;  // renamed over the target
  bool finished_ = false;   // committed, restored or discarded
  std::unique_ptr<Buffer> buffer_;
  std::unique_ptr<std::ostream> stream_;
};

/// Several files replaced as one set (a calibration's parameter files and the file that ties them
/// together). Each member is written through its AtomicOutputFile; commit() then
///   1. prepares every member: flushed, synced, verified (read back by its verifier), and its current
///      file hard-linked aside under the backup's temporary name (also without keep_backup);
///   2. renames each member over its target, in the order added;
///   3. moves each kept version to <target>.bak (keep_backup) or drops it, and syncs the directories.
/// A failure in step 1 (a full disk, a failed sync, a refused read-back, a failed backup link)
/// changes nothing: every target and every .bak as it was, no temporary left. A rename that fails in
/// step 2 puts back the members already renamed, each from its linked-aside version (a member that
/// did not exist is removed): again every target and .bak as it was. Should putting one back fail
/// too, the message names it and where its previous version was left. A failure in step 3 leaves
/// the whole new set in place and throws BackupNotKept naming the backups not kept. What no process
/// can guarantee: a kill or a power cut between the first and the last rename (microseconds) leaves
/// some members new and others old, each file whole.
class AtomicOutputSet {
 public:
  AtomicOutputSet() = default;
  /// Not committed: every temporary removed, every target as it was.
  ~AtomicOutputSet() = default;
  AtomicOutputSet(const AtomicOutputSet&) = delete;
  AtomicOutputSet& operator=(const AtomicOutputSet&) = delete;

  /// Adds a member and returns its file, to be filled through stream() or write() (not committed on
  /// its own). `verify` checks its complete temporary (see AtomicOutputFile::Verifier). Refuses
  /// (std::runtime_error) a member that is the same file as another (checkDistinct's rule), or whose
  /// backup would be another member. Throws as AtomicOutputFile's constructor does.
  AtomicOutputFile& add(const std::string& path, const OutputFileOptions& options = {},
                        AtomicOutputFile::Verifier verify = {});
  /// Steps 1 to 3 above. Throws std::runtime_error (BackupNotKept after step 2), naming the files.
  void commit();

 private:
  struct Member {
    std::unique_ptr<AtomicOutputFile> file;
    AtomicOutputFile::Verifier verify;
  };
  /// The members' requested paths, comma-separated.
  std::string names() const;
  std::vector<Member> members_;
  bool committed_ = false;
};

/// The whole content at once (see AtomicOutputFile).
void writeFileAtomically(const std::string& path, const std::string& contents, const OutputFileOptions& options = {},
                         const AtomicOutputFile::Verifier& verify = {});

/// `path` with symbolic links in its last component followed (to at most 40 levels), relative link
/// targets taken relative to the link's directory. A path that does not exist (or a dangling link's
/// missing target) is returned as is: that is where a new file would be created.
std::string resolveOutputTarget(const std::string& path);

/// Where a write of `path` with keep_backup keeps the previous version: its link-resolved target
/// followed by ".bak". Throws as resolveOutputTarget does.
std::string backupPathOf(const std::string& path);

/// Whether two paths name the same file, by checkDistinct's rule below.
bool sameFile(const std::string& a, const std::string& b);

/// Refuses (std::runtime_error, naming both paths) an output that is the same file as one of the
/// inputs or as another output: same device and inode after following links for existing files,
/// same link-resolved absolute path for an output that does not exist yet. Tools call it before
/// they open anything, so that `--out` can never overwrite the file being read.
void checkDistinct(const std::vector<std::string>& inputs, const std::vector<std::string>& outputs);

/// A regular file opened for reading (O_RDONLY, close-on-exec) without ever blocking on what the
/// path names: a directory, a FIFO, a device or a socket is refused from a stat before the open, and
/// again from an fstat of the descriptor, which is opened O_NONBLOCK (cleared once it is known to be a
/// regular file) should the path have been swapped for a FIFO in between. `what` names the file in
/// messages ("bag"). Returns the descriptor, which the caller closes; `size` (when given) receives
/// the file's size. Throws std::runtime_error.
int openRegularFileForReading(const std::string& path, const std::string& what, std::uint64_t* size = nullptr);

/// The content of a regular file of at most `max_bytes`. Refuses without blocking a directory, a
/// FIFO, a device or a socket, and a file above the limit (also one that grows past it while being
/// read). `what` names the file in messages ("parameter file"). Throws std::runtime_error.
std::string readBoundedRegularFile(const std::string& path, std::size_t max_bytes, const std::string& what);

/// Fault injection for the tests: the steps at which an AtomicOutputFile can fail.
namespace fault_injection {
enum class OutputFileStep {
  kWrite,       ///< writing the temporary (a full disk)
  kSync,        ///< fsync of the temporary
  kBackup,      ///< linking the current target under the backup's temporary name
  kRename,      ///< renaming the temporary over the target (the backup's temporary link exists)
  kKeepBackup,  ///< renaming the backup's temporary to <target>.bak, after the target's rename
  kRestore,     ///< AtomicOutputSet: putting a member's previous version back after a failed rename
};
/// Called at each step with the target path; a non-zero return is taken as that step's errno.
/// An empty function (the default) injects nothing. Not thread-safe: set it only in tests.
using OutputFileFault = std::function<int(OutputFileStep step, const std::string& target_path)>;
void setOutputFileFault(OutputFileFault fault);
}  // namespace fault_injection

}  // namespace core
}  // namespace hrg_gyro
