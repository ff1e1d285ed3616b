// The process's malloc heap: live bytes, and returning freed pages to the operating system.
//
// A stall of the host lets thousands of 10 kHz messages pile up in the subscription queues; they
// are freed once the backlog drains, but glibc keeps the pages (they sit between live chunks), so
// without a trim the resident size keeps every backlog's high-water mark and a soak cannot tell
// that from a leak. Trimming is process-wide and rate-limited across all callers, so nodelets
// sharing a manager trim it once per period between them.
#pragma once

#include <diagnostic_updater/diagnostic_updater.h>

namespace hrg_gyro {

/// Bytes handed out by malloc and not freed, in all arenas (mallinfo2), MiB.
double processHeapInUseMiB();

/// Calls malloc_trim(0) if no caller in this process did so in the last `period` seconds of wall
/// time (period <= 0: never). Returns true when it trimmed.
bool trimProcessHeap(double period);

/// Adds the "memory" status to a node's updater: OK, "process heap in use (MiB)" and "heap trims";
/// each update trims first when due. For the nodes that sit on high-rate queues.
void addProcessHeapDiagnostic(diagnostic_updater::Updater& updater, double trim_period);

}  // namespace hrg_gyro
