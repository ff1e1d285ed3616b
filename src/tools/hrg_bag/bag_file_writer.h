// Writes a ROS bag (format 2.0, what rosbag::Bag writes and every rosbag reader reads) by whole
// chunks. rosbag::Bag::write seeks to the end of the file twice per message, and each seek of its
// stdio stream costs a flush, a stat, a seek and a read: about six system calls per message, which
// made writing the output bag of `hrg_bag process` ten times slower than reading its input. Here a
// message is serialised straight into the chunk in memory, and the file sees one large write per
// chunk plus the index at the end. A full chunk is compressed and written by a background thread
// (SerialWorker) while the next one fills; written chunks come back to be filled again, so memory is
// allocated once, and never more than kMaxChunksAlive chunks, however far the background thread
// falls behind (a loaded machine): the thread filling chunks then waits for it.
// Layout written: the file header record (padded to 4 KiB like rosbag's, rewritten on close), then
// per chunk a chunk record (connection records of the connections it introduces, then the message
// data records; none, LZ4 or BZ2 compressed) followed by its index data records (by connection id, as
// rosbag orders them), and at the end the connection records and the chunk info records the file
// header points at.
#pragma once

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <ros/time.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/direct_file_buffer.h"
#include "serial_worker.h"

namespace hrg_gyro {
namespace bag_tools {

/// A write to the file failed; `error` is the errno of the failed call (ENOSPC on a full disk).
struct BagWriteError : std::runtime_error {
  BagWriteError(const std::string& what, int error) : std::runtime_error(what), error(error) {}
  int error;
};

class BagFileWriter {
 public:
  enum class Compression { kNone, kLz4, kBz2 };

  /// Full chunks that may wait for the background thread besides the one it writes. One keeps both
  /// threads busy; each more would only cost memory while the thread is behind.
  static constexpr std::size_t kChunksWaiting = 1;
  /// The most chunks in memory at once, whatever the load: the one filling, the waiting ones and the
  /// one being written. A chunk holds up to `chunk_threshold` bytes plus its last message, and 12
  /// bytes of index a message (up to twice that touched, as the index grows). With the compression
  /// buffer (a chunk's size), LZ4's own (1.1 MiB), the index records and the 4 MiB file stage, the
  /// writer's worst case at the default threshold is about 3 x (4.06 + 0.8) + 4.1 + 1.1 + 0.4 + 4 =
  /// 24 MiB for messages of about 120 bytes (docs/importing_logs.md).
  static constexpr std::size_t kMaxChunksAlive = kChunksWaiting + 2;

  /// Creates (truncates) `path`. Chunks close once they hold more than `chunk_threshold` bytes.
  BagFileWriter(const std::string& path, Compression compression, std::uint32_t chunk_threshold = 4u << 20);
  ~BagFileWriter();
  BagFileWriter(const BagFileWriter&) = delete;
  BagFileWriter& operator=(const BagFileWriter&) = delete;

  /// Appends `message` on `topic` recorded at `time` (>= ros::TIME_MIN, as rosbag requires).
  template <class Message>
  void write(const std::string& topic, const ros::Time& time, const Message& message) {
    const std::uint32_t connection =
        connectionOf(topic, ros::message_traits::datatype<Message>(), ros::message_traits::md5sum<Message>(),
                     ros::message_traits::definition<Message>());
    const std::uint32_t length = ros::serialization::serializationLength(message);
    std::uint8_t* data = beginMessage(connection, time, length);
    ros::serialization::OStream stream(data, length);
    ros::serialization::serialize(stream, message);
    endMessage();
  }

  /// Writes the last chunk, the index and the final file header, and closes the file.
  void close();

  /// The chunks allocated so far: at most kMaxChunksAlive (the tests check the bound).
  std::size_t chunksAllocated() const { return chunks_allocated_; }

 private:
  struct Connection {
    std::string topic, datatype, md5sum, definition;
    bool in_file = false;  // its connection record is already in an earlier chunk
  };
  struct IndexEntry {
    ros::Time time;
    std::uint32_t offset;
  };
  struct ChunkIndex {
    std::uint32_t connection;
    std::vector<IndexEntry> entries;
  };
  /// A chunk's bytes and its index, handed to the worker whole; recycled with their capacity, so a
  /// session of any length allocates a few chunks' worth of memory once (a fresh 4 MiB buffer per
  /// chunk cost a page fault per 4 KiB, a tenth of the time of writing a bag).
  struct Chunk {
    std::vector<std::uint8_t> bytes;
    std::vector<ChunkIndex> index;  // per connection
    ros::Time start, end;
  };
  struct ChunkInfo {
    std::uint64_t position;
    ros::Time start, end;
    std::vector<std::pair<std::uint32_t, std::uint32_t>> counts;  // connection, messages
  };

  std::uint32_t connectionOf(const std::string& topic, const char* datatype, const char* md5sum,
                             const char* definition);
  std::uint8_t* beginMessage(std::uint32_t connection, const ros::Time& time, std::uint32_t length);
  void endMessage();
  void flushChunk();
  /// An emptied chunk from the spares, or a new one.
  std::shared_ptr<Chunk> takeChunk();
  /// In the worker: compresses `chunk` and writes it and its index records (sorting the index).
  void writeChunk(Chunk& chunk);
  void writeFileHeader(std::uint64_t index_position);
  /// Appends to the file (through stage_).
  void writeFile(const void* data, std::size_t size);
  /// Writes everything stage_ holds (the last partial block through the page cache).
  void flushStaged();
  void seekFile(std::uint64_t position);

  std::string path_;
  int fd_ = -1;
  // The file goes out through this buffer, in whole blocks around the page cache where the file
  // system allows (the bag is synced before it replaces its path anyway).
  std::unique_ptr<core::DirectFileBuffer> stage_;
  Compression compression_;
  std::uint32_t chunk_threshold_;
  std::uint64_t file_position_ = 0;
  std::vector<Connection> connections_;
  std::size_t last_connection_ = 0;  // the connection of the previous write: looked at first
  std::shared_ptr<Chunk> chunk_;     // the open chunk, filled by write()
  std::mutex spare_mutex_;           // guards spare_chunks_, which the worker refills
  std::vector<std::shared_ptr<Chunk>> spare_chunks_;
  std::size_t chunks_allocated_ = 0;  // by takeChunk, on the thread that writes
  // Used by the worker while it runs, by close() once it has finished.
  std::vector<std::uint8_t> compressed_, scratch_;
  std::vector<ChunkInfo> chunks_;
  std::unique_ptr<SerialWorker> worker_;  // stopped before the file is closed
};

}  // namespace bag_tools
}  // namespace hrg_gyro
