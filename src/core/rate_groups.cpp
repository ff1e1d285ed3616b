#include "hrg_gyro/core/rate_groups.h"

#include <algorithm>
#include <numeric>

namespace hrg_gyro {
namespace core {

void RateGroups::add(Nanoseconds stamp, double theta, double y, std::uint64_t plateau_id, double plateau_rate,
                     double reported_rate) {
  RateGroup* group = nullptr;
  for (RateGroup& g : groups_) {
    if (std::abs(g.meanRate() - plateau_rate) <= tolerance_) {
      group = &g;
      break;
    }
  }
  if (!group) {
    groups_.emplace_back(bins_, windowFor(plateau_rate), max_order_);
    group = &groups_.back();
  }
  if (group->last_plateau != plateau_id || (group->last_stamp != 0 && toSeconds(stamp - group->last_stamp) > max_gap_)) {
    group->rates.breakChain();
  }
  group->last_plateau = plateau_id;
  group->last_stamp = stamp;
  group->rates.add(stamp, theta, y);
  group->rate_sum += reported_rate;
  group->rate_sq_sum += reported_rate * reported_rate;
  ++group->rate_count;
}

std::vector<std::size_t> RateGroups::byDuration() const {
  std::vector<std::size_t> idx(groups_.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::stable_sort(idx.begin(), idx.end(), [this](std::size_t a, std::size_t b) {
    return groups_[a].rates.totalTime() > groups_[b].rates.totalTime();
  });
  return idx;
}

}  // namespace core
}  // namespace hrg_gyro
