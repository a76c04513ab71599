// Shared set-ups for the coupling tests: the coupling list of the typed tests (each entry
// builds its coupling through the public constructor only), the tilted patch in a periodic
// box, the sheet across a duct (model/duct_screen.hpp) and the duct's probe windows.
#pragma once
#include <doctest/doctest.h>

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/fluid/block_solver.hpp>
#include <parafsi/fluid/fluid.hpp>
#include <parafsi/model/duct_screen.hpp>
#include <parafsi/model/rect_mesh.hpp>
#include <parafsi/structure/structure.hpp>

#include <tuple>
#include <utility>

namespace ctu {
namespace pf = parafsi;
namespace st = pf::structure;

/// Coupling list entry: the penalty coupling with PFAC `pfac`.
struct penalty {
  static constexpr const char* name = "penalty";
  template <class Porosity>
  static auto make(Porosity por, double pfac) {
    pf::coupling::penalty_options po;
    po.pfac = pfac;
    return pf::coupling::penalty{por, po};
  }
};

/// Coupling list entry: the embedded coupling with its default options (it has no PFAC),
/// the cells beside the membrane first order (OneSided = false, the class's default) or
/// reconstructed from their own side (OneSided = true, the drop's default on the box).
template <bool OneSided>
struct embedded_t {
  static constexpr const char* name = OneSided ? "embedded/one-sided" : "embedded";
  template <class Porosity>
  static auto make(Porosity por, double /*pfac*/) {
    return pf::coupling::embedded<Porosity, OneSided>{por};
  }
};
using embedded = embedded_t<false>;
using embedded_one_sided = embedded_t<true>;

/// The coupling list: TEST_CASE_TEMPLATE_DEFINE(name, C, id) then TEST_CASE_TEMPLATE_APPLY(id, ctu::couplings).
using couplings = std::tuple<penalty, embedded, embedded_one_sided>;

/// A tilted 0.18 × 0.17 m square patch (3 × 3 quads, isotropic fabric of modulus E and areal
/// density ρ_A, thickness 0.1 mm) moving at v0 through still air of density rho in a periodic
/// 8³ box of 0.4 m (no boundary forces), no gravity.
template <class Coupling>
auto tilted_patch(Coupling cpl, double rho, double areal_density, double E, Eigen::Vector3d v0 = {4.0, 1.0, -0.5}) {
  auto grid = pf::fluid::rectilinear_grid::uniform({8, 8, 8}, {0, 0, 0}, {0.4, 0.4, 0.4});
  pf::fluid::solver fl{grid, pf::boundary::set::all(pf::boundary::periodic{})};
  fl.fill_uniform({rho, {0, 0, 0}, 101325.0});
  const auto m = pf::model::rect_mesh({0.12, 0.1, 0.11}, {0.02, 0.18, 0.0}, {0.0, 0.03, 0.17}, 3, 3);
  st::nodes nd;
  for (const auto& x : m.positions) nd.add(x, v0);
  st::triangle_mesh tm;
  tm.triangles = m.triangles;
  st::membrane_tri mem{tm, st::material::fabric<>::isotropic(E, 0.3, areal_density, 1e-4)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity = {0, 0, 0};
  return pf::explicit_stepper{std::move(fl), std::move(as), std::move(cpl)};
}

/// The duct's fluid grid (slip walls unless `bc` says otherwise is the caller's choice).
inline pf::fluid::rectilinear_grid duct_grid(const pf::model::duct_screen_scene& d) {
  return pf::fluid::rectilinear_grid::uniform(d.cells, d.lo, d.hi);
}

/// The duct's sheet as a triangle mesh.
inline st::triangle_mesh sheet_mesh(const pf::model::duct_screen_scene& d) {
  st::triangle_mesh tm;
  tm.triangles = d.sheet.triangles;
  return tm;
}

/// The duct's sheet as a rigid structure: every node pinned, no gravity (E = 0.3 GPa, ν 0.3,
/// 54 g/m², t = 0.11 mm: its loads are read, it does not move).
inline auto pinned_sheet(const pf::model::duct_screen_scene& d) {
  st::nodes nd;
  for (const auto& x : d.sheet.positions) nd.add(x);
  for (pf::index_t i = 0; i < nd.size(); ++i) nd.pin(i);
  st::membrane_tri mem{sheet_mesh(d), st::material::fabric<>::isotropic(3e8, 0.3, 0.054, 1.1e-4)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity = {0, 0, 0};
  return as;
}

/// Mean pressure and x-velocity, and the total mass, of the cells of a duct (n × m × 2) with
/// centres strictly between x = a and x = b.
template <class S>
void window_means(const S& s, double a, double b, double& p, double& u, double& mass) {
  const auto& g = s.fluid().grid();
  p = u = mass = 0;
  int n = 0;
  for (pf::index_t k = 0; k < g.n(2); ++k)
    for (pf::index_t j = 0; j < g.n(1); ++j)
      for (pf::index_t i = 0; i < g.n(0); ++i) {
        const double x = g.centre(0, i);
        if (x <= a || x >= b) continue;
        const auto w = s.fluid().primitive(i, j, k);
        p += w.p;
        u += w.u.x;
        mass += w.rho * g.cell_volume(i, j, k);
        ++n;
      }
  p /= n;
  u /= n;
}

/// The tilted patch of ctu::tilted_patch on a block mesh of the same periodic 0.4 m box
/// (2 x 2 x 2 root blocks of 4^3 cells), refined to `levels` within 4 cm of the patch.
template <class Coupling = pf::coupling::penalty<pf::porosity::impermeable>>
auto blocks_patch(int levels, Coupling cpl = Coupling{pf::porosity::impermeable{}}, double E = 1e5) {
  pf::fluid::block_layout lay{{0, 0, 0}, {0.4, 0.4, 0.4}, {2, 2, 2}, 4};
  const auto m = pf::model::rect_mesh({0.12, 0.1, 0.11}, {0.02, 0.18, 0.0}, {0.0, 0.03, 0.17}, 3, 3);
  pf::fluid::blocks::tree t({2, 2, 2}, {true, true, true});
  if (levels > 0) t.refine_where(levels, pf::fluid::blocks::near_points(lay, m.positions, 0.04, levels));
  pf::fluid::block_solver fl{t, lay, pf::boundary::set::all(pf::boundary::periodic{})};
  fl.fill_uniform({1.18, {0, 0, 0}, 101325.0});
  const Eigen::Vector3d v0{4.0, 1.0, -0.5};
  st::nodes nd;
  for (const auto& x : m.positions) nd.add(x, v0);
  st::triangle_mesh tm;
  tm.triangles = m.triangles;
  st::membrane_tri mem{tm, st::material::fabric<>::isotropic(E, 0.3, 0.5, 1e-4)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity = {0, 0, 0};
  return pf::explicit_stepper{std::move(fl), std::move(as), std::move(cpl)};
}

}  // namespace ctu
