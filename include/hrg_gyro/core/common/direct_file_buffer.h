// A block-aligned buffer in front of a file descriptor that writes whole blocks around the page
// cache (O_DIRECT, where the file system takes it) and the last partial block through it.
//
// For large outputs that are synced before they replace their path anyway: the cache would only
// hold a second copy, filling it costs system time (on the project's VM more than the writing
// itself: BENCHMARKS.md, "Offline"), and the final sync then waits for all of it at once.
// AtomicOutputFile's stream (OutputFileOptions::direct_io) and hrg_bag's bag writer write through it.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <memory>

namespace hrg_gyro {
namespace core {

class DirectFileBuffer {
 public:
  static constexpr std::size_t kBlock = 4096;

  /// Buffers for `fd` (which the caller keeps and closes), `capacity` rounded up to whole blocks.
  /// With `direct` false, or where the file system refuses O_DIRECT, every write goes through the
  /// page cache. Throws std::bad_alloc.
  DirectFileBuffer(int fd, std::size_t capacity, bool direct);
  DirectFileBuffer(const DirectFileBuffer&) = delete;
  DirectFileBuffer& operator=(const DirectFileBuffer&) = delete;

  char* data() { return data_.get(); }
  std::size_t capacity() const { return capacity_; }
  /// The bytes buffered and not written yet, from data().
  std::size_t size() const { return size_; }
  /// For a caller that fills data() itself (a stream buffer's put area): how many bytes it holds.
  void setSize(std::size_t size) { size_ = size; }
  /// Whether whole blocks currently go around the page cache.
  bool direct() const { return direct_; }

  /// Copies `n` bytes in, writing whenever the buffer is full. 0, or the errno of a failed write.
  int append(const void* bytes, std::size_t n);
  /// Writes the buffered bytes: only the whole blocks while O_DIRECT is on (the rest moves to the
  /// front), everything with `all`, which turns O_DIRECT off first (so the last partial block, and
  /// anything written after a seek, go through the cache). A write refused in O_DIRECT mode
  /// (EINVAL: an alignment beyond kBlock) is retried without it. 0, or the errno of a failed write;
  /// what was written before the failure has left the buffer.
  int write(bool all);

 private:
  bool setDirect(bool on);
  /// Drops the first n bytes (written).
  void consume(std::size_t n);

  int fd_;
  std::unique_ptr<char, void (*)(void*)> data_;
  std::size_t capacity_;
  std::size_t size_ = 0;
  bool direct_ = false;
};

}  // namespace core
}  // namespace hrg_gyro
