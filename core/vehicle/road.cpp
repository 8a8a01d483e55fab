#include "vehicle/road.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>

namespace codyna {
namespace {

// Catmull-Rom weights of the points at offsets -1, 0, 1, 2 for t in [0, 1], and their first and
// second derivatives in t
struct RoadWeights {
  double w[4], d[4], dd[4];
};

RoadWeights road_weights(double t) {
  const double t2 = t * t, t3 = t2 * t;
  RoadWeights r;
  r.w[0] = 0.5 * (-t3 + 2 * t2 - t);
  r.w[1] = 0.5 * (3 * t3 - 5 * t2 + 2);
  r.w[2] = 0.5 * (-3 * t3 + 4 * t2 + t);
  r.w[3] = 0.5 * (t3 - t2);
  r.d[0] = 0.5 * (-3 * t2 + 4 * t - 1);
  r.d[1] = 0.5 * (9 * t2 - 10 * t);
  r.d[2] = 0.5 * (-9 * t2 + 8 * t + 1);
  r.d[3] = 0.5 * (3 * t2 - 2 * t);
  r.dd[0] = 0.5 * (-6 * t + 4);
  r.dd[1] = 0.5 * (18 * t - 10);
  r.dd[2] = 0.5 * (-18 * t + 8);
  r.dd[3] = 0.5 * (6 * t - 2);
  return r;
}

// the cell of u = (x - x0) / dx among n nodes: index i in [0, n - 2], t in [0, 1]; held at the ends
// (clamped: true, the slope across the edge 0)
struct RoadCell {
  int i = 0;
  double t = 0;
  bool clamped = false;
};

RoadCell road_cell(double x, double x0, double dx, int n) {
  RoadCell c;
  double u = (x - x0) / dx;
  if (std::isnan(u)) u = 0;  // a failed state: the first cell, never an undefined cast to int
  if (u <= 0) {
    c.clamped = u < 0;
    u = 0;
  } else if (u >= n - 1) {
    c.clamped = u > n - 1;
    u = n - 1;
  }
  c.i = std::min(static_cast<int>(std::floor(u)), n - 2);
  c.t = u - c.i;
  return c;
}

// a sampled value with ghost points beyond the ends extrapolated linearly (one-sided tangents)
double road_sample(const std::vector<double>& v, int i) {
  const int n = static_cast<int>(v.size());
  if (i < 0) return 2 * v[0] - v[1];
  if (i >= n) return 2 * v[static_cast<std::size_t>(n - 1)] - v[static_cast<std::size_t>(n - 2)];
  return v[static_cast<std::size_t>(i)];
}

// one profile at x: value, first and second derivative in x
struct RoadProfilePoint {
  double z = 0, zx = 0, zxx = 0;
};

RoadProfilePoint road_profile_at(const std::vector<double>& v, double x, double x0, double dx) {
  const RoadCell c = road_cell(x, x0, dx, static_cast<int>(v.size()));
  const RoadWeights w = road_weights(c.t);
  RoadProfilePoint p;
  for (int a = 0; a < 4; ++a) {
    const double s = road_sample(v, c.i - 1 + a);
    p.z += w.w[a] * s;
    p.zx += w.d[a] * s;
    p.zxx += w.dd[a] * s;
  }
  if (c.clamped) p.zx = p.zxx = 0;
  p.zx /= dx;
  p.zxx /= dx * dx;
  return p;
}

void road_check_uniform(const std::vector<double>& x, const char* what) {
  if (x.size() < 2) throw std::invalid_argument(std::string("expected at least 2 ") + what + " values, got " + std::to_string(x.size()));
  for (double v : x)
    if (!std::isfinite(v)) throw std::invalid_argument(std::string("expected finite ") + what + " values");
  const double d = (x.back() - x.front()) / static_cast<double>(x.size() - 1);
  if (!(d > 0)) throw std::invalid_argument(std::string("expected increasing ") + what + " values");
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double expected = x.front() + d * static_cast<double>(i);
    if (std::abs(x[i] - expected) > 1e-9 * d)
      throw std::invalid_argument(std::string("expected uniformly spaced ") + what + " values (spacing " + std::to_string(d) +
                                  "), but value " + std::to_string(i) + " is " + std::to_string(x[i]) + " instead of " +
                                  std::to_string(expected));
  }
}

void road_check_finite(const std::vector<double>& z, const char* what) {
  for (double v : z)
    if (!std::isfinite(v)) throw std::invalid_argument(std::string("expected finite ") + what);
}

}  // namespace

