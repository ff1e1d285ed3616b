#include "bag_file_writer.h"

#include <bzlib.h>
#include <fcntl.h>
#include <roslz4/lz4s.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace hrg_gyro {
namespace bag_tools {
namespace {

// Record kinds ("op" field) and sizes of the bag format 2.0.
constexpr std::uint8_t kOpMessageData = 0x02, kOpFileHeader = 0x03, kOpIndexData = 0x04, kOpChunk = 0x05,
                       kOpChunkInfo = 0x06, kOpConnection = 0x07;
constexpr char kMagic[] = "#ROSBAG V2.0\n";
constexpr std::uint32_t kFileHeaderLength = 4096;  // the file header record is padded to this, as rosbag's
constexpr int kLz4BlockSizeId = 6;                 // rosbag's LZ4 block size
constexpr int kBz2BlockSize100k = 9, kBz2WorkFactor = 30;

/// Little-endian numbers and "name=value" header fields, appended to a byte buffer.
class Bytes {
 public:
  explicit Bytes(std::vector<std::uint8_t>* out) : out_(*out) {}
  template <class Number>
  void number(Number value) {
    const std::size_t at = out_.size();
    out_.resize(at + sizeof value);
    std::memcpy(out_.data() + at, &value, sizeof value);
  }
  void time(const ros::Time& t) {
    number(t.sec);
    number(t.nsec);
  }
  void raw(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const std::uint8_t*>(data);
    out_.insert(out_.end(), bytes, bytes + size);
  }
  void field(const char* name, const void* value, std::size_t size) {
    const std::size_t name_length = std::strlen(name);
    number(static_cast<std::uint32_t>(name_length + 1 + size));
    raw(name, name_length);
    out_.push_back('=');
    raw(value, size);
  }
  template <class Number>
  void numberField(const char* name, Number value) {
    field(name, &value, sizeof value);
  }
  void timeField(const char* name, const ros::Time& t) {
    const std::uint32_t both[2] = {t.sec, t.nsec};
    field(name, both, sizeof both);
  }
  void textField(const char* name, const std::string& value) { field(name, value.data(), value.size()); }
  /// A length prefix written as 0 and filled in by endLength.
  std::size_t beginLength() {
    const std::size_t at = out_.size();
    number(std::uint32_t{0});
    return at;
  }
  void endLength(std::size_t at) {
    const auto length = static_cast<std::uint32_t>(out_.size() - at - sizeof(std::uint32_t));
    std::memcpy(out_.data() + at, &length, sizeof length);
  }

 private:
  std::vector<std::uint8_t>& out_;
};

// A connection record (its header: op, topic, conn; its data: the type's name, MD5 and definition), as
// a chunk carries it before the connection's first message and the index section at the end again.
void connectionRecord(Bytes* out, std::uint32_t id, const std::string& topic, const std::string& datatype,
                      const std::string& md5sum, const std::string& definition) {
  const std::size_t header = out->beginLength();
  out->numberField("op", kOpConnection);
  out->textField("topic", topic);
  out->numberField("conn", id);
  out->endLength(header);
  const std::size_t data = out->beginLength();
  out->textField("type", datatype);
  out->textField("md5sum", md5sum);
  out->textField("message_definition", definition);
  out->endLength(data);
}

}  // namespace

BagFileWriter::BagFileWriter(const std::string& path, Compression compression, std::uint32_t chunk_threshold)
    : path_(path), compression_(compression), chunk_threshold_(chunk_threshold) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw BagWriteError("cannot create " + path, errno);
  try {
    stage_ = std::make_unique<core::DirectFileBuffer>(fd_, std::size_t{4} << 20, true);
  } catch (...) {
    ::close(fd_);
    throw;
  }
  chunk_ = takeChunk();
  writeFile(kMagic, sizeof kMagic - 1);
  writeFileHeader(0);  // rewritten by close() with the index position
  worker_ = std::make_unique<SerialWorker>(kChunksWaiting);
}

BagFileWriter::~BagFileWriter() {
  worker_.reset();  // no write may still be under way when the descriptor closes
  if (fd_ >= 0) ::close(fd_);
}

std::uint32_t BagFileWriter::connectionOf(const std::string& topic, const char* datatype, const char* md5sum,
                                          const char* definition) {
  if (last_connection_ < connections_.size() && connections_[last_connection_].topic == topic) {
    return static_cast<std::uint32_t>(last_connection_);
  }
  for (std::size_t i = 0; i < connections_.size(); ++i) {
    if (connections_[i].topic == topic) {
      last_connection_ = i;
      return static_cast<std::uint32_t>(i);
    }
  }
  connections_.push_back({topic, datatype, md5sum, definition});
  last_connection_ = connections_.size() - 1;
  return static_cast<std::uint32_t>(last_connection_);
}

