#!/usr/bin/env python3
"""An independent generator of triad calibration sessions on a single-axis rate table, written without
the package's simulator (as test/independent_session.py is for one gyro), so that the triad simulator
and the triad calibration cannot share one mistake of frames or signs. Its model, stated here from
docs/simulation.md ("A triad on a rate table") and written out with numpy:

  Frames. Table zero: Earth-fixed, z up, x at `azimuth` from North towards East; the Earth's rate there
  is W (cos(lat) cos(az), cos(lat) sin(az), sin(lat)). The platter (the table frame) is the table zero
  turned by the table angle phi about z (counter-clockwise seen from above).
  Positions. body_to_table R: `up` +-a puts body axis a along +-z, the next body axis (x -> y -> z -> x)
  along the platter's x and the last along +-y. Between positions the fixture is unclamped for `move`
  s, the table at rest, and the body turns about the fixed axis rho = log(R_prev^T R_next) (body frame)
  by s(u) rho, s(u) = u - sin(2 pi u) / (2 pi), u the elapsed fraction of the move.
  Body rate. omega_body = R^T (phidot e_z + Rz(phi)^T omega_E0) + sdot rho.
  Axes. A = I + misalignments off the diagonal (row i: axis i's sensitive direction, [A_xy, A_xz],
  [A_yx, A_yz], [A_zx, A_zy]) and residual scales on it; axis i integrates (RK4)
      d theta_i/dt = K_i(theta_i) A_i . omega_body + D_i(theta_i)
  with harmonic K_i and D_i, and its channels are those of an ideal pickoff (the closed form below) for
  a wave of amplitude A, quadrature B and phase tau at theta_i, plus white noise.
  Table. Each position: a rest, then +rate and -rate plateaus (ramps at a fixed acceleration), then
  rest; the table controller logs the angle (encoder noise, counts) and the drive's rate at its own
  rate, header.seq its record count.
  Fixture. hrg_gyro/FixturePosition with the sample at every change of position or lock and every
  second: index, name, nominal body_to_table, locked (false during a move, index the position moved
  into).

Channel model (the standing wave r = A cos(2 phi - theta) cos(wt + tau) + B sin(2 phi - theta) sin(wt + tau)):
    Ac =  A cos th cos tau - B sin th sin tau      Bc = -A cos th sin tau - B sin th cos tau
    As =  A sin th cos tau + B cos th sin tau      Bs = -A sin th sin tau + B cos th cos tau

It writes a bag with /<axis>/channels (hrg_gyro/ChannelAmplitudes, the three axes at the same stamps,
header.seq the sample index, frame_id the axis name), /turntable/state (hrg_gyro/TurntableState) and
/fixture/position (hrg_gyro/FixturePosition, frame_id the body frame), no truth topics, and a YAML
file with what it injected: A and M = A^-1, each axis's K, D and initial theta, the Earth's rate, the
positions (orientation, times, plateau rates) and the session's settings.

Usage: independent_triad.py --out BAG --truth YAML [--rate 0.4] [--rest 20] [--move 10] [--latitude 0.9]
       [--azimuth 0.3] [--misalignment AXY AXZ AYX AYZ AZX AZY] [--scale SX SY SZ]
       [--positions +z,-z,+x,-x,+y,-y] [--encoder-noise 2e-6] [--encoder-bits 23] [--seed 1]
"""
import argparse
import math
import sys

import numpy as np
import rosbag
import rospy
import yaml
from hrg_gyro.msg import ChannelAmplitudes, FixturePosition, TurntableState

EARTH_RATE = 7.2921150e-5  # rad/s
AXES = ("x", "y", "z")


class Harmonic:
    """mean + sum_k c_k cos(k theta) + s_k sin(k theta), even k (the parameter file's form)."""

    def __init__(self, mean, terms):
        self.mean, self.terms = mean, terms  # terms: [(order, cos, sin), ...]

    def __call__(self, theta):
        v = self.mean
        for order, c, s in self.terms:
            v += c * math.cos(order * theta) + s * math.sin(order * theta)
        return v

    def as_dict(self):
        return {"mean": self.mean, "orders": [o for o, _, _ in self.terms],
                "cos": [c for _, c, _ in self.terms], "sin": [s for _, _, s in self.terms]}


