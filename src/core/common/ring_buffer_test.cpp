#include "hrg_gyro/core/common/ring_buffer.h"

#include <gtest/gtest.h>

#include <deque>
#include <random>

namespace hrg_gyro {
namespace core {
namespace {

TEST(RingBufferTest, BehavesAsADequeThroughGrowthAndWrapAround) {
  RingBuffer<int> ring(1000);
  std::deque<int> reference;
  std::mt19937 rng(7);
  int next = 0;
  for (int step = 0; step < 20000; ++step) {
    // Mostly pushes at first (growth while wrapped), then balanced (wrap-around at full size).
    const bool push = reference.empty() || (reference.size() < 1000 && rng() % 100 < (step < 5000 ? 70 : 50));
    if (push) {
      ring.push_back(next);
      reference.push_back(next++);
    } else {
      ring.pop_front();
      reference.pop_front();
    }
    ASSERT_EQ(ring.size(), reference.size());
    if (!reference.empty()) {
      ASSERT_EQ(ring.front(), reference.front());
      ASSERT_EQ(ring.back(), reference.back());
      const std::size_t i = rng() % reference.size();
      ASSERT_EQ(ring[i], reference[i]);
    }
  }
  EXPECT_LE(ring.capacity(), 1000u);
}

TEST(RingBufferTest, StopsAllocatingOnceItHasGrown) {
  RingBuffer<int> ring(100000);
  for (int i = 0; i < 5000; ++i) ring.push_back(i);
  const std::size_t capacity = ring.capacity();
  const int* storage = &ring[0];       // the block's start: nothing was popped yet
  for (int i = 0; i < 1000000; ++i) {  // a steady FIFO of 5000 elements
    ring.pop_front();
    ring.push_back(i);
  }
  EXPECT_EQ(ring.capacity(), capacity);
  EXPECT_EQ(ring.size(), 5000u);
  // Still the same block: every element lies inside it.
  for (std::size_t i = 0; i < ring.size(); i += 499) {
    EXPECT_GE(&ring[i], storage);
    EXPECT_LT(&ring[i], storage + capacity);
  }
  EXPECT_EQ(ring.front(), 995000);
  EXPECT_EQ(ring.back(), 999999);
}

TEST(RingBufferTest, LowerBoundOnSortedContentAcrossTheWrap) {
  RingBuffer<int> ring(8);
  for (int i = 0; i < 6; ++i) ring.push_back(10 * i);   // 0..50
  for (int i = 0; i < 4; ++i) ring.pop_front();         // 40, 50
  for (int i = 6; i < 11; ++i) ring.push_back(10 * i);  // 40..100, wrapped
  const auto less = [](int v, int key) { return v < key; };
  EXPECT_EQ(ring.lowerBound(40, less), 0u);
  EXPECT_EQ(ring.lowerBound(41, less), 1u);
  EXPECT_EQ(ring.lowerBound(100, less), 6u);
  EXPECT_EQ(ring.lowerBound(101, less), 7u);
  EXPECT_EQ(ring.lowerBound(-5, less), 0u);
}

TEST(RingBufferTest, RefusesToGrowBeyondItsMaximum) {
  RingBuffer<int> ring(3);
  ring.push_back(1);
  ring.push_back(2);
  ring.push_back(3);
  EXPECT_THROW(ring.push_back(4), std::length_error);
  ring.clear();
  EXPECT_TRUE(ring.empty());
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