RoadHeight RoadSurface::height(double x, double y) const {
  RoadHeight h;
  if (kind == Kind::Tracks) {
    const RoadProfilePoint l = road_profile_at(left, x, x0, dx);
    if (right.empty()) return {l.z, l.zx, 0, l.zxx, 0, 0};
    const RoadProfilePoint r = road_profile_at(right, x, x0, dx);
    const double w = y_left - y_right, t = (y - y_right) / w;
    h.z = r.z + t * (l.z - r.z);
    h.zx = r.zx + t * (l.zx - r.zx);
    h.zxx = r.zxx + t * (l.zxx - r.zxx);
    h.zy = (l.z - r.z) / w;
    h.zxy = (l.zx - r.zx) / w;
    return h;
  }
  const RoadCell cx = road_cell(x, x0, dx, nx), cy = road_cell(y, y0, dy, ny);
  const RoadWeights wx = road_weights(cx.t), wy = road_weights(cy.t);
  for (int b = 0; b < 4; ++b) {
    // the row of nodes at y index j (ghost rows extrapolated linearly from the two nearest)
    const int j = cy.i - 1 + b;
    const int j0 = std::clamp(j, 0, ny - 1);
    const int j1 = j < 0 ? 1 : j >= ny ? ny - 2 : j0;
    const double f0 = j == j0 ? 1.0 : 2.0, f1 = j == j0 ? 0.0 : -1.0;
    for (int a = 0; a < 4; ++a) {
      const int i = cx.i - 1 + a;
      const auto node = [&](int jj) {
        const int i0 = std::clamp(i, 0, nx - 1);
        const double* row = z.data() + static_cast<std::ptrdiff_t>(jj) * nx;
        if (i == i0) return row[i0];
        return i < 0 ? 2 * row[0] - row[1] : 2 * row[nx - 1] - row[nx - 2];
      };
      const double s = f0 * node(j0) + (f1 != 0 ? f1 * node(j1) : 0.0);
      h.z += wx.w[a] * wy.w[b] * s;
      h.zx += wx.d[a] * wy.w[b] * s;
      h.zy += wx.w[a] * wy.d[b] * s;
      h.zxx += wx.dd[a] * wy.w[b] * s;
      h.zxy += wx.d[a] * wy.d[b] * s;
      h.zyy += wx.w[a] * wy.dd[b] * s;
    }
  }
  if (cx.clamped) h.zx = h.zxx = h.zxy = 0;
  if (cy.clamped) h.zy = h.zyy = h.zxy = 0;
  h.zx /= dx;
  h.zy /= dy;
  h.zxx /= dx * dx;
  h.zyy /= dy * dy;
  h.zxy /= dx * dy;
  return h;
}

int RoadSurface::region(double x, double y) const {
  for (int k = static_cast<int>(friction.size()) - 1; k >= 0; --k) {
    const RoadFrictionRegion& r = friction[static_cast<std::size_t>(k)];
    if (x >= r.x_min && x <= r.x_max && y >= r.y_min && y <= r.y_max) return k;
  }
  return -1;
}

double RoadSurface::friction_scale(double x, double y) const {
  const int k = region(x, y);
  return k < 0 ? 1.0 : friction[static_cast<std::size_t>(k)].scale;
}

RoadSurface road_grid(const std::vector<double>& x, const std::vector<double>& y, const std::vector<std::vector<double>>& z) {
  road_check_uniform(x, "x");
  road_check_uniform(y, "y");
  if (z.size() != y.size())
    throw std::invalid_argument("expected " + std::to_string(y.size()) + " rows of heights (one per y), got " + std::to_string(z.size()));
  RoadSurface r;
  r.kind = RoadSurface::Kind::Grid;
  r.nx = static_cast<int>(x.size());
  r.ny = static_cast<int>(y.size());
  r.x0 = x.front();
  r.y0 = y.front();
  r.dx = (x.back() - x.front()) / (r.nx - 1);
  r.dy = (y.back() - y.front()) / (r.ny - 1);
  for (std::size_t j = 0; j < z.size(); ++j) {
    if (z[j].size() != x.size())
      throw std::invalid_argument("expected " + std::to_string(x.size()) + " heights (one per x) in row " + std::to_string(j) +
                                  ", got " + std::to_string(z[j].size()));
    r.z.insert(r.z.end(), z[j].begin(), z[j].end());
  }
  road_check_finite(r.z, "heights");
  return r;
}

