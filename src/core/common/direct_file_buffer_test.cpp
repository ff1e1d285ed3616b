#include "hrg_gyro/core/common/direct_file_buffer.h"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace hrg_gyro {
namespace core {
namespace {

class DirectFileBufferTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char name[] = "/tmp/hrg_direct_file_buffer_test_XXXXXX";
    fd_ = ::mkstemp(name);
    ASSERT_GE(fd_, 0);
    path_ = name;
  }
  void TearDown() override {
    if (fd_ >= 0) ::close(fd_);
    ::unlink(path_.c_str());
  }
  std::string content() const {
    std::ifstream in(path_, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  }
  off_t length() const {
    struct stat st {};
    ::fstat(fd_, &st);
    return st.st_size;
  }
  int fd_ = -1;
  std::string path_;
};

// Appends of uneven sizes through a small buffer: while O_DIRECT is on only whole blocks reach the
// file, and after write(true) every byte is there in order.
TEST_F(DirectFileBufferTest, WholeBlocksGoOutFirstAndEveryByteArrives) {
  DirectFileBuffer buffer(fd_, 3 * DirectFileBuffer::kBlock + 1, true);
  EXPECT_EQ(buffer.capacity(), 4 * DirectFileBuffer::kBlock);  // rounded up to whole blocks
  std::string expected;
  const std::size_t pieces[] = {1, 4095, 7, 9000, 70001, 3};
  for (std::size_t i = 0; i < 60; ++i) {
    const std::string piece(pieces[i % 6], static_cast<char>('a' + i % 26));
    ASSERT_EQ(buffer.append(piece.data(), piece.size()), 0);
    expected += piece;
    if (buffer.direct()) {
      EXPECT_EQ(length() % DirectFileBuffer::kBlock, 0) << i;
      EXPECT_EQ(static_cast<std::size_t>(length()) + buffer.size(), expected.size()) << i;
    }
  }
  ASSERT_EQ(buffer.write(false), 0);
  if (buffer.direct()) {
    EXPECT_LT(buffer.size(), DirectFileBuffer::kBlock);
  }
  ASSERT_EQ(buffer.write(true), 0);
  EXPECT_FALSE(buffer.direct());
  EXPECT_EQ(buffer.size(), 0u);
  EXPECT_EQ(content(), expected);
}

// Where the file system takes O_DIRECT (this test's /tmp), the buffer uses it; without asking, never.
TEST_F(DirectFileBufferTest, UsesODirectOnlyWhenAskedAndTaken) {
  const int probe = ::open(path_.c_str(), O_WRONLY | O_DIRECT | O_CLOEXEC);
  const bool takes = probe >= 0;
  if (probe >= 0) ::close(probe);
  EXPECT_EQ(DirectFileBuffer(fd_, 8192, true).direct(), takes);
  EXPECT_EQ(::fcntl(fd_, F_GETFL) & O_DIRECT, takes ? O_DIRECT : 0);
  ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) & ~O_DIRECT);
  EXPECT_FALSE(DirectFileBuffer(fd_, 8192, false).direct());
  EXPECT_EQ(::fcntl(fd_, F_GETFL) & O_DIRECT, 0);
}

// A descriptor that cannot be written: the errno comes back, from append() once the buffer is full
// and from write(true).
TEST_F(DirectFileBufferTest, AFailedWriteReturnsItsErrno) {
  const int read_only = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(read_only, 0);
  DirectFileBuffer buffer(read_only, DirectFileBuffer::kBlock, false);
  const std::string small(100, 'x'), large(2 * DirectFileBuffer::kBlock, 'y');
  EXPECT_EQ(buffer.append(small.data(), small.size()), 0);
  EXPECT_EQ(buffer.write(true), EBADF);
  EXPECT_EQ(buffer.append(large.data(), large.size()), EBADF);
  ::close(read_only);
  EXPECT_EQ(content(), "");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
