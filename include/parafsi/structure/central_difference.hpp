/// \file central_difference.hpp
/// Central-difference (leapfrog) update of the structure nodes (methods §8.1):
///   a^n = M⁻¹ (f_ext^n − f_int^n) + g,
///   v^{n+½} = [(1 − α Δt̄/2) v^{n−½} + Δt̄ a^n] / (1 + α Δt̄/2),   Δt̄ = ½(Δt^{n−1} + Δt^n)
///   x^{n+1} = x^n + Δt^n v^{n+½},
/// with gravity g as a body load (f = m g on free nodes), optional mass-proportional
/// ("dynamic relaxation") damping α ≥ 0 for bringing a structure to rest, and Δt^{-1} = 0
/// so the first step is the usual half kick from the initial velocities.
/// Constrained nodes (1/m = 0) keep their velocity; pinned ones stay put.
/// Stability: Δt ≤ TSSF · min(element and nodal estimates), TSSF = 0.9 (LS-DYNA's
/// default). `substeps(Δt_f, Δt_crit)` = ceil(Δt_f/Δt_crit) is the number of structure
/// substeps that fit one fluid step (methods §8.3).
///
/// References: Belytschko, Liu, Moran (2000) Nonlinear Finite Elements, §6.2;
///   LS-DYNA Theory Manual (time integration, TSSF); Underwood P. (1983) Dynamic
///   relaxation, in Computational Methods for Transient Analysis, North-Holland.
#pragma once
#include <cmath>
#include <vector>

#include <Eigen/Core>

#include "../core/error.hpp"
#include "../core/simd.hpp"
#include "detail/scatter.hpp"
#include "energy.hpp"
#include "nodes.hpp"

namespace parafsi::structure {

struct central_difference {
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};  ///< body load (m/s²)
  double mass_damping = 0.0;                 ///< α (1/s), 0 = none
  double tssf = 0.9;                         ///< time-step scale factor

  void validate() const {
    require(gravity.allFinite(), "central_difference: gravity must be finite");
    require(mass_damping >= 0 && std::isfinite(mass_damping), "central_difference: mass damping must be >= 0, got ",
            mass_damping);
    require(tssf > 0 && tssf <= 1, "central_difference: TSSF must be in (0, 1], got ", tssf);
  }

  /// Number of equal substeps of at most dt_crit in dt_outer.
  static long substeps(double dt_outer, double dt_crit) {
    require(dt_outer > 0 && std::isfinite(dt_outer), "central_difference::substeps: outer step must be > 0, got ",
            dt_outer);
    require(dt_crit > 0, "central_difference::substeps: critical step must be > 0, got ", dt_crit);
    if (!std::isfinite(dt_crit)) return 1;
    return std::max(1L, long(std::ceil(dt_outer / dt_crit * (1.0 - 1e-12))));
  }

  /// f = m g on free nodes, 0 elsewhere; damping/external parts cleared when tracking.
  template <bool Track>
  void clear_forces(nodes& nd) const {
    auto& s = nd.data();
    double* fx = s.get<field::fx>();
    double* fy = s.get<field::fy>();
    double* fz = s.get<field::fz>();
    const double* m = s.get<field::m>();
    const double* mi = s.get<field::minv>();
    double* fdx = s.get<field::fdx>();
    double* fdy = s.get<field::fdy>();
    double* fdz = s.get<field::fdz>();
    double* fex = s.get<field::fex>();
    double* fey = s.get<field::fey>();
    double* fez = s.get<field::fez>();
    const double gx = gravity.x(), gy = gravity.y(), gz = gravity.z();
    impl::for_each_chunk(nd.size(), [&](index_t b, index_t e, index_t) {
      simd::for_each_pack(b, e, [&](auto tag, index_t i) {
        using V = typename decltype(tag)::type;
        const V mg = simd::select(simd::load<V>(mi + i) > V(0.0), simd::load<V>(m + i), V(0.0));
        simd::store(fx + i, mg * V(gx));
        simd::store(fy + i, mg * V(gy));
        simd::store(fz + i, mg * V(gz));
        if constexpr (Track) {
          const V z(0.0);
          simd::store(fdx + i, z);
          simd::store(fdy + i, z);
          simd::store(fdz + i, z);
          simd::store(fex + i, z);
          simd::store(fey + i, z);
          simd::store(fez + i, z);
        }
      });
    });
  }

  struct update_result {
    double kinetic = 0, damping = 0, external = 0;  ///< K^{n+½}, ΔD, ΔW (tracked only)
    index_t bad_node = -1;                          ///< first node that went non-finite
  };