RoadSurface road_tracks(const std::vector<double>& s, const std::vector<double>& left, const std::vector<double>& right,
                        double y_left, double y_right) {
  road_check_uniform(s, "s");
  if (left.size() != s.size() || (!right.empty() && right.size() != s.size()))
    throw std::invalid_argument("expected as many heights per track as s values (" + std::to_string(s.size()) + ")");
  road_check_finite(left, "heights");
  road_check_finite(right, "heights");
  if (!right.empty() && !(std::isfinite(y_left) && std::isfinite(y_right) && y_left > y_right))
    throw std::invalid_argument("expected the left track's y above the right track's");
  RoadSurface r;
  r.kind = RoadSurface::Kind::Tracks;
  r.nx = static_cast<int>(s.size());
  r.x0 = s.front();
  r.dx = (s.back() - s.front()) / (r.nx - 1);
  r.left = left;
  r.right = right;
  r.y_left = y_left;
  r.y_right = y_right;
  return r;
}

namespace {

// the cells of one CSV line (comma separated, blanks around cells ignored)
std::vector<std::string> road_csv_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) {
    const auto b = cell.find_first_not_of(" \t\r"), e = cell.find_last_not_of(" \t\r");
    cells.push_back(b == std::string::npos ? std::string() : cell.substr(b, e - b + 1));
  }
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

double road_csv_number(const std::string& cell, const std::string& path, int line, std::size_t column) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(cell, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != cell.size() || !std::isfinite(v))
    throw std::runtime_error(path + ": line " + std::to_string(line) + ", column " + std::to_string(column + 1) +
                             ": expected a number, got \"" + cell + "\"");
  return v;
}

// the non-comment lines of a CSV file as cells, with their line numbers
std::vector<std::pair<int, std::vector<std::string>>> road_csv_rows(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the file (missing?)");
  std::vector<std::pair<int, std::vector<std::string>>> rows;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto b = line.find_first_not_of(" \t\r");
    if (b == std::string::npos || line[b] == '#') continue;
    rows.emplace_back(number, road_csv_cells(line));
  }
  if (rows.size() < 3) throw std::runtime_error(path + ": expected a header row and at least 2 rows of numbers");
  return rows;
}

}  // namespace

RoadTable read_road_grid_csv(const std::string& path) {
  const auto rows = road_csv_rows(path);
  RoadTable t;
  const auto& [line0, header] = rows.front();
  if (header.size() < 3) throw std::runtime_error(path + ": line " + std::to_string(line0) + ": expected y\\x, x0, x1, ... (at least 2 x)");
  for (std::size_t c = 1; c < header.size(); ++c) t.x.push_back(road_csv_number(header[c], path, line0, c));
  for (std::size_t r = 1; r < rows.size(); ++r) {
    const auto& [line, cells] = rows[r];
    if (cells.size() != header.size())
      throw std::runtime_error(path + ": line " + std::to_string(line) + ": expected " + std::to_string(header.size()) +
                               " cells (y and one height per x), got " + std::to_string(cells.size()));
    t.y.push_back(road_csv_number(cells[0], path, line, 0));
    std::vector<double> z;
    for (std::size_t c = 1; c < cells.size(); ++c) z.push_back(road_csv_number(cells[c], path, line, c));
    t.z.push_back(std::move(z));
  }
  return t;
}

