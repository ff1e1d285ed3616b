#include "hrg_gyro/core/estimation/rate_groups.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace hrg_gyro {
namespace core {

double RateGroup::rateStd() const {
  if (rate_count < 2) return 0.0;
  const double m = meanRate();
  return std::sqrt(std::max(0.0, rate_sq_sum / rate_count - m * m));
}

double RateGroup::totalTime() const {
  double t = 0.0;
  for (const auto& kv : slices) t += kv.second.totalTime();
  return t;
}

std::uint64_t RateGroup::samples() const {
  std::uint64_t n = 0;
  for (const auto& kv : slices) n += kv.second.samples();
  return n;
}

double RateGroup::thetaSwept() const {
  double a = 0.0;
  for (const auto& kv : slices) a += kv.second.thetaSwept();
  return a;
}

const ThetaBinnedRates& RateGroup::rates() const {
  if (slices.size() != 1) throw std::logic_error("rates() of a rate group kept in frequency slices");
  return slices.begin()->second;
}

RateGroups::RateGroups(int bins, double window, double window_span, double theta_per_rate, int max_order,
                       double tolerance, double max_gap, double slice_width, int max_slices)
    : bins_(bins),
      window_(window),
      window_span_(window_span),
      theta_per_rate_(theta_per_rate),
      max_order_(max_order),
      tolerance_(tolerance),
      max_gap_(max_gap),
      slice_width_(slice_width),
      max_slices_(max_slices) {
  if (!(slice_width >= 0.0) || !std::isfinite(slice_width)) {
    throw std::invalid_argument("slice width must be 0 (no slices) or positive");
  }
}

bool RateGroups::add(Nanoseconds stamp, double theta, double y, std::uint64_t plateau_id, double plateau_rate,
                     double reported_rate, double frequency) {
  RateGroup* group = nullptr;
  for (RateGroup& g : groups_) {
    if (std::abs(g.meanPlateauRate() - plateau_rate) <= tolerance_) {
      group = &g;
      break;
    }
  }
  if (!group) {
    groups_.emplace_back();
    group = &groups_.back();
    group->window = windowFor(plateau_rate);
  }
  // Stay in the current slice unless the frequency has left it by more than the hysteresis.
  long slice = sliceOf(frequency);
  if (group->in_slice && slice != group->current_slice) {
    const double lo = group->current_slice * slice_width_, hysteresis = 0.1 * slice_width_;
    if (frequency >= lo - hysteresis && frequency < lo + slice_width_ + hysteresis) slice = group->current_slice;
  }
  auto it = group->slices.find(slice);
  if (it == group->slices.end()) {
    if (sliced() && slice_count_ >= max_slices_) return false;
    it = group->slices.emplace(slice, ThetaBinnedRates(bins_, group->window, max_order_)).first;
    ++slice_count_;
  }
  const bool new_chain = !group->in_slice || slice != group->current_slice || group->last_plateau != plateau_id ||
                         (group->last_stamp != 0 && toSeconds(stamp - group->last_stamp) > max_gap_);
  if (new_chain) {
    if (group->in_slice && slice != group->current_slice) {
      auto previous = group->slices.find(group->current_slice);
      if (previous != group->slices.end()) previous->second.breakChain();
    }
    it->second.breakChain();
  }
  group->in_slice = true;
  group->current_slice = slice;
  group->last_plateau = plateau_id;
  group->last_stamp = stamp;
  it->second.add(stamp, theta, y, frequency);
  group->rate_sum += reported_rate;
  group->plateau_rate_sum += plateau_rate;
  group->rate_sq_sum += reported_rate * reported_rate;
  ++group->rate_count;
  return true;
}

std::vector<std::size_t> RateGroups::byDuration() const {
  std::vector<std::size_t> idx(groups_.size());
  std::iota(idx.begin(), idx.end(), 0);
  std::stable_sort(idx.begin(), idx.end(),
                   [this](std::size_t a, std::size_t b) { return groups_[a].totalTime() > groups_[b].totalTime(); });
  return idx;
}

}  // namespace core
}  // namespace hrg_gyro
