// The Earth's rate at a site: Omega (WGS-84), its ENU vector at a geodetic latitude, its vertical and
// horizontal parts, and the one rule a latitude is held to. Every part of the project that sees the
// Earth turn (the compensation's vertical rate, the calibrations' references, north-finding, the
// simulators) takes it from here, so the figure and its trigonometry are written once.
//
//   Omega_n = Omega (0, cos(lat), sin(lat)) in ENU (x East, y North, z Up), lat north positive;
//   vertical part Omega sin(lat) (a gyro along the local up sees it at rest), horizontal Omega cos(lat)
//   (what a gyrocompass measures, pointing North). No ROS.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace hrg_gyro {
namespace core {

/// Sidereal rotation rate of the Earth, rad/s (WGS-84).
constexpr double kEarthRotationRate = 7.2921150e-5;

/// The vertical part of the Earth's rate at a geodetic latitude (rad), rad/s: what a gyro with its axis
/// along the local up direction (REP-103 z up) sees at rest.
inline double verticalEarthRate(double latitude) { return kEarthRotationRate * std::sin(latitude); }
/// Omega cos(lat): the horizontal part, pointing North, rad/s.
inline double horizontalEarthRate(double latitude) { return kEarthRotationRate * std::cos(latitude); }
/// The Earth's rate in ENU at `latitude` (rad): (0, horizontal, vertical), rad/s.
Eigen::Vector3d earthRateEnu(double latitude);

/// Whether a latitude is one (finite, within [-pi/2, pi/2] rad).
bool validLatitude(double latitude);
/// What a setting or file says of a latitude that is not valid (validLatitude).
constexpr const char* kLatitudeRule = "must be given, in [-pi/2, pi/2] rad";

}  // namespace core
}  // namespace hrg_gyro
