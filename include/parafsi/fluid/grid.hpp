/// \file grid.hpp
/// Rectilinear hexahedral grid in box coordinates ξ: per-axis face coordinates, so
/// cells can be refined around a body ("local mesh encryption"); a uniform grid is
/// the special case of equal spacing. Cells are stored x-fastest with `ghosts` = 2
/// ghost layers on every side; cell (i, j, k), i ∈ [−2, n_x + 2), lives at
/// index(i, j, k) = (i + 2) + s_y (j + 2) + s_z (k + 2).
/// The grid itself never moves: the box pose (frame) maps ξ to inertial x = X_b + R_b ξ.
#pragma once
#include <array>
#include <cmath>
#include <vector>

#include "../core/error.hpp"
#include "../core/simd.hpp"

namespace parafsi::fluid {

/// Face coordinates of one axis (n + 1 strictly increasing values).
struct axis {
  std::vector<double> faces;

  index_t cells() const noexcept { return static_cast<index_t>(faces.size()) - 1; }
  double lo() const noexcept { return faces.front(); }
  double hi() const noexcept { return faces.back(); }

  /// n equal cells on [lo, hi].
  static axis uniform(index_t n, double lo, double hi) {
    require(n >= 1, "axis::uniform: need at least one cell, got ", n);
    require(hi > lo, "axis::uniform: need hi > lo, got [", lo, ", ", hi, "]");
    axis a;
    a.faces.resize(static_cast<std::size_t>(n) + 1);
    for (index_t i = 0; i <= n; ++i) a.faces[std::size_t(i)] = lo + (hi - lo) * double(i) / double(n);
    return a;
  }

  /// Cells of size h_fine on [a, b] (a ≤ b inside [lo, hi]), growing geometrically by
  /// `growth` per cell outside it until lo and hi are reached (the last cell on each
  /// side is merged so that the ends are exact).
  static axis refined(double lo, double hi, double a, double b, double h_fine, double growth) {
    require(hi > lo && a >= lo && b <= hi && b >= a, "axis::refined: need lo <= a <= b <= hi");
    require(h_fine > 0.0, "axis::refined: h_fine must be > 0, got ", h_fine);
    require(growth >= 1.0 && growth <= 2.0, "axis::refined: growth must be in [1, 2], got ", growth);
    std::vector<double> mid;
    const index_t nf = std::max<index_t>(1, static_cast<index_t>(std::ceil((b - a) / h_fine - 1e-9)));
    for (index_t i = 0; i <= nf; ++i) mid.push_back(a + (b - a) * double(i) / double(nf));
    const double h0 = (b - a) / double(nf);
    std::vector<double> left, right;
    auto grow = [&](double start, double end, double dir, std::vector<double>& out) {
      double x = start, h = h0;
      while (dir * (end - x) > 1e-12) {
        h *= growth;
        double nx = x + dir * h;
        if (dir * (end - nx) < 0.5 * h) nx = end;  // merge a short last cell
        out.push_back(nx);
        x = nx;
      }
    };
    grow(a, lo, -1.0, left);
    grow(b, hi, +1.0, right);
    axis ax;
    for (auto it = left.rbegin(); it != left.rend(); ++it) ax.faces.push_back(*it);
    for (double x : mid) ax.faces.push_back(x);
    for (double x : right) ax.faces.push_back(x);
    return ax;
  }
};

class rectilinear_grid {
 public:
  static constexpr index_t ghosts = 2;

  rectilinear_grid() = default;
  rectilinear_grid(axis x, axis y, axis z) : axes_{std::move(x), std::move(y), std::move(z)} {
    for (int d = 0; d < 3; ++d) {
      const auto& f = axes_[d].faces;
      require(f.size() >= 2, "rectilinear_grid: axis ", d, " needs at least one cell");
      for (std::size_t i = 1; i < f.size(); ++i)
        require(f[i] > f[i - 1], "rectilinear_grid: axis ", d, " faces not increasing at face ", i, " (", f[i - 1],
                " >= ", f[i], ")");
      n_[d] = axes_[d].cells();
      build_axis(d);
    }
    sy_ = n_[0] + 2 * ghosts;
    sz_ = sy_ * (n_[1] + 2 * ghosts);
    total_ = sz_ * (n_[2] + 2 * ghosts);
  }

  /// Uniform box [lo, hi] with n cells per axis.
  static rectilinear_grid uniform(std::array<index_t, 3> n, std::array<double, 3> lo, std::array<double, 3> hi) {
    return {axis::uniform(n[0], lo[0], hi[0]), axis::uniform(n[1], lo[1], hi[1]), axis::uniform(n[2], lo[2], hi[2])};
  }

