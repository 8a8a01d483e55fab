// Road surfaces beyond a plane (docs/roads.md): a height z(x, y) over the x, y plane of the road
// body's frame, with its first and second derivatives, and a friction scale(x, y) per region.
//   grid     a regular grid of heights, bicubic Catmull-Rom (C1: height and gradient continuous
//            across cell edges; quadratics in x and y reproduced exactly in interior cells)
//   tracks   one or two longitudinal profiles z(s), s along x, each a cubic Catmull-Rom of a regular
//            sampling; between two tracks the cross-section is the straight line through their
//            heights (extrapolated beyond them), so a wheel on a track sees exactly its profile
//   iso8608  generated tracks of an ISO 8608 class (iso8608_tracks below)
// Outside the sampled range the height is held at the edge (the clamped coordinate's slope is 0
// there). Pure numbers: no model, no dynamics (dynamics/tire_effect.hpp takes the tangent plane).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace codyna {

// the height at a point and its derivatives (road body coordinates)
struct RoadHeight {
  double z = 0, zx = 0, zy = 0, zxx = 0, zxy = 0, zyy = 0;
};

// a friction region: the box x_min <= x <= x_max, y_min <= y <= y_max scales the law's friction
struct RoadFrictionRegion {
  double x_min = -1e300, x_max = 1e300, y_min = -1e300, y_max = 1e300;
  double scale = 1.0;
};

struct RoadSurface {
  enum class Kind { Grid, Tracks };
  Kind kind = Kind::Grid;
  // grid: nodes x0 + i dx (i < nx), y0 + j dy (j < ny), heights z[j nx + i]
  double x0 = 0, y0 = 0, dx = 1, dy = 1;
  int nx = 0, ny = 0;
  std::vector<double> z;
  // tracks: samples at x0 + i dx (i < nx) of the left and right profiles (right empty: one track,
  // the height independent of y), the tracks at y = y_left, y_right (y_left > y_right)
  std::vector<double> left, right;
  double y_left = 0, y_right = 0;
  // friction regions: the last region holding the point gives its scale; outside all: 1
  std::vector<RoadFrictionRegion> friction;

  RoadHeight height(double x, double y) const;
  int region(double x, double y) const;  // index into friction, -1: none
  double friction_scale(double x, double y) const;
};

// A grid road from node coordinates (increasing, uniformly spaced to 1e-9 of the spacing, at least 2
// each) and heights z[j][i] at (x[i], y[j]). Throws std::invalid_argument("expected ...").
RoadSurface road_grid(const std::vector<double>& x, const std::vector<double>& y, const std::vector<std::vector<double>>& z);
// A tracks road from s (uniform, increasing, >= 2 samples) and one or two profiles.
RoadSurface road_tracks(const std::vector<double>& s, const std::vector<double>& left, const std::vector<double>& right,
                        double y_left, double y_right);

// CSV files (comma separated, '#' comment lines). Throw std::runtime_error naming the path and line.
//   grid:    first row "y\x", x0, x1, ...; then one row per y: y_j, z(x0, y_j), z(x1, y_j), ...
//   profile: a header row naming the columns s,z (one track) or s,left,right; then numbers
struct RoadTable {
  std::vector<double> x, y;                 // grid: the node coordinates; profile: x = s
  std::vector<std::vector<double>> z;       // grid: z[j][i]; profile: z[0] left (or the one track), z[1] right
};
RoadTable read_road_grid_csv(const std::string& path);
RoadTable read_road_profile_csv(const std::string& path);

// ISO 8608 (road surface profiles): the displacement PSD Gd(n) = Gd(n0) (n / n0)^-2, n0 = 0.1 cycle/m,
// Gd(n0) = 16e-6 m^3 for class A (0) and x4 per class up to H (7).
double iso8608_gd0(int road_class);
// the variance of the profile over the band [n1, n2] (cycle/m): Gd(n0) n0^2 (1/n1 - 1/n2)
double iso8608_band_variance(int road_class, double n1, double n2);
struct Iso8608Spec {
  int road_class = 2;                        // 0 = A ... 7 = H
  double length = 200;                       // m, the profile's period
  double n_min = 0.011, n_max = 2.83;        // cycle/m
  double spacing = 0.05;                     // m, the sampling (adjusted to divide the length)
  std::uint64_t seed = 1;
};
// Two independent tracks (left, right) sampled at s_i = i * length / N, i = 0..N: sums of cosines at
// the frequencies k / length in the band, each of amplitude sqrt(2 * integral of Gd over its share of
// the band), with phases uniform in [0, 2 pi) from mt19937_64 (its integers mapped to doubles here,
// not by <random>'s distributions, so the profile is the same on every machine). Track 0 takes the
// first draws, track 1 the next. Throws std::invalid_argument("expected ...").
std::vector<std::vector<double>> iso8608_tracks(const Iso8608Spec& spec);
// "A".."H" -> 0..7, -1 otherwise
int iso8608_class(const std::string& name);

}  // namespace codyna