std::uint8_t* BagFileWriter::beginMessage(std::uint32_t connection, const ros::Time& time, std::uint32_t length) {
  if (time < ros::TIME_MIN) throw BagWriteError("cannot write " + path_ + ": a message stamped before 0.000000001", 0);
  Chunk& chunk = *chunk_;
  if (chunk.bytes.empty()) {
    chunk.start = chunk.end = time;
  } else {
    if (time < chunk.start) chunk.start = time;
    if (time > chunk.end) chunk.end = time;
  }
  Bytes out(&chunk.bytes);
  Connection& c = connections_[connection];
  if (!c.in_file) {
    // A connection's record goes into the first chunk that carries it (and into the index at the end).
    c.in_file = true;
    connectionRecord(&out, connection, c.topic, c.datatype, c.md5sum, c.definition);
  }
  // A recycled chunk keeps its connections' index lists (emptied, with their capacity).
  ChunkIndex* index = nullptr;
  for (ChunkIndex& i : chunk.index) {
    if (i.connection == connection) index = &i;
  }
  if (!index) {
    chunk.index.push_back({connection, {}});
    index = &chunk.index.back();
  }
  index->entries.push_back({time, static_cast<std::uint32_t>(chunk.bytes.size())});
  const std::size_t header = out.beginLength();
  out.numberField("op", kOpMessageData);
  out.numberField("conn", connection);
  out.timeField("time", time);
  out.endLength(header);
  out.number(length);
  const std::size_t at = chunk.bytes.size();
  chunk.bytes.resize(at + length);
  return chunk.bytes.data() + at;
}

void BagFileWriter::endMessage() {
  if (chunk_->bytes.size() > chunk_threshold_) flushChunk();
}

std::shared_ptr<BagFileWriter::Chunk> BagFileWriter::takeChunk() {
  {
    std::lock_guard<std::mutex> lock(spare_mutex_);
    if (!spare_chunks_.empty()) {
      std::shared_ptr<Chunk> chunk = std::move(spare_chunks_.back());
      spare_chunks_.pop_back();
      return chunk;
    }
  }
  auto chunk = std::make_shared<Chunk>();
  chunk->bytes.reserve(chunk_threshold_ + (64u << 10));
  ++chunks_allocated_;
  return chunk;
}

void BagFileWriter::flushChunk() {
  if (chunk_->bytes.empty()) return;
  // The full chunk goes to the worker, which returns it to the spares once written; a spare (or,
  // while the worker holds them all, a new one) takes the next messages. Submitted first: submit
  // waits while kChunksWaiting chunks wait, so a new chunk is made only while at most that many wait
  // and one is written, which bounds the chunks ever made by kMaxChunksAlive. (Taken first, the
  // next chunk would be one more, made while the full one still waits to be queued.)
  worker_->submit([this, full = chunk_] {
    writeChunk(*full);
    full->bytes.clear();
    for (ChunkIndex& index : full->index) index.entries.clear();
    std::lock_guard<std::mutex> lock(spare_mutex_);
    spare_chunks_.push_back(full);
  });
  chunk_ = takeChunk();
}