  /// Kick (Δt̄) and drift (Δt) of every node; returns the energy increments when tracking.
  template <bool Track>
  update_result update(nodes& nd, double dt_kick, double dt) {
    auto& s = nd.data();
    double* x = s.get<field::x>();
    double* y = s.get<field::y>();
    double* z = s.get<field::z>();
    double* vx = s.get<field::vx>();
    double* vy = s.get<field::vy>();
    double* vz = s.get<field::vz>();
    const double* fx = s.get<field::fx>();
    const double* fy = s.get<field::fy>();
    const double* fz = s.get<field::fz>();
    const double* fdx = s.get<field::fdx>();
    const double* fdy = s.get<field::fdy>();
    const double* fdz = s.get<field::fdz>();
    const double* fex = s.get<field::fex>();
    const double* fey = s.get<field::fey>();
    const double* fez = s.get<field::fez>();
    const double* m = s.get<field::m>();
    const double* mi = s.get<field::minv>();
    const index_t nc = impl::chunk_count(nd.size());
    part_k_.assign(std::size_t(nc), 0.0);
    part_d_.assign(std::size_t(nc), 0.0);
    part_w_.assign(std::size_t(nc), 0.0);
    bad_.assign(std::size_t(nc), 0);
    const double ha = 0.5 * mass_damping * dt_kick;
    const double gx = gravity.x(), gy = gravity.y(), gz = gravity.z();
    impl::for_each_chunk(nd.size(), [&](index_t b, index_t e, index_t c) {
      double k = 0, d = 0, w = 0;
      bool ok = true;
      simd::for_each_pack(b, e, [&](auto tag, index_t i) {
        using V = typename decltype(tag)::type;
        const V minv = simd::load<V>(mi + i);
        const auto is_free = minv > V(0.0);
        const V h = simd::select(is_free, V(ha), V(0.0));
        const V c1 = (V(1.0) - h) / (V(1.0) + h), c2 = V(dt_kick) / (V(1.0) + h);
        const V ux = simd::load<V>(vx + i), uy = simd::load<V>(vy + i), uz = simd::load<V>(vz + i);
        const V nx = c1 * ux + c2 * simd::load<V>(fx + i) * minv;
        const V ny = c1 * uy + c2 * simd::load<V>(fy + i) * minv;
        const V nz = c1 * uz + c2 * simd::load<V>(fz + i) * minv;
        simd::store(vx + i, nx);
        simd::store(vy + i, ny);
        simd::store(vz + i, nz);
        const V X = simd::load<V>(x + i) + V(dt) * nx, Y = simd::load<V>(y + i) + V(dt) * ny,
                Z = simd::load<V>(z + i) + V(dt) * nz;
        simd::store(x + i, X);
        simd::store(y + i, Y);
        simd::store(z + i, Z);
        ok = ok && simd::all_finite(X + Y + Z + nx + ny + nz);
        if constexpr (Track) {
          const V mm = simd::select(is_free, simd::load<V>(m + i), V(0.0));
          const V bx = V(0.5) * (ux + nx), by = V(0.5) * (uy + ny), bz = V(0.5) * (uz + nz);
          k += simd::hsum(V(0.5) * mm * (nx * nx + ny * ny + nz * nz));
          const V pd = V(mass_damping) * mm * (bx * bx + by * by + bz * bz) -
                       (simd::load<V>(fdx + i) * bx + simd::load<V>(fdy + i) * by + simd::load<V>(fdz + i) * bz);
          const V pw = (simd::load<V>(fex + i) + mm * V(gx)) * bx + (simd::load<V>(fey + i) + mm * V(gy)) * by +
                       (simd::load<V>(fez + i) + mm * V(gz)) * bz;
          d += simd::hsum(pd);  // all nodes: damping acts at constrained ones too
          w += simd::hsum(simd::select(is_free, pw, V(0.0)));
        }
      });
      part_k_[std::size_t(c)] = k;
      part_d_[std::size_t(c)] = d * dt_kick;
      part_w_[std::size_t(c)] = w * dt_kick;
      bad_[std::size_t(c)] = ok ? 0 : 1;
    });
    update_result r;
    for (index_t c = 0; c < nc; ++c)
      if (bad_[std::size_t(c)]) {
        for (index_t i = c * impl::chunk; i < std::min(nd.size(), (c + 1) * impl::chunk); ++i)
          if (!(std::isfinite(x[i]) && std::isfinite(y[i]) && std::isfinite(z[i]) && std::isfinite(vx[i]) &&
                std::isfinite(vy[i]) && std::isfinite(vz[i]))) {
            r.bad_node = i;
            break;
          }
        if (r.bad_node >= 0) break;
      }
    if constexpr (Track) {
      r.kinetic = impl::ordered_sum(part_k_);
      r.damping = impl::ordered_sum(part_d_);
      r.external = impl::ordered_sum(part_w_);
      // Prescribed-velocity nodes: the rig's work −f_int·v (gravity on them is not applied).
      for (index_t i : nd.constrained())
        if (nd.kind(i) == constraint::prescribed)
          r.external += dt_kick * ((fex[i] - fx[i]) * vx[i] + (fey[i] - fy[i]) * vy[i] + (fez[i] - fz[i]) * vz[i]);
    }
    return r;
  }

 private:
  std::vector<double> part_k_, part_d_, part_w_;
  std::vector<char> bad_;
};

}  // namespace parafsi::structure
