#!/usr/bin/env python3
"""hrg_bag import --imu as a navigation engineer runs it on a real log: the shipped excerpt of the
PSINS toolbox's ring-laser-gyro log (test/data/psins_lasergyro_excerpt.imu, 30 000 rows at 100 Hz)
imported with --format psins becomes 30 000 sensor_msgs/Imu in FLU, each value the one computed here
from the counts, bit for bit, and one NavSatFix of the header's site; the same file read with the
generic options instead of the preset gives the same messages; hrg_bag info validates the bag; bad
rows and options are refused as the bench logs' are. Needs no master."""
import math
import os
import shutil
import subprocess
import unittest

import rosbag
import rospy
import rostest

HRG_BAG = subprocess.check_output(["catkin_find", "--first-only", "--libexec", "hrg_gyro", "hrg_bag"],
                                  universal_newlines=True).strip()

EARTH_RATE = 7.292115e-5  # rad/s
ARCSEC = math.pi / 180.0 / 3600.0  # PSINS's glv.sec
EPOCH = 1395394311  # s: 2014-03-21, the log's date (its header line 2 gives t0 = 600 s for the excerpt)


def hrg_bag(*args, timeout=300):
    p = subprocess.run([HRG_BAG] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                       universal_newlines=True, timeout=timeout)
    return p.returncode, p.stdout, p.stderr


def psins_rows(path):
    """The header lines and the count rows of a PSINS file, read here without hrg_bag."""
    lines = [line for line in open(path) if line.strip() and not line.lstrip().startswith("%")]
    header = [[float(v) for v in line.split()] for line in lines[:3]]
    return header, [[int(v) for v in line.split()] for line in lines[3:]]


def expected_flu(header, row):
    """(omega, f) in FLU of one row: increment = count x scale (x 1e-6 g for ug*s), / the interval,
    then x right y forward z up to x forward y left z up."""
    dt = header[1][4] / 1000.0
    g = header[1][5]
    w = [row[i] * (header[2][i] * ARCSEC) / dt for i in range(3)]
    f = [row[3 + i] * (header[2][3 + i] * (1e-6 * g)) / dt for i in range(3)]
    return (w[1], -w[0], w[2]), (f[1], -f[0], f[2])