  index_t n(int d) const noexcept { return n_[d]; }
  index_t interior_cells() const noexcept { return n_[0] * n_[1] * n_[2]; }
  index_t total_cells() const noexcept { return total_; }
  index_t stride(int d) const noexcept { return d == 0 ? 1 : (d == 1 ? sy_ : sz_); }
  index_t index(index_t i, index_t j, index_t k) const noexcept {
    return (i + ghosts) + sy_ * (j + ghosts) + sz_ * (k + ghosts);
  }
  /// Axis indices (i, j, k) of the cell at flat index c (the inverse of index()).
  std::array<index_t, 3> ijk(index_t c) const noexcept {
    return {c % sy_ - ghosts, (c % sz_) / sy_ - ghosts, c / sz_ - ghosts};
  }
  const axis& axis_of(int d) const noexcept { return axes_[d]; }

  // Per-axis arrays indexed by cell index + ghosts (i.e. position 0 is cell −2).
  /// Cell centre along axis d.
  double centre(int d, index_t i) const noexcept { return xc_[d][std::size_t(i + ghosts)]; }
  double width(int d, index_t i) const noexcept { return dx_[d][std::size_t(i + ghosts)]; }
  double face(int d, index_t i) const noexcept { return axes_[d].faces[std::size_t(i)]; }
  const double* centres(int d) const noexcept { return xc_[d].data() + ghosts; }
  const double* widths(int d) const noexcept { return dx_[d].data() + ghosts; }
  const double* inv_widths(int d) const noexcept { return idx_[d].data() + ghosts; }
  const double* half_widths(int d) const noexcept { return hdx_[d].data() + ghosts; }
  /// 1 / (x_c[i] − x_c[i−1]) (distance between the centres left of and at cell i).
  const double* inv_centre_gaps(int d) const noexcept { return idc_[d].data() + ghosts; }
  double cell_volume(index_t i, index_t j, index_t k) const noexcept { return width(0, i) * width(1, j) * width(2, k); }
  /// Volume of the cell at flat index c.
  double cell_volume(index_t c) const noexcept {
    const auto q = ijk(c);
    return cell_volume(q[0], q[1], q[2]);
  }
  double min_width() const noexcept {
    double h = 1e300;
    for (int d = 0; d < 3; ++d)
      for (index_t i = 0; i < n_[d]; ++i) h = std::min(h, width(d, i));
    return h;
  }

 private:
  void build_axis(int d) {
    const auto& f = axes_[d].faces;
    const index_t n = n_[d];
    const std::size_t m = std::size_t(n + 2 * ghosts) + simd::width + 1;
    xc_[d].assign(m, 0.0);
    dx_[d].assign(m, 1.0);
    // Ghost cells mirror the boundary cells' widths.
    for (index_t i = -ghosts; i < n + ghosts + index_t(simd::width) + 1; ++i) {
      index_t src = i < 0 ? -1 - i : (i >= n ? 2 * n - 1 - i : i);
      src = std::clamp<index_t>(src, 0, n - 1);
      dx_[d][std::size_t(i + ghosts)] = f[std::size_t(src) + 1] - f[std::size_t(src)];
    }
    // Centres: walk outwards from the interior.
    for (index_t i = 0; i < n; ++i) xc_[d][std::size_t(i + ghosts)] = 0.5 * (f[std::size_t(i)] + f[std::size_t(i) + 1]);
    for (index_t i = -1; i >= -ghosts; --i)
      xc_[d][std::size_t(i + ghosts)] = xc_[d][std::size_t(i + 1 + ghosts)] -
                                        0.5 * (dx_[d][std::size_t(i + ghosts)] + dx_[d][std::size_t(i + 1 + ghosts)]);
    for (index_t i = n; i < n + ghosts + index_t(simd::width) + 1; ++i)
      xc_[d][std::size_t(i + ghosts)] = xc_[d][std::size_t(i - 1 + ghosts)] +
                                        0.5 * (dx_[d][std::size_t(i + ghosts)] + dx_[d][std::size_t(i - 1 + ghosts)]);
    idx_[d].resize(m);
    hdx_[d].resize(m);
    idc_[d].resize(m);
    for (std::size_t i = 0; i < m; ++i) {
      idx_[d][i] = 1.0 / dx_[d][i];
      hdx_[d][i] = 0.5 * dx_[d][i];
      idc_[d][i] = i == 0 ? 1.0 / dx_[d][0] : 1.0 / (xc_[d][i] - xc_[d][i - 1]);
    }
  }

  std::array<axis, 3> axes_{};
  std::array<index_t, 3> n_{};
  index_t sy_ = 0, sz_ = 0, total_ = 0;
  std::array<std::vector<double>, 3> xc_, dx_, idx_, hdx_, idc_;
};

}  // namespace parafsi::fluid