RoadTable read_road_profile_csv(const std::string& path) {
  const auto rows = road_csv_rows(path);
  const auto& [line0, header] = rows.front();
  if (header.size() != 2 && header.size() != 3)
    throw std::runtime_error(path + ": line " + std::to_string(line0) + ": expected the header s,z (one track) or s,left,right");
  RoadTable t;
  t.z.resize(header.size() - 1);
  for (std::size_t r = 1; r < rows.size(); ++r) {
    const auto& [line, cells] = rows[r];
    if (cells.size() != header.size())
      throw std::runtime_error(path + ": line " + std::to_string(line) + ": expected " + std::to_string(header.size()) +
                               " numbers like the header, got " + std::to_string(cells.size()));
    t.x.push_back(road_csv_number(cells[0], path, line, 0));
    for (std::size_t c = 1; c < cells.size(); ++c) t.z[c - 1].push_back(road_csv_number(cells[c], path, line, c));
  }
  return t;
}

double iso8608_gd0(int road_class) { return 16e-6 * std::pow(4.0, road_class); }

double iso8608_band_variance(int road_class, double n1, double n2) {
  const double n0 = 0.1;
  return iso8608_gd0(road_class) * n0 * n0 * (1.0 / n1 - 1.0 / n2);
}

int iso8608_class(const std::string& name) {
  if (name.size() != 1 || name[0] < 'A' || name[0] > 'H') return -1;
  return name[0] - 'A';
}

std::vector<std::vector<double>> iso8608_tracks(const Iso8608Spec& spec) {
  if (spec.road_class < 0 || spec.road_class > 7) throw std::invalid_argument("expected a class A to H");
  if (!(spec.length > 0) || !(spec.length <= 1e6)) throw std::invalid_argument("expected a length > 0 and at most 1e6 m");
  if (!(spec.n_min > 0) || !(spec.n_max > spec.n_min) || !std::isfinite(spec.n_max))
    throw std::invalid_argument("expected a band [n_min, n_max] with 0 < n_min < n_max (cycle/m)");
  if (!(spec.spacing > 0)) throw std::invalid_argument("expected a spacing > 0 (m)");
  const double L = spec.length;
  if (!(L / spec.spacing <= 2e7)) throw std::invalid_argument("expected at most 2e7 samples (length / spacing)");
  if (!(spec.n_max * L < 1e7)) throw std::invalid_argument("expected a spacing below 1 / (2 n_max) (Nyquist)");
  const long samples = std::max(2L, std::lround(std::ceil(L / spec.spacing)));
  const long k1 = std::max(1L, std::lround(std::ceil(spec.n_min * L))), k2 = std::lround(std::floor(spec.n_max * L));
  if (k2 < k1) throw std::invalid_argument("expected a band holding at least one frequency k / length");
  if (2 * k2 >= samples) throw std::invalid_argument("expected a spacing below 1 / (2 n_max) (Nyquist)");
  // the sum below costs (components x samples) cosines per track, about 1e8 a second: refused
  // beyond 1e9 in all (10 s) rather than left to run for hours (a 10 km road at the defaults)
  const double terms = 2.0 * static_cast<double>(k2 - k1 + 1) * static_cast<double>(samples + 1);
  if (terms > 1e9) {
    std::ostringstream os;
    os << "the road would sum " << (k2 - k1 + 1) << " cosines at " << samples + 1 << " points per track (" << terms
       << " terms); expected at most 1e9: a shorter length, a narrower band or a coarser spacing";
    throw std::invalid_argument(os.str());
  }
  std::mt19937_64 rng(spec.seed);
  const auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };  // [0, 1), 53 bits
  const double two_pi = 6.283185307179586476925286766559;
  std::vector<std::vector<double>> tracks(2, std::vector<double>(static_cast<std::size_t>(samples + 1), 0.0));
  for (std::vector<double>& z : tracks) {
    for (long k = k1; k <= k2; ++k) {
      const double n = static_cast<double>(k) / L;
      const double lo = std::max(spec.n_min, n - 0.5 / L), hi = std::min(spec.n_max, n + 0.5 / L);
      const double amplitude = std::sqrt(2.0 * iso8608_band_variance(spec.road_class, lo, hi));
      const double phase = two_pi * uniform();
      for (long i = 0; i <= samples; ++i) {
        // k i / samples reduced to [0, 1) keeps the argument small (exact periodicity)
        const double cycles = static_cast<double>((k * i) % samples) / static_cast<double>(samples);
        z[static_cast<std::size_t>(i)] += amplitude * std::cos(two_pi * cycles + phase);
      }
    }
  }
  return tracks;
}

}  // namespace codyna
