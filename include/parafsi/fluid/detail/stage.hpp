/// \file stage.hpp
/// Pieces every phase of the fluid step uses: the stage geometry of the box pose
/// (face normals n_d = R e_d, box-frame velocity v̂ = Rᵀ V and angular velocity
/// ω̂ = Rᵀ Ω), pointer bundles over the five components of a cell array, cell
/// loads/stores, the (optionally threaded) loop and the phase timer.
#pragma once
#include <array>
#include <chrono>
#include <utility>

#include <Eigen/Core>

#include "../../core/config.hpp"
#include "../../core/parallel.hpp"
#include "../../core/vec3.hpp"
#include "../fields.hpp"
#include "../frame/pose.hpp"
#include "../state.hpp"

namespace parafsi::fluid::detail {

struct stage_geometry {
  std::array<vec3<double>, 3> n;  ///< face normals (inertial) of the three box axes
  Eigen::Vector3d vh, oh;         ///< box-frame velocity and angular velocity
  Eigen::Matrix3d R;
};
inline stage_geometry geometry(const frame::pose& pose) {
  stage_geometry g;
  for (int d = 0; d < 3; ++d) g.n[std::size_t(d)] = {pose.R(0, d), pose.R(1, d), pose.R(2, d)};
  g.vh = pose.R.transpose() * pose.V;
  g.oh = pose.R.transpose() * pose.Omega;
  g.R = pose.R;
  return g;
}

/// The five component arrays of a conserved (ρ, mx, my, mz, E) or primitive
/// (ρ, u, v, w, p) storage.
template <class T>
using fields5 = std::array<T*, 5>;
template <class Storage>
fields5<double> conserved_ptrs(Storage& s) noexcept {
  return {s.template get<field::rho>(), s.template get<field::mx>(), s.template get<field::my>(),
          s.template get<field::mz>(), s.template get<field::E>()};
}
template <class Storage>
fields5<const double> conserved_ptrs(const Storage& s) noexcept {
  return {s.template get<field::rho>(), s.template get<field::mx>(), s.template get<field::my>(),
          s.template get<field::mz>(), s.template get<field::E>()};
}
template <class Storage>
fields5<double> primitive_ptrs(Storage& s) noexcept {
  return {s.template get<field::rho>(), s.template get<field::u>(), s.template get<field::v>(),
          s.template get<field::w>(), s.template get<field::p>()};
}
template <class Storage>
fields5<const double> primitive_ptrs(const Storage& s) noexcept {
  return {s.template get<field::rho>(), s.template get<field::u>(), s.template get<field::v>(),
          s.template get<field::w>(), s.template get<field::p>()};
}

PARAFSI_INLINE void store_cons(const fields5<double>& s, index_t c, const cons<double>& q) noexcept {
  s[0][c] = q.rho;
  s[1][c] = q.m.x;
  s[2][c] = q.m.y;
  s[3][c] = q.m.z;
  s[4][c] = q.E;
}
template <class T>
PARAFSI_INLINE cons<double> load_cons(const fields5<T>& s, index_t c) noexcept {
  return {s[0][c], {s[1][c], s[2][c], s[3][c]}, s[4][c]};
}

/// Parallel loop over disjoint work; serial when `threaded` is false (small grids:
/// below ~32k cells a parallel region costs more than it saves).
template <class F>
inline void par_for(bool threaded, index_t b, index_t e, F&& f) {
  parallel::for_range(b, e, std::forward<F>(f), threaded);
}

template <class F>
inline void timed(double& acc, F&& f) {
  const auto t0 = std::chrono::steady_clock::now();
  f();
  acc += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace parafsi::fluid::detail
