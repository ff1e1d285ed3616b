#include "hrg_gyro/core/calibration/triad/triad_position_samples.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/model/model_pair_evaluator.h"

namespace hrg_gyro {
namespace core {
namespace {

/// Interpolates a stored series at `stamp` (series sorted by stamp); false outside it or across a gap.
bool interpolate(const StampedSeries& series, Nanoseconds stamp, double max_gap, double* value) {
  const auto after =
      std::lower_bound(series.begin(), series.end(), stamp,
                       [](const std::pair<Nanoseconds, double>& s, Nanoseconds t) { return s.first < t; });
  if (after == series.end()) return false;
  if (after->first == stamp) {
    *value = after->second;
    return true;
  }
  if (after == series.begin()) return false;
  const auto before = after - 1;
  const double span = toSeconds(after->first - before->first);
  if (!(span > 0.0) || span > max_gap) return false;
  const double f = toSeconds(stamp - before->first) / span;
  *value = before->second + f * (after->second - before->second);
  return true;
}

/// The table's plateau records of the stamps [from, to), judged as the sessions judge them.
std::vector<PlateauRecord> judgedPlateaus(const TriadSeries& series, Nanoseconds from, Nanoseconds to,
                                          const PlateauSettings& settings) {
  PlateauDetector detector(settings);
  std::vector<PlateauRecord> judged, out;
  for (std::size_t k = 0; k < series.table.size(); ++k) {
    if (series.table[k].first < from || series.table[k].first >= to) continue;
    out.clear();
    detector.add(series.table[k].first, series.table[k].second, series.table_rates[k], &out);
    judged.insert(judged.end(), out.begin(), out.end());
  }
  return judged;
}

}  // namespace

StampedSeries compensatedAngle(const StampedSeries& theta, const GyroParameters& parameters) {
  ModelPairEvaluator models(parameters.scale_factor, parameters.drift);
  StampedSeries alpha;
  double a = 0.0;
  for (std::size_t k = 0; k < theta.size(); ++k) {
    if (k > 0) {
      const double dt = toSeconds(theta[k].first - theta[k - 1].first);
      double kk, dd;
      models.evaluate(0.5 * (theta[k].second + theta[k - 1].second), NAN, &kk, &dd);
      a += (theta[k].second - theta[k - 1].second - dd * dt) / kk;
    }
    alpha.push_back({theta[k].first, a});
  }
  return alpha;
}

std::vector<std::pair<std::size_t, std::size_t>> plateauRuns(const std::vector<TriadPositionSample>& samples) {
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  std::size_t begin = 0;
  while (begin < samples.size()) {
    std::size_t end = begin;
    while (end < samples.size() && samples[end].plateau == samples[begin].plateau) ++end;
    runs.emplace_back(begin, end);
    begin = end;
  }
  return runs;
}

std::vector<TriadPositionSample> positionSamples(const TriadSeries& series, Nanoseconds from, Nanoseconds to,
                                                 const PlateauSettings& plateau, double max_gap) {
  const std::vector<PlateauRecord> judged = judgedPlateaus(series, from, to, plateau);
  std::vector<TriadPositionSample> points;
  if (judged.size() < 3) return points;
  for (const auto& s : series.alpha[0]) {
    if (s.first < judged.front().stamp || s.first > judged.back().stamp) continue;
    const auto after = std::lower_bound(judged.begin(), judged.end(), s.first,
                                        [](const PlateauRecord& r, Nanoseconds t) { return r.stamp < t; });
    if (after == judged.end() || after == judged.begin()) continue;
    const PlateauRecord& b = *after;
    const PlateauRecord& a = *(after - 1);
    if (a.plateau.id != b.plateau.id || !a.plateau.settled) continue;
    TriadPositionSample p;
    p.stamp = s.first;
    p.plateau = b.plateau.id;
    p.is_static = b.plateau.is_static;
    bool ok = interpolate(series.table, s.first, max_gap, &p.phi);
    for (int i = 0; i < 3 && ok; ++i) {
      ok = interpolate(series.alpha[i], s.first, max_gap, &p.alpha[i]) &&
           interpolate(series.theta[i], s.first, max_gap, &p.theta[i]);
    }
    if (ok) points.push_back(p);
  }
  return points;
}

}  // namespace core
}  // namespace hrg_gyro