void BagFileWriter::writeChunk(Chunk& chunk) {
  const std::uint8_t* data = chunk.bytes.data();
  std::size_t size = chunk.bytes.size();
  const char* compression = "none";
  if (compression_ == Compression::kLz4) {
    compression = "lz4";
    compressed_.resize(chunk.bytes.size() + chunk.bytes.size() / 64 + 4096);
    for (;;) {
      unsigned int out_size = static_cast<unsigned int>(compressed_.size());
      const int result =
          roslz4_buffToBuffCompress(const_cast<char*>(reinterpret_cast<const char*>(chunk.bytes.data())),
                                    static_cast<unsigned int>(chunk.bytes.size()),
                                    reinterpret_cast<char*>(compressed_.data()), &out_size, kLz4BlockSizeId);
      if (result == ROSLZ4_OK) {
        size = out_size;
        break;
      }
      if (result != ROSLZ4_OUTPUT_SMALL) throw BagWriteError("cannot write " + path_ + ": LZ4 compression failed", 0);
      compressed_.resize(compressed_.size() * 2);
    }
    data = compressed_.data();
  } else if (compression_ == Compression::kBz2) {
    compression = "bz2";
    // bzip2's documented worst case is +1 % + 600.
    compressed_.resize(chunk.bytes.size() + chunk.bytes.size() / 100 + 4096);
    unsigned int out_size = static_cast<unsigned int>(compressed_.size());
    if (BZ2_bzBuffToBuffCompress(reinterpret_cast<char*>(compressed_.data()), &out_size,
                                 const_cast<char*>(reinterpret_cast<const char*>(chunk.bytes.data())),
                                 static_cast<unsigned int>(chunk.bytes.size()), kBz2BlockSize100k, 0,
                                 kBz2WorkFactor) != BZ_OK) {
      throw BagWriteError("cannot write " + path_ + ": BZ2 compression failed", 0);
    }
    size = out_size;
    data = compressed_.data();
  }
  ChunkInfo info{file_position_, chunk.start, chunk.end, {}};
  scratch_.clear();
  Bytes out(&scratch_);
  const std::size_t header = out.beginLength();
  out.numberField("op", kOpChunk);
  out.textField("compression", compression);
  out.numberField("size", static_cast<std::uint32_t>(chunk.bytes.size()));
  out.endLength(header);
  out.number(static_cast<std::uint32_t>(size));
  writeFile(scratch_.data(), scratch_.size());
  writeFile(data, size);
  // The index data records of the chunk, one per connection, right after it, in the order of the
  // connection ids as rosbag writes them (a recycled chunk lists its connections in the order of
  // an earlier chunk).
  std::sort(chunk.index.begin(), chunk.index.end(),
            [](const ChunkIndex& a, const ChunkIndex& b) { return a.connection < b.connection; });
  scratch_.clear();
  for (const ChunkIndex& index : chunk.index) {
    if (index.entries.empty()) continue;  // a recycled chunk's connection with no message this time
    const auto count = static_cast<std::uint32_t>(index.entries.size());
    const std::size_t index_header = out.beginLength();
    out.numberField("op", kOpIndexData);
    out.numberField("ver", std::uint32_t{1});
    out.numberField("conn", index.connection);
    out.numberField("count", count);
    out.endLength(index_header);
    out.number(static_cast<std::uint32_t>(count * 12u));
    for (const IndexEntry& e : index.entries) {
      out.time(e.time);
      out.number(e.offset);
    }
    info.counts.emplace_back(index.connection, count);
  }
  writeFile(scratch_.data(), scratch_.size());
  chunks_.push_back(std::move(info));
}

void BagFileWriter::close() {
  flushChunk();
  worker_->finish();
  const std::uint64_t index_position = file_position_;
  scratch_.clear();
  Bytes out(&scratch_);
  for (std::size_t id = 0; id < connections_.size(); ++id) {
    const Connection& c = connections_[id];
    connectionRecord(&out, static_cast<std::uint32_t>(id), c.topic, c.datatype, c.md5sum, c.definition);
  }
  for (const ChunkInfo& chunk : chunks_) {
    const std::size_t header = out.beginLength();
    out.numberField("op", kOpChunkInfo);
    out.numberField("ver", std::uint32_t{1});
    out.numberField("chunk_pos", chunk.position);
    out.timeField("start_time", chunk.start);
    out.timeField("end_time", chunk.end);
    out.numberField("count", static_cast<std::uint32_t>(chunk.counts.size()));
    out.endLength(header);
    out.number(static_cast<std::uint32_t>(chunk.counts.size() * 8u));
    for (const auto& count : chunk.counts) {
      out.number(count.first);
      out.number(count.second);
    }
  }
  writeFile(scratch_.data(), scratch_.size());
  seekFile(sizeof kMagic - 1);
  writeFileHeader(index_position);
  flushStaged();
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) throw BagWriteError("cannot close " + path_, errno);
}

void BagFileWriter::writeFileHeader(std::uint64_t index_position) {
  std::vector<std::uint8_t> record;
  Bytes out(&record);
  const std::size_t header = out.beginLength();
  out.numberField("op", kOpFileHeader);
  out.numberField("index_pos", index_position);
  out.numberField("conn_count", static_cast<std::uint32_t>(connections_.size()));
  out.numberField("chunk_count", static_cast<std::uint32_t>(chunks_.size()));
  out.endLength(header);
  const std::uint32_t padding = kFileHeaderLength - static_cast<std::uint32_t>(record.size() - sizeof(std::uint32_t));
  out.number(padding);
  record.resize(record.size() + padding, ' ');
  writeFile(record.data(), record.size());
}

void BagFileWriter::writeFile(const void* data, std::size_t size) {
  if (const int error = stage_->append(data, size)) throw BagWriteError("cannot write " + path_, error);
  file_position_ += size;
}

void BagFileWriter::flushStaged() {
  if (const int error = stage_->write(true)) throw BagWriteError("cannot write " + path_, error);
}

void BagFileWriter::seekFile(std::uint64_t position) {
  flushStaged();
  if (::lseek(fd_, static_cast<off_t>(position), SEEK_SET) < 0) throw BagWriteError("cannot seek in " + path_, errno);
  file_position_ = position;
}

}  // namespace bag_tools
}  // namespace hrg_gyro
