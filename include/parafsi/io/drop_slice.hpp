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
/// Numbers with 8 significant digits.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>

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
  const auto& g = fluid.grid();
  const auto& pose = fluid.pose();
  const Eigen::Matrix3d Rt = pose.R.transpose();
  index_t j0 = 0;
  for (index_t j = 1; j < g.n(1); ++j)
    if (std::fabs(g.centre(1, j)) < std::fabs(g.centre(1, j0))) j0 = j;
  const Eigen::Vector3d& vp = payload_velocity;
  auto ub = [&](index_t i, index_t k) {
    const auto w = fluid.primitive(i, j0, k);
    return Eigen::Vector3d(Rt * Eigen::Vector3d(w.u.x, w.u.y, w.u.z));
  };
  const std::string stem = drop_slice_stem(t_label);
  std::ostringstream os;
  os.precision(8);
  os << "xi,zeta,x,y,z,rho,p,speed,speed_rel,omega_n\n";
  const index_t nx = g.n(0), nz = g.n(2);
  for (index_t k = 0; k < nz; ++k)
    for (index_t i = 0; i < nx; ++i) {
      const index_t il = std::max<index_t>(0, i - 1), ir = std::min(nx - 1, i + 1);
      const index_t kl = std::max<index_t>(0, k - 1), kr = std::min(nz - 1, k + 1);
      // ω_y (box) = ∂u_x/∂ζ − ∂u_z/∂ξ (the component normal to the plane).
      const double dudz = (ub(i, kr).x() - ub(i, kl).x()) / (g.centre(2, kr) - g.centre(2, kl));
      const double dwdx = (ub(ir, k).z() - ub(il, k).z()) / (g.centre(0, ir) - g.centre(0, il));
      const auto w = fluid.primitive(i, j0, k);
      const Eigen::Vector3d u(w.u.x, w.u.y, w.u.z);
      const Eigen::Vector3d xi(g.centre(0, i), g.centre(1, j0), g.centre(2, k));
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
