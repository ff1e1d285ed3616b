#include "hrg_gyro/ros/process_heap.h"

#include <malloc.h>

#include <atomic>
#include <chrono>

namespace hrg_gyro {
namespace {

std::atomic<std::int64_t> last_trim_ns{0};
std::atomic<std::uint64_t> trims{0};

std::int64_t steadyNowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

double processHeapInUseMiB() {
  const struct mallinfo2 m = mallinfo2();
  return static_cast<double>(m.uordblks + m.hblkhd) / (1024.0 * 1024.0);
}

bool trimProcessHeap(double period) {
  if (!(period > 0.0)) return false;
  const std::int64_t now = steadyNowNs();
  std::int64_t last = last_trim_ns.load();
  // Compared in seconds: a huge period (1e300 s: never in practice) must not overflow a conversion.
  if (last != 0 && 1e-9 * static_cast<double>(now - last) < period) return false;
  // One caller wins the period; the others see the new stamp and return.
  if (!last_trim_ns.compare_exchange_strong(last, now)) return false;
  malloc_trim(0);
  ++trims;
  return true;
}

void addProcessHeapDiagnostic(diagnostic_updater::Updater& updater, double trim_period) {
  updater.add("memory", [trim_period](diagnostic_updater::DiagnosticStatusWrapper& stat) {
    trimProcessHeap(trim_period);
    stat.summary(diagnostic_msgs::DiagnosticStatus::OK, "process heap");
    stat.addf("process heap in use (MiB)", "%.2f", processHeapInUseMiB());
    stat.add("heap trims", trims.load());
  });
}

}  // namespace hrg_gyro