class HrgBagImportImu(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.work = os.path.join(rospy.get_param("~work_dir"), "hrg_bag_import_imu")
        shutil.rmtree(cls.work, ignore_errors=True)
        os.makedirs(cls.work)
        cls.log = os.path.join(rospy.get_param("~package_dir"), "test", "data", "psins_lasergyro_excerpt.imu")
        cls.header, cls.rows = psins_rows(cls.log)
        cls.bag = os.path.join(cls.work, "psins.bag")
        cls.code, _, cls.err = hrg_bag("import", "--imu", cls.log, "--format", "psins", "--epoch", str(EPOCH),
                                       "--out", cls.bag, "--quiet")

    def path(self, name):
        return os.path.join(self.work, name)

    def read(self, bag):
        with rosbag.Bag(bag) as b:
            topics = {t: (i.msg_type, i.message_count) for t, i in b.get_type_and_topic_info().topics.items()}
            imu = [(m, t) for _, m, t in b.read_messages(topics=["/imu/data_raw"])]
            fix = [(m, t) for _, m, t in b.read_messages(topics=["/fix"])]
        return topics, imu, fix

    def test_the_psins_excerpt_becomes_imu_messages_in_flu_and_one_fix(self):
        self.assertEqual(self.code, 0, self.err)
        self.assertEqual(len(self.rows), 30000)
        for fragment in ("gyro increments in arcsec x 0.1, accelerometer increments in ug*s x 125 (g = 9.780327 m/s^2)",
                         "axes RFU -> FLU", "initial attitude (unverified", "true heading 90.6000 deg",
                         "latitude 34.246048 deg = 0.5977062933960191 rad (put it in your gyrocompass settings'",
                         "30000 rows, stamps 1395394911.010000000 .. 1395395211.000000000 s (299.990 s, 100.000 Hz)",
                         "skipped 0", "one NavSatFix on /fix, frame imu_link"):
            self.assertIn(fragment, self.err)
        topics, imu, fix = self.read(self.bag)
        self.assertEqual(topics, {"/imu/data_raw": ("sensor_msgs/Imu", 30000), "/fix": ("sensor_msgs/NavSatFix", 1)})
        # The stamps: row n (from 1) closes epoch + t0 + n x 10 ms; the record time is the stamp.
        first_ns = (EPOCH + 600) * 10**9 + 10**7
        sum_w, sum_f = [0.0] * 3, [0.0] * 3
        for n, ((m, t), row) in enumerate(zip(imu, self.rows)):
            self.assertEqual(m.header.stamp.to_nsec(), first_ns + n * 10**7)
            self.assertEqual(t, m.header.stamp)
            self.assertEqual(m.header.seq, n)
            self.assertEqual(m.header.frame_id, "imu_link")
            w, f = expected_flu(self.header, row)
            self.assertEqual((m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z), w, n)
            self.assertEqual((m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z), f, n)
            # REP-145: no orientation; covariances unknown (0), the accelerometer measured.
            self.assertEqual(m.orientation_covariance[0], -1.0)
            self.assertEqual(list(m.angular_velocity_covariance), [0.0] * 9)
            self.assertEqual(list(m.linear_acceleration_covariance), [0.0] * 9)
            for i in range(3):
                sum_w[i] += w[i]
                sum_f[i] += f[i]
        (m, t), = fix
        self.assertEqual(m.header.stamp.to_nsec(), first_ns)
        self.assertEqual(t, m.header.stamp)
        self.assertEqual((m.latitude, m.longitude, m.altitude), (34.246048, 108.909664, 380.0))
        self.assertEqual(m.status.status, m.status.STATUS_FIX)
        self.assertEqual(m.position_covariance_type, m.COVARIANCE_TYPE_UNKNOWN)
        self.assertEqual(m.header.frame_id, "imu_link")
        # A still IMU: the Earth's rate and gravity, +g up (specific force), and the heading the mean
        # vectors give is the header's 90.6 deg to the base's rocking (90.75 deg here).
        w = [s / len(imu) for s in sum_w]
        f = [s / len(imu) for s in sum_f]
        norm_w, norm_f = math.sqrt(sum(x * x for x in w)), math.sqrt(sum(x * x for x in f))
        print("|mean omega| %.6e rad/s = %.4f Earth rates, |mean f| %.5f m/s^2" % (norm_w, norm_w / EARTH_RATE, norm_f))
        self.assertGreater(norm_w / EARTH_RATE, 0.99)
        self.assertLess(norm_w / EARTH_RATE, 1.0)
        self.assertAlmostEqual(norm_f, 9.7955, places=3)
        self.assertGreater(f[2], 9.7)
        def cross(a, b):
            return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

        up = [x / norm_f for x in f]
        east = cross(w, f)
        norm_e = math.sqrt(sum(x * x for x in east))
        east = [x / norm_e for x in east]
        north = cross(up, east)
        heading = math.degrees(math.atan2(east[0], north[0])) % 360.0  # of x, the forward axis
        print("heading of the forward axis from the mean vectors: %.3f deg" % heading)
        self.assertLess(abs(heading - 90.6), 0.5)

    def test_the_generic_options_read_the_same_file_to_the_same_messages(self):
        # The preset is only a shorthand: the layout, units, scales, interval, axes and site given one
        # by one (t0 = 600 s folded into the epoch) give the same bag content.
        out = self.path("generic.bag")
        code, _, err = hrg_bag("import", "--imu", self.log, "--out", out, "--quiet", "--comment", "%", "--skip-lines",
                               "3", "--no-header", "--delimiter", "whitespace",
                               "--column", "gx=#1", "gy=#2", "gz=#3", "ax=#4", "ay=#5", "az=#6",
                               "--gyro-unit", "arcsec", "--gyro-scale", "0.1", "--accel-unit", "ug*s",
                               "--accel-scale", "125,125,125", "--gravity", "9.780327", "--interval", "0.01",
                               "--frame", "RFU", "--epoch", str(EPOCH + 600), "--latitude", "34.246048",
                               "--longitude", "108.909664", "--height", "380")
        self.assertEqual(code, 0, err)
        _, imu_a, fix_a = self.read(self.bag)
        _, imu_b, fix_b = self.read(out)
        self.assertEqual(len(imu_b), 30000)
        self.assertEqual([(m.header, m.angular_velocity, m.linear_acceleration) for m, _ in imu_a],
                         [(m.header, m.angular_velocity, m.linear_acceleration) for m, _ in imu_b])
        self.assertEqual(fix_a[0][0], fix_b[0][0])
        # A frame given wins over the preset's: FLU leaves the log's x right as x.
        out = self.path("flu.bag")
        code, _, err = hrg_bag("import", "--imu", self.log, "--format", "psins", "--frame", "FLU", "--epoch",
                               str(EPOCH), "--out", out, "--quiet")
        self.assertEqual(code, 0, err)
        _, imu_c, _ = self.read(out)
        self.assertEqual(imu_c[0][0].angular_velocity.x, -imu_a[0][0].angular_velocity.y)

    def test_info_validates_the_imu_bag(self):
        self.assertEqual(self.code, 0, self.err)
        code, out, err = hrg_bag("info", self.bag)
        self.assertEqual(code, 0, out + err)
        self.assertIn("sensor_msgs/Imu", out)
        self.assertIn("(100.00 Hz)", out)
        self.assertIn("lost sequence numbers: 0", out)
        self.assertIn("OK: 0 error(s), 0 warning(s) (an IMU bag: no gyro channels)", out)

    def test_bad_rows_are_refused_with_line_and_column_or_skipped_and_counted(self):
        with open(self.log) as f:
            lines = f.readlines()
        # Lines 1-13 are comments and the blank line, 14-16 the header, 17 the first row: line 18 holds
        # row 1 (from 0), line 21 row 4.
        self.assertEqual(lines[16:18], ["-10 -9 3 0 4 80\n", "0 0 7 0 0 80\n"])
        lines[17] = "0 9x 7 0 0 80\n"
        lines[20] = "1 2 3 4 5\n"
        bad = self.path("bad.imu")
        with open(bad, "w") as f:
            f.writelines(lines)
        out = self.path("bad.bag")
        code, _, err = hrg_bag("import", "--imu", bad, "--format", "psins", "--out", out, "--quiet")
        self.assertEqual(code, 1, err)
        self.assertIn(bad + ":18: unreadable number: gy (#2): '9x' is not a number", err)
        self.assertIn("--skip-bad-rows skips and counts such rows", err)
        self.assertFalse(os.path.exists(out))
        code, _, err = hrg_bag("import", "--imu", bad, "--format", "psins", "--out", out, "--quiet", "--skip-bad-rows")
        self.assertEqual(code, 0, err)
        self.assertIn("29998 rows", err)
        self.assertIn("skipped 2 (wrong field count 1, unreadable number 1)", err)
        with rosbag.Bag(out) as b:
            seqs = [m.header.seq for _, m, _ in b.read_messages(topics=["/imu/data_raw"])]
        self.assertEqual(seqs[:6], [0, 2, 3, 5, 6, 7])  # a skipped row leaves a gap, its place in time kept

    def test_bad_usage_exits_2_naming_the_option(self):
        out = self.path("usage.bag")
        psins = ["--imu", self.log, "--format", "psins", "--out", out]
        cases = [
            (["--imu", self.log, "--channels", self.log, "--out", out], "--channels is for a bench's logs"),
            (["--channels", self.log, "--out", out, "--gyro-unit", "rad"], "--gyro-unit is for an IMU's log"),
            (psins + ["--delimiter", "comma"], "--format psins fixes the layout"),
            (psins + ["--frame", "RFU", "--rotation", "0,0,1"], "--frame and --rotation both give the log's axes"),
            (psins + ["--frame", "FBU"], "names the forward-back line twice"),
            (psins + ["--gyro-unit", "rpm"], "--gyro-unit"),
            (psins + ["--gyro-scale", "0.1,0.1"], "--gyro-scale expects one number or three"),
            (psins + ["--epoch", "1.5e9"], "--epoch"),
            (psins + ["--interval", "0"], "--interval"),
            (psins + ["--latitude", "95"], "latitude 95 deg is outside [-90, 90]"),
            (psins + ["--fix-topic", "/imu/data_raw"], "--imu-topic and --fix-topic are both /imu/data_raw"),
            (["--imu", self.log, "--format", "psins", "--out", self.log], "refused"),
            (["--imu", self.log, "--out", out, "--comment", "%", "--skip-lines", "3", "--no-header",
              "--column", "gx=#1", "gy=#2", "gz=#3"], "no time column: give the rows' spacing with --interval S"),
            (["--imu", self.log, "--out", out, "--comment", "%", "--skip-lines", "3", "--no-header",
              "--column", "gx=#1", "gy=#2", "ac=#3"], "unknown key 'ac' for --imu"),
            (["--imu", "/dev/null", "--format", "psins", "--out", out], "--imu: '/dev/null' is a character device"),
        ]
        for args, fragment in cases:
            code, _, err = hrg_bag("import", *args)
            self.assertEqual(code, 2, "%s -> %d\n%s" % (args, code, err))
            self.assertIn(fragment, err, args)
            self.assertNotIn("terminate called", err)
            self.assertFalse(os.path.exists(out), args)

    def test_a_log_from_t_0_needs_an_epoch_only_when_a_row_stands_at_0(self):
        log = self.path("rates.csv")
        with open(log, "w") as f:
            f.write("time,gx,gy,gz\n0.0,1e-5,2e-5,3e-5\n0.01,1e-5,2e-5,3e-5\n")
        out = self.path("rates.bag")
        code, _, err = hrg_bag("import", "--imu", log, "--out", out, "--quiet")
        self.assertEqual(code, 1, err)
        self.assertIn(log + ":2: stamp out of range: time 0.000000000 s + epoch 0.000000000 s", err)
        self.assertIn("pass --epoch S, the Unix time of the log's t = 0", err)
        code, _, err = hrg_bag("import", "--imu", log, "--out", out, "--quiet", "--epoch", "1700000000.5")
        self.assertEqual(code, 0, err)
        with rosbag.Bag(out) as b:
            msgs = [m for _, m, _ in b.read_messages()]
        self.assertEqual([m.header.stamp.to_nsec() for m in msgs], [1700000000500000000, 1700000000510000000])
        self.assertEqual(msgs[0].linear_acceleration_covariance[0], -1.0)  # no accelerometer columns
        self.assertEqual(msgs[0].angular_velocity.z, 3e-5)

    def test_a_large_log_is_streamed_in_flat_memory(self):
        # As the bench logs' import (hrg_bag_import.test): the peak of 2 M rows against that of 1000 plus
        # the bag writer's worst case and 2 MiB for the allocator (docs/importing_logs.md). Holding the
        # 2 M messages (about 330 bytes each) would take more than 600 MiB.
        peaks = {}
        for n in (1000, 2000000):
            log = self.path("large_%d.imu" % n)
            with open(log, "w") as f:
                f.write("".join(open(self.log).readlines()[:16]))
                f.writelines("%d -9 3 0 4 80\n" % (i % 20 - 10) for i in range(n))
            out = self.path("large_%d.bag" % n)
            report = self.path("time.txt")
            p = subprocess.run(["/usr/bin/time", "-f", "%M", "-o", report, HRG_BAG, "import", "--imu", log, "--format",
                                "psins", "--epoch", str(EPOCH), "--out", out, "--quiet"], stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, universal_newlines=True, timeout=600)
            self.assertEqual(p.returncode, 0, p.stderr)
            self.assertIn("%d rows" % n, p.stderr)
            with open(report) as f:
                peaks[n] = int(f.read().split()[-1])
            os.remove(log)
            os.remove(out)
        print("peak RSS: 1000 rows %d KiB, 2M rows %d KiB" % (peaks[1000], peaks[2000000]))
        self.assertLess(peaks[2000000], peaks[1000] + 26 * 1024, peaks)


if __name__ == "__main__":
    rospy.init_node("hrg_bag_import_imu_test")
    rostest.rosrun("hrg_gyro", "hrg_bag_import_imu", HrgBagImportImu)
