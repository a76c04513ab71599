/// \file drop_slice.hpp
/// Mid-plane slice of the drop's fluid box, as two CSV files written through checked
/// files (io/checked_file.hpp):
///
///   <dir>/slice_<t>.csv        xi,zeta,x,y,z,rho,p,speed,speed_rel,omega_n
///   <dir>/slice_<t>_nodes.csv  xi,eta,zeta,canopy
///
/// with <t> the label time as `%06.3f`. The slice is the layer of cells j0 whose centre is
/// nearest to ξy = 0 (the box's x–z plane through the payload). Per cell: box coordinates
/// ξx, ξz; inertial position x = X + R ξ; density; physical pressure q + `pressure_offset`
/// (the pressure-gradient scaling offset, 0 without it); |u| and |u − v_p| (v_p the payload
/// velocity); and ω_n = ∂u_x/∂ζ − ∂u_z/∂ξ in box components, the vorticity normal to the
/// plane, by central differences (one-sided at the box faces). The node file gives every
/// structure node in box coordinates, flagged 1 for the canopy's nodes [0, canopy_nodes).
/// Numbers with 8 significant digits. On a block mesh (fluid::block_solver) the slice is
/// sampled at the finest level's cell centres (the layer nearest to ξy = 0) from the leaf
/// cells holding them, so coarse leaves appear as patches of equal values.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "../core/config.hpp"
#include "../structure/nodes.hpp"
#include "checked_file.hpp"

namespace parafsi::io {

/// The file stem of the slice at label time t: "slice_%06.3f".
inline std::string drop_slice_stem(double t_label) {
  char name[64];
  std::snprintf(name, sizeof name, "slice_%06.3f", t_label);
  return name;
}

/// Write the slice of `fluid` at label time `t_label` into `dir` (rules in the file comment).
template <class Fluid>
void write_drop_slice(const std::filesystem::path& dir, double t_label, const Fluid& fluid, const structure::nodes& nd,
                      index_t canopy_nodes, const Eigen::Vector3d& payload_velocity, double pressure_offset) {
  const auto& pose = fluid.pose();
  const Eigen::Matrix3d Rt = pose.R.transpose();
  // The sampling grid: nx × nz centres at height y0 and the state at each.
  index_t nx = 0, nz = 0;
  std::array<std::vector<double>, 2> centre;  // ξx of column i, ξz of row k
  double y0 = 0;
  auto sample_grid = [&](auto&& xc, auto&& yc, index_t ny, auto&& zc) {
    index_t j0 = 0;
    for (index_t j = 1; j < ny; ++j)
      if (std::fabs(yc(j)) < std::fabs(yc(j0))) j0 = j;
    y0 = yc(j0);
    for (index_t i = 0; i < nx; ++i) centre[0].push_back(xc(i));
    for (index_t k = 0; k < nz; ++k) centre[1].push_back(zc(k));
    return j0;
  };
  auto state = [&](index_t i, index_t k, index_t j0) {
    if constexpr (requires { fluid.block_count(); }) {
      (void)j0;
      return fluid.sample(Eigen::Vector3d(centre[0][std::size_t(i)], y0, centre[1][std::size_t(k)]));
    } else {
      return fluid.primitive(i, j0, k);
    }
  };
  index_t j0 = 0;
  if constexpr (requires { fluid.block_count(); }) {
    const auto& lay = fluid.layout();
    const int top = fluid.tree().finest_level();
    auto axis_n = [&](int d) { return fluid.tree().extent(d, top) * lay.block_cells; };
    auto cc = [&](int d) {
      return [&lay, top, d](index_t i) { return lay.lo[std::size_t(d)] + (double(i) + 0.5) * lay.cell_width(d, top); };
    };
    nx = axis_n(0);
    nz = axis_n(2);
    j0 = sample_grid(cc(0), cc(1), axis_n(1), cc(2));
  } else {
    const auto& g = fluid.grid();
    nx = g.n(0);
    nz = g.n(2);
    j0 = sample_grid([&](index_t i) { return g.centre(0, i); }, [&](index_t j) { return g.centre(1, j); }, g.n(1),
                     [&](index_t k) { return g.centre(2, k); });
  }
  const Eigen::Vector3d& vp = payload_velocity;
  auto ub = [&](index_t i, index_t k) {
    const auto w = state(i, k, j0);
    return Eigen::Vector3d(Rt * Eigen::Vector3d(w.u.x, w.u.y, w.u.z));
  };
  const std::string stem = drop_slice_stem(t_label);
  std::ostringstream os;
  os.precision(8);
  os << "xi,zeta,x,y,z,rho,p,speed,speed_rel,omega_n\n";
  for (index_t k = 0; k < nz; ++k)
    for (index_t i = 0; i < nx; ++i) {
      const index_t il = std::max<index_t>(0, i - 1), ir = std::min(nx - 1, i + 1);
      const index_t kl = std::max<index_t>(0, k - 1), kr = std::min(nz - 1, k + 1);
      // ω_y (box) = ∂u_x/∂ζ − ∂u_z/∂ξ (the component normal to the plane).
      const double dudz = (ub(i, kr).x() - ub(i, kl).x()) / (centre[1][std::size_t(kr)] - centre[1][std::size_t(kl)]);
      const double dwdx = (ub(ir, k).z() - ub(il, k).z()) / (centre[0][std::size_t(ir)] - centre[0][std::size_t(il)]);
      const auto w = state(i, k, j0);
      const Eigen::Vector3d u(w.u.x, w.u.y, w.u.z);
      const Eigen::Vector3d xi(centre[0][std::size_t(i)], y0, centre[1][std::size_t(k)]);
      const Eigen::Vector3d x = pose.X + pose.R * xi;
      os << xi.x() << ',' << xi.z() << ',' << x.x() << ',' << x.y() << ',' << x.z() << ',' << w.rho << ','
         << w.p + pressure_offset << ',' << u.norm() << ',' << (u - vp).norm() << ',' << (dudz - dwdx) << '\n';
    }
  write_text_file(dir / (stem + ".csv"), os.str());
  std::ostringstream on;
  on.precision(8);
  on << "xi,eta,zeta,canopy\n";
  for (index_t i = 0; i < nd.size(); ++i) {
    const Eigen::Vector3d xb = Rt * (nd.position(i) - pose.X);
    on << xb.x() << ',' << xb.y() << ',' << xb.z() << ',' << (i < canopy_nodes ? 1 : 0) << '\n';
  }
  write_text_file(dir / (stem + "_nodes.csv"), on.str());
}

}  // namespace parafsi::io
