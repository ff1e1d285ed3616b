// Generator pairing: raw channels and generator references paired by stamp, whichever comes first,
// with bounded waiting lists.
#include "hrg_gyro/core/calibration/generator_pairing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace hrg_gyro {
namespace core {
namespace {

struct Pair {
  Nanoseconds stamp;
  ChannelVector raw, reference;
};

TEST(GeneratorPairingTest, PairsEqualStampsWhicheverStreamComesFirst) {
  std::vector<Pair> pairs;
  GeneratorPairing pairing([&](Nanoseconds t, const ChannelVector& raw, const ChannelVector& reference) {
    pairs.push_back({t, raw, reference});
  });
  const WaveParameters wave{1.0, 0.01, 0.3, 0.2};
  // Raw channels outside the sweep (no reference will come), then the raw stream ahead by two.
  pairing.addRaw(1, ChannelVector::Constant(1.0));
  pairing.addRaw(10, ChannelVector::Constant(10.0));
  pairing.addRaw(20, ChannelVector::Constant(20.0));
  pairing.addReference(10, wave);
  pairing.addReference(20, wave);
  // Then the reference stream ahead, with one reference whose channels were lost (30).
  pairing.addReference(30, wave);
  pairing.addReference(40, wave);
  pairing.addRaw(40, ChannelVector::Constant(40.0));
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[0].stamp, 10);
  EXPECT_EQ(pairs[1].stamp, 20);
  EXPECT_EQ(pairs[2].stamp, 40);
  EXPECT_EQ(pairs[2].raw, ChannelVector::Constant(40.0));
  EXPECT_TRUE(pairs[0].reference.isApprox(idealChannels(wave)));
  EXPECT_EQ(pairing.waitingRaw() + pairing.waitingReferences(), 0u);
}

TEST(GeneratorPairingTest, WaitingListsStayBounded) {
  int pairs = 0;
  GeneratorPairing pairing([&](Nanoseconds, const ChannelVector&, const ChannelVector&) { ++pairs; }, 100);
  for (Nanoseconds t = 1; t <= 1000; ++t) pairing.addRaw(t, ChannelVector::Zero());
  EXPECT_EQ(pairing.waitingRaw(), 100u);
  pairing.addReference(1000, WaveParameters());  // still waiting: pairs
  pairing.addReference(5, WaveParameters());     // long gone: dropped
  EXPECT_EQ(pairs, 1);
  pairing.clear();
  EXPECT_EQ(pairing.waitingRaw() + pairing.waitingReferences(), 0u);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
