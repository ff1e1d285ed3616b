#include "hrg_gyro/core/common/direct_file_buffer.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <new>

namespace hrg_gyro {
namespace core {

DirectFileBuffer::DirectFileBuffer(int fd, std::size_t capacity, bool direct)
    : fd_(fd),
      data_(nullptr, std::free),
      capacity_(std::max<std::size_t>(1, (capacity + kBlock - 1) / kBlock) * kBlock) {
  data_.reset(static_cast<char*>(std::aligned_alloc(kBlock, capacity_)));
  if (!data_) throw std::bad_alloc();
  direct_ = direct && setDirect(true);
}

int DirectFileBuffer::append(const void* bytes, std::size_t n) {
  const char* from = static_cast<const char*>(bytes);
  while (n > 0) {
    const std::size_t take = std::min(n, capacity_ - size_);
    std::memcpy(data_.get() + size_, from, take);
    size_ += take;
    from += take;
    n -= take;
    if (size_ == capacity_) {
      if (const int error = write(false)) return error;
    }
  }
  return 0;
}

int DirectFileBuffer::write(bool all) {
  if (all && direct_) {
    if (!setDirect(false)) return errno != 0 ? errno : EIO;
    direct_ = false;
  }
  const std::size_t now = direct_ ? size_ / kBlock * kBlock : size_;
  std::size_t done = 0;
  while (done < now) {
    const ssize_t n = ::write(fd_, data_.get() + done, now - done);
    if (n < 0) {
      const int error = errno;
      if (error == EINTR) continue;
      if (error == EINVAL && direct_ && setDirect(false)) {
        direct_ = false;
        continue;
      }
      consume(done);
      return error;
    }
    done += static_cast<std::size_t>(n);
  }
  consume(now);
  return 0;
}

bool DirectFileBuffer::setDirect(bool on) {
  const int flags = ::fcntl(fd_, F_GETFL);
  return flags >= 0 && ::fcntl(fd_, F_SETFL, on ? flags | O_DIRECT : flags & ~O_DIRECT) == 0;
}

void DirectFileBuffer::consume(std::size_t n) {
  std::memmove(data_.get(), data_.get() + n, size_ - n);
  size_ -= n;
}

}  // namespace core
}  // namespace hrg_gyro
