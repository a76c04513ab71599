/// \file view.hpp
/// `fluid::view`: a read-only view of the fluid state for couplings and observers —
/// the grid, the box pose, the gas and const pointers to the cell arrays of the state
/// it describes (the step's start state between steps, the current stage's state
/// inside a face patch). Cell states are decoded in this one place:
///   ρ,   u = m / ρ,   p = (γ − 1)(E − ½ |m|²/ρ)   (gas::ideal::pressure).
/// Cells are flat indices of the grid (grid.index(i, j, k); grid.ijk(c) inverts it).
#pragma once
#include <array>

#include <Eigen/Core>

#include "../core/config.hpp"
#include "fields.hpp"
#include "frame/pose.hpp"
#include "gas.hpp"
#include "grid.hpp"
#include "state.hpp"

namespace parafsi::fluid {

struct view {
  const rectilinear_grid* grid = nullptr;
  const frame::pose* pose = nullptr;
  gas::ideal gas{};
  const double* rho = nullptr;  ///< density (kg/m³)
  const double* mx = nullptr;   ///< momentum per volume, inertial components (kg/(m² s))
  const double* my = nullptr;
  const double* mz = nullptr;
  const double* E = nullptr;  ///< total energy per volume (J/m³)

  /// View of a conserved storage (soa over conserved_fields).
  template <class Storage>
  static view of(const rectilinear_grid& g, const frame::pose& p, const gas::ideal& gas, const Storage& U) noexcept {
    return {&g,
            &p,
            gas,
            U.template get<field::rho>(),
            U.template get<field::mx>(),
            U.template get<field::my>(),
            U.template get<field::mz>(),
            U.template get<field::E>()};
  }

  index_t index(index_t i, index_t j, index_t k) const noexcept { return grid->index(i, j, k); }
  std::array<index_t, 3> ijk(index_t c) const noexcept { return grid->ijk(c); }

  double density(index_t c) const noexcept { return rho[c]; }
  /// Inertial velocity m/ρ of cell c (m/s).
  Eigen::Vector3d velocity(index_t c) const noexcept { return Eigen::Vector3d(mx[c], my[c], mz[c]) / rho[c]; }
  double pressure(index_t c) const noexcept { return gas.pressure(rho[c], mx[c], my[c], mz[c], E[c]); }
  /// Bulk modulus γ p of cell c (Pa).
  double bulk_modulus(index_t c) const noexcept { return gas.gamma * pressure(c); }
  prim<double> primitive(index_t c) const noexcept {
    const Eigen::Vector3d u = velocity(c);
    return {rho[c], {u.x(), u.y(), u.z()}, pressure(c)};
  }
};

}  // namespace parafsi::fluid
