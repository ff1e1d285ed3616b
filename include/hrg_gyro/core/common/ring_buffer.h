// A FIFO of values in one block that grows (doubling, up to a maximum) but never churns the heap.
//
// The calibration session keeps the last tens of seconds of two 10 kHz streams. As std::deque
// they cost an allocation every few samples and a free 40 s later; over an hour that steady FIFO
// turnover, interleaved with the messages' short-lived allocations, let glibc's arenas creep upward
// (about 3 MiB/h of resident memory with the live heap flat at 25.2 MiB, measured in the soak).
// Here the storage is allocated a few times while the buffer first grows, then reused in place.
#pragma once

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace hrg_gyro {
namespace core {

template <typename T>
class RingBuffer {
 public:
  /// max_size: the most elements it will hold; push_back beyond it is the caller's error.
  explicit RingBuffer(std::size_t max_size) : max_size_(max_size) {}

  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  std::size_t capacity() const { return slots_.size(); }

  /// Element i from the front (0 = oldest).
  const T& operator[](std::size_t i) const { return slots_[wrap(head_ + i)]; }
  T& operator[](std::size_t i) { return slots_[wrap(head_ + i)]; }
  const T& front() const { return (*this)[0]; }
  const T& back() const { return (*this)[size_ - 1]; }

  void push_back(const T& value) {
    if (size_ == slots_.size()) grow();
    slots_[wrap(head_ + size_)] = value;
    ++size_;
  }
  void pop_front() {
    head_ = wrap(head_ + 1);
    --size_;
  }
  void clear() { head_ = size_ = 0; }

  /// Index of the first element for which less(element, key) is false (elements sorted by key).
  template <typename Key, typename Less>
  std::size_t lowerBound(const Key& key, Less less) const {
    std::size_t lo = 0, hi = size_;
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (less((*this)[mid], key)) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return lo;
  }

 private:
  std::size_t wrap(std::size_t i) const { return i >= slots_.size() ? i - slots_.size() : i; }

  void grow() {
    if (slots_.size() >= max_size_) throw std::length_error("RingBuffer: full");
    std::vector<T> bigger(std::min(max_size_, std::max<std::size_t>(64, 2 * slots_.size())));
    for (std::size_t i = 0; i < size_; ++i) bigger[i] = (*this)[i];
    slots_.swap(bigger);
    head_ = 0;
  }

  std::size_t max_size_;
  std::vector<T> slots_;
  std::size_t head_ = 0, size_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
