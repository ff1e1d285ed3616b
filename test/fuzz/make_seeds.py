#!/usr/bin/env python3
"""Writes the seed corpus of the fuzz targets (run once; the files are checked in).

parameter_file: valid files of every form (nominal, harmonics, frequency dependent with spline and
piecewise-linear interpolation, flow style) and typical mistakes. sample_processing: record streams
in the layout of sample_processing_fuzzer.cpp (rotation, glitches, gaps, NaNs, model swaps, resets).
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))

PARAMETER_FILES = {
    "harmonics.yaml": """schema_version: 1
scale_factor:
  orders: [2, 4, 6, 8]
  mean: -0.5612
  cos: [1.0e-3, -2.0e-4, 5.0e-5, 1.0e-6]
  sin: [-4.0e-4, 1.0e-4, 0.0, -2.0e-6]
drift:
  orders: [2, 4]
  mean: 2.0e-5
  cos: [1.0e-5, 0.0]
  sin: [0.0, -3.0e-6]
correction_matrix:
  p: [1.0e-3, -2.0e-3, 5.0e-4, -3.0e-4]
earth_rate:
  enabled: true
  latitude: 0.9
calibration:
  method: dual_rate
  time: "2026-11-21T10:00:00Z"
  source: live
  notes: "two-stage"
""",
    "spline.yaml": """schema_version: 1
scale_factor:
  orders: [2, 4]
  frequency_nodes: [4990.0, 5000.0, 5010.0]
  interpolation: natural_cubic_spline
  mean: [-0.5601, -0.56, -0.5599]
  cos: [[1.0e-3, 1.1e-3, 1.2e-3], [0.0, 1.0e-5, 2.0e-5]]
  sin: [[0.0, 0.0, 0.0], [-1.0e-4, -1.0e-4, -1.0e-4]]
drift:
  orders: [2]
  frequency_nodes: [4990.0, 5010.0]
  interpolation: piecewise_linear
  mean: [1.0e-5, 2.0e-5]
  cos: [[1.0e-5, 0.0]]
  sin: [[0.0, 1.0e-5]]
correction_matrix:
  p: [0.0, 0.0, 0.0, 0.0]
earth_rate:
  enabled: false
  latitude: -0.3
""",
    "flow.yaml": "{schema_version: 1, scale_factor: {orders: [], mean: -0.56, cos: [], sin: []}, "
                 "drift: {orders: [], mean: 0.0, cos: [], sin: []}, correction_matrix: {p: [0, 0, 0, 0]}, "
                 "earth_rate: {enabled: false, latitude: 0}}\n",
    "bad_odd_order.yaml": "schema_version: 1\nscale_factor: {orders: [2, 3], mean: -0.56, cos: [0, 0], sin: [0, 0]}\n",
    "bad_positive_k0.yaml": "schema_version: 1\nscale_factor: {orders: [], mean: 0.56, cos: [], sin: []}\n",
    "bad_nan.yaml": "schema_version: 1\nscale_factor: {orders: [2], mean: .nan, cos: [0], sin: [0]}\n",
    "bad_nodes.yaml": "schema_version: 1\nscale_factor: {orders: [2], frequency_nodes: [5000, 4990], "
                      "mean: [-0.56, -0.56], cos: [[0, 0]], sin: [[0, 0]]}\n",
    "bad_truncated.yaml": "schema_version: 1\nscale_factor:\n  orders: [2, 4]\n  mean: -0.5",
    "bad_anchors.yaml": "schema_version: 1\nscale_factor: &a {orders: [2], mean: -0.56, cos: [0], sin: [0]}\n"
                        "drift: *a\n",
}


def record_plausible(dtheta, amp=40, quad=3, phase=10, dt_us=1000, freq=100):
    return struct.pack("<BhBbbHB", 1, dtheta, amp, quad, phase, dt_us, freq)


def record_raw(stamp, z, f):
    return struct.pack("<Bq4dd", 0, stamp, *z, f)


def record_perturb(what, extra=b""):
    return struct.pack("<BB", 2, what) + extra


def stream(model, records):
    return bytes([model]) + b"".join(records)


def sample_streams():
    rotation = [record_plausible(25) for _ in range(200)]
    yield "rotation_nominal.bin", stream(0, rotation)
    yield "rotation_harmonics.bin", stream(1, rotation)
    yield "rotation_frequency.bin", stream(2, [record_plausible(-40, freq=50 + i % 100) for i in range(200)])
    glitches = []
    for i in range(100):
        glitches.append(record_plausible(10))
        if i % 10 == 5:
            glitches.append(record_perturb(0 | (i % 4)))       # sign flip
            glitches.append(record_perturb(4 | ((i + 1) % 4)))  # zero channel
    yield "glitches.bin", stream(1, glitches)
    gaps = []
    for i in range(60):
        gaps.append(record_plausible(5, dt_us=1000 if i % 20 else 65000))
        if i % 15 == 7:
            gaps.append(record_perturb(12, struct.pack("<I", 500000)))      # stamp back 0.5 ms
            gaps.append(record_perturb(16, struct.pack("<I", 200000)))   # forward 0.2 s
    yield "gaps_and_order.bin", stream(2, gaps)
    nan = float("nan")
    inf = float("inf")
    raw = [record_plausible(3) for _ in range(20)]
    raw += [record_raw(0, (1, 0, 0, 0), 5000.0), record_raw(2_000_000_000, (nan, 0, 0, 0), nan),
            record_raw(2_000_100_000, (inf, -inf, 0, 0), inf), record_raw(2_000_200_000, (0, 0, 0, 0), 5000.0),
            record_raw(2_000_300_000, (1e300, 1e300, 1e300, 1e300), 5000.0),
            record_raw(2_000_400_000, (0.5, 0.49, 0.0, 0.0), 5000.0)]
    raw += [record_plausible(3) for _ in range(20)]
    yield "non_finite.bin", stream(1, raw)
    swaps = []
    for i in range(120):
        swaps.append(record_plausible(30))
        if i % 30 == 10:
            swaps.append(struct.pack("<BB", 3, i // 30))  # reload another model
        if i % 50 == 49:
            swaps.append(bytes([4]))  # reset
    yield "reload_and_reset.bin", stream(1, swaps)
    back = [record_plausible(20) for _ in range(30)]
    back.append(record_raw(1_000_000, (0.8, 0.01, 0.3, 0.0), 5000.0))  # bag loop: far back
    back += [record_plausible(20) for _ in range(30)]
    yield "bag_loop.bin", stream(0, back)


def main():
    for name, text in PARAMETER_FILES.items():
        with open(os.path.join(HERE, "corpus", "parameter_file", name), "w") as f:
            f.write(text)
    for name, data in sample_streams():
        with open(os.path.join(HERE, "corpus", "sample_processing", name), "wb") as f:
            f.write(data)


if __name__ == "__main__":
    main()