# Each axis its own gyro: K0 near -0.56, a little anisotropy, a bias with a 2 theta term.
GYROS = [
    (Harmonic(-0.56, [(2, -2.0e-4, 1.5e-4), (4, 1.0e-4, 0.0)]), Harmonic(1.0e-5, [(2, 2.0e-5, -1.0e-5)]), 0.2),
    (Harmonic(-0.5612, [(2, -1.8e-4, 1.3e-4), (4, 1.1e-4, 0.0)]), Harmonic(1.2e-5, [(2, 1.7e-5, -0.8e-5)]), 1.0),
    (Harmonic(-0.5589, [(2, -2.3e-4, 1.7e-4), (4, 0.9e-4, 0.0)]), Harmonic(0.8e-5, [(2, 2.2e-5, -1.2e-5)]), 2.1),
]


def up_rotation(up):
    """body_to_table of an `up` position, its columns the body axes in the table frame."""
    if len(up) != 2 or up[0] not in "+-" or up[1] not in AXES:
        raise ValueError("a position is one of +x, -x, +y, -y, +z, -z, not %r" % up)
    sign = 1.0 if up[0] == "+" else -1.0
    a = AXES.index(up[1])
    r = np.zeros((3, 3))
    r[:, a] = [0.0, 0.0, sign]
    r[:, (a + 1) % 3] = [1.0, 0.0, 0.0]
    r[:, (a + 2) % 3] = [0.0, sign, 0.0]
    return r


def skew(v):
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def rodrigues(rotation_vector):
    angle = np.linalg.norm(rotation_vector)
    if angle == 0.0:
        return np.eye(3)
    k = skew(rotation_vector / angle)
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * k @ k


def log_rotation(r):
    """The rotation vector of r (angle in [0, pi]); at a half turn, the axis from r + I."""
    angle = math.acos(max(-1.0, min(1.0, (np.trace(r) - 1.0) / 2.0)))
    if angle < 1e-12:
        return np.zeros(3)
    if math.pi - angle < 1e-9:
        s = r + np.eye(3)
        axis = s[:, np.argmax(np.linalg.norm(s, axis=0))]
        return angle * axis / np.linalg.norm(axis)
    w = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]) / (2.0 * math.sin(angle))
    return angle * w


def quaternion(r):
    """(w, x, y, z) of a rotation matrix, w >= 0."""
    w = math.sqrt(max(0.0, 1.0 + np.trace(r))) / 2.0
    if w > 1e-6:
        q = np.array([w, (r[2, 1] - r[1, 2]) / (4 * w), (r[0, 2] - r[2, 0]) / (4 * w), (r[1, 0] - r[0, 1]) / (4 * w)])
    else:  # a half turn: the axis from the diagonal
        axis = log_rotation(r) / math.pi
        q = np.array([0.0, axis[0], axis[1], axis[2]])
    return q / np.linalg.norm(q)


class Table:
    """The table's commanded rate, piecewise linear: holds and ramps at a fixed acceleration."""

    def __init__(self, acceleration):
        self.acceleration = acceleration
        self.pieces = []  # (start, duration, rate0, accel, angle0)
        self.end = 0.0

    def final_rate(self):
        if not self.pieces:
            return 0.0
        _, duration, rate0, accel, _ = self.pieces[-1]
        return rate0 + accel * duration

    def _append(self, duration, rate0, accel):
        angle0 = 0.0
        if self.pieces:
            _, d, r, a, g = self.pieces[-1]
            angle0 = g + r * d + 0.5 * a * d * d
        self.pieces.append((self.end, duration, rate0, accel, angle0))
        self.end += duration

    def hold(self, rate, duration):
        now = self.final_rate()
        if now != rate:
            a = math.copysign(self.acceleration, rate - now)
            self._append((rate - now) / a, now, a)
        if duration > 0.0:
            self._append(duration, rate, 0.0)

    def state(self, t):
        """Angle and rate at the times t (array)."""
        starts = np.array([p[0] for p in self.pieces])
        k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.pieces) - 1)
        p = np.array(self.pieces)[k]
        tau = np.clip(t - p[:, 0], 0.0, p[:, 1])
        rate = p[:, 2] + p[:, 3] * tau
        angle = p[:, 4] + p[:, 2] * tau + 0.5 * p[:, 3] * tau * tau
        return angle, rate


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--truth", required=True, help="YAML with what was injected")
    parser.add_argument("--rate", type=float, default=0.4, help="plateau rates +-rate, rad/s")
    parser.add_argument("--rest", type=float, default=20.0, help="s at rest at the start of each position")
    parser.add_argument("--move", type=float, default=10.0, help="s to move the fixture between positions")
    parser.add_argument("--acceleration", type=float, default=0.5, help="drive acceleration limit, rad/s^2")
    parser.add_argument("--latitude", type=float, default=0.9, help="rad")
    parser.add_argument("--azimuth", type=float, default=0.3,
                        help="rad: the platter's x axis at table angle 0, from North towards East")
    parser.add_argument("--misalignment", type=float, nargs=6,
                        default=[1.2e-4, -0.8e-4, 0.5e-4, 2.1e-4, -1.6e-4, 0.9e-4],
                        metavar=("AXY", "AXZ", "AYX", "AYZ", "AZX", "AZY"), help="off-diagonal entries of A, rad")
    parser.add_argument("--scale", type=float, nargs=3, default=[0.0, 0.0, 0.0], metavar=("SX", "SY", "SZ"),
                        help="residual scales: A_ii = 1 + s_i")
    parser.add_argument("--positions", default="+z,-z,+x,-x,+y,-y", help="the fixture's sequence of up axes")
    parser.add_argument("--output-hz", type=float, default=200.0)
    parser.add_argument("--log-hz", type=float, default=100.0, help="turntable log rate, Hz")
    parser.add_argument("--channel-noise", type=float, default=5e-6, help="white noise per channel amplitude")
    parser.add_argument("--encoder-noise", type=float, default=0.0, help="rad, white, on the logged angle")
    parser.add_argument("--encoder-bits", type=int, default=0, help="counts per turn 2^bits; 0: not quantised")
    parser.add_argument("--frame-id", default="imu_link", help="the body frame")
    parser.add_argument("--seed", type=int, default=1)
    a = parser.parse_args(argv)
    try:
        ups = a.positions.split(",")
        rotations = [up_rotation(u) for u in ups]
    except ValueError as e:
        parser.error(str(e))
    if max(abs(m) for m in a.misalignment + a.scale) > 0.05:
        parser.error("misalignments and scales are small: at most 0.05")

    body_to_axis = np.eye(3)
    off = iter(a.misalignment)
    for i in range(3):
        body_to_axis[i, i] = 1.0 + a.scale[i]
        for j in range(3):
            if j != i:
                body_to_axis[i, j] = next(off)
    lat, az = a.latitude, a.azimuth
    earth0 = EARTH_RATE * np.array([math.cos(lat) * math.cos(az), math.cos(lat) * math.sin(az), math.sin(lat)])

    # The session: per position a rest, +rate, -rate (each sweeping the slowest axis's theta by 2 pi
    # after a 3 s settle), back to rest; the moves between positions with the table at rest.
    table = Table(a.acceleration)
    plateau = 3.0 + 2.0 * math.pi / (min(abs(g[0].mean) for g in GYROS) * a.rate) + 2.0
    positions = []
    for k, (up, r) in enumerate(zip(ups, rotations)):
        move_start = table.end
        if k > 0:
            table.hold(0.0, a.move)
        start = table.end
        table.hold(0.0, a.rest)
        plateaus = []
        for sign in (1.0, -1.0):
            table.hold(sign * a.rate, 0.0)
            plateaus.append([table.end, table.end + plateau, sign * a.rate])
            table.hold(sign * a.rate, plateau)
        table.hold(0.0, 1.0)
        positions.append({"name": "%s %s" % (up[1], "up" if up[0] == "+" else "down"), "up": up, "r": r,
                          "move_start": move_start, "start": start, "end": table.end, "plateaus": plateaus})
    for k, p in enumerate(positions):
        p["rho"] = log_rotation(positions[k - 1]["r"].T @ p["r"]) if k > 0 else np.zeros(3)

    step = 1.0 / (2.0 * max(a.output_hz, a.log_hz))
    for hz in (a.output_hz, a.log_hz):
        if abs(1.0 / (hz * step) - round(1.0 / (hz * step))) > 1e-9:
            parser.error("a rate of %g Hz is not a whole number of %g s integration steps apart" % (hz, step))
    n = int(table.end / step)

    def body_rate(t):
        """omega_body (rows) at the times t, and the position index and lock of each."""
        angle, rate = table.state(t)
        c, s = np.cos(angle), np.sin(angle)
        platter = np.stack([c * earth0[0] + s * earth0[1], -s * earth0[0] + c * earth0[1],
                            np.full_like(t, earth0[2]) + rate], axis=1)
        index = np.clip(np.searchsorted([p["move_start"] for p in positions], t, side="right") - 1, 0,
                        len(positions) - 1)
        omega = np.empty_like(platter)
        locked = np.ones(len(t), dtype=bool)
        for k, p in enumerate(positions):
            here = index == k
            moving = here & (t < p["start"])
            still = here & ~moving
            omega[still] = platter[still] @ p["r"]  # R^T v, row by row
            locked[moving] = False
            if np.any(moving):
                u = (t[moving] - p["move_start"]) / a.move
                s_u = u - np.sin(2 * math.pi * u) / (2 * math.pi)
                sdot = (1.0 - np.cos(2 * math.pi * u)) / a.move
                previous = positions[k - 1]["r"]
                for j, sj, dj in zip(np.flatnonzero(moving), s_u, sdot):
                    r_t = previous @ rodrigues(sj * p["rho"])
                    omega[j] = r_t.T @ platter[j] + dj * p["rho"]
        return omega, index, locked

    times = np.arange(n + 1) * step
    omega_grid, index_grid, locked_grid = body_rate(times)
    omega_half, _, _ = body_rate(times[:-1] + step / 2)
    rates_grid = omega_grid @ body_to_axis.T  # column i: A_i . omega_body
    rates_half = omega_half @ body_to_axis.T

    theta = np.empty((n + 1, 3))
    for i, (k_model, d_model, theta0) in enumerate(GYROS):
        r_full, r_mid = rates_grid[:, i].tolist(), rates_half[:, i].tolist()
        th = theta0
        for j in range(n + 1):
            theta[j, i] = th
            if j == n:
                break
            r0, rm, r1 = r_full[j], r_mid[j], r_full[j + 1]
            k1 = k_model(th) * r0 + d_model(th)
            k2 = k_model(th + step / 2 * k1) * rm + d_model(th + step / 2 * k1)
            k3 = k_model(th + step / 2 * k2) * rm + d_model(th + step / 2 * k2)
            k4 = k_model(th + step * k3) * r1 + d_model(th + step * k3)
            th += step / 6 * (k1 + 2 * k2 + 2 * k3 + k4)

    rng = np.random.default_rng(a.seed)
    start_time = 1.0  # s: ROS time 0 means unset
    amplitude, quadrature, tau = 1.0, 0.02, 0.3
    out_every = int(round(1.0 / (a.output_hz * step)))
    log_every = int(round(1.0 / (a.log_hz * step)))
    idx = np.arange(0, n + 1, out_every)
    with rosbag.Bag(a.out, "w") as bag:
        channels = []
        for i in range(3):
            th = theta[idx, i]
            noise = a.channel_noise * rng.standard_normal((len(idx), 4))
            ct, st, ctau, stau = np.cos(th), np.sin(th), math.cos(tau), math.sin(tau)
            channels.append(np.stack([amplitude * ct * ctau - quadrature * st * stau,
                                      -amplitude * ct * stau - quadrature * st * ctau,
                                      amplitude * st * ctau + quadrature * ct * stau,
                                      -amplitude * st * stau + quadrature * ct * ctau], axis=1) + noise)
        lidx = np.arange(0, n + 1, log_every)
        angle, rate = table.state(times[lidx])
        logged = angle + a.encoder_noise * rng.standard_normal(len(lidx))
        if a.encoder_bits > 0:
            resolution = 2.0 * math.pi / 2 ** a.encoder_bits
            logged = resolution * np.round(logged / resolution)
        records = iter(enumerate(lidx))
        pending = next(records, None)
        last_fixture = None
        for j, g in enumerate(idx):
            stamp = rospy.Time.from_sec(start_time + times[g])
            for i in range(3):
                m = ChannelAmplitudes()
                m.header.seq = j
                m.header.stamp = stamp
                m.header.frame_id = AXES[i]
                m.c_in, m.c_quad, m.s_in, m.s_quad = channels[i][j]
                m.frequency, m.temperature, m.periods = 5000.0, float("nan"), 25
                bag.write("/%s/channels" % AXES[i], m, stamp)
            while pending is not None and pending[1] <= g:
                k, l = pending
                m = TurntableState()
                m.header.seq = k  # the controller's record count
                m.header.stamp = rospy.Time.from_sec(start_time + times[l])
                m.header.frame_id = a.frame_id
                m.angle, m.rate = logged[k], rate[k]
                bag.write("/turntable/state", m, m.header.stamp)
                pending = next(records, None)
            state = (int(index_grid[g]), bool(locked_grid[g]))
            due = last_fixture is not None and times[g] - last_fixture[1] >= 1.0 - 0.5 / a.output_hz
            if last_fixture is None or state != last_fixture[0] or due:
                p = positions[state[0]]
                m = FixturePosition()
                m.header.seq = j
                m.header.stamp = stamp
                m.header.frame_id = a.frame_id
                m.index, m.name, m.locked = state[0], p["name"], state[1]
                q = quaternion(p["r"])
                m.body_to_table.w, m.body_to_table.x, m.body_to_table.y, m.body_to_table.z = q
                bag.write("/fixture/position", m, stamp)
                last_fixture = (state, times[g])

    truth = {
        "frame_id": a.frame_id,
        "axes": list(AXES),
        "body_to_axis": body_to_axis.tolist(),
        "axis_to_body": np.linalg.inv(body_to_axis).tolist(),
        "misalignment": {AXES[i]: [float(body_to_axis[i, j]) for j in range(3) if j != i] for i in range(3)},
        "scale": {AXES[i]: a.scale[i] for i in range(3)},
        "gyros": {AXES[i]: {"scale_factor": g[0].as_dict(), "drift": g[1].as_dict(), "initial_theta": g[2]}
                  for i, g in enumerate(GYROS)},
        "latitude": lat, "azimuth": az, "earth_rate_table_zero": earth0.tolist(),
        "positions": [{"name": p["name"], "up": p["up"], "body_to_table": p["r"].tolist(),
                       "move_start": float(p["move_start"]), "start": float(p["start"]), "end": float(p["end"]),
                       "plateaus": p["plateaus"]} for p in positions],
        "session_seconds": float(times[n]), "start_time": start_time, "output_hz": a.output_hz, "log_hz": a.log_hz,
        "rate": a.rate, "rest": a.rest, "move": a.move,
        "channel_noise": a.channel_noise, "wave": {"amplitude": amplitude, "quadrature": quadrature, "phase": tau},
    }
    with open(a.truth, "w") as f:
        yaml.safe_dump(truth, f)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
