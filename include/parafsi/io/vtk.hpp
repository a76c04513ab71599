/// \file vtk.hpp
/// VTK XML output for ParaView, written by hand (no VTK library), for the user's loop
/// (DESIGN §1: observers run between steps; §2: io/ is never included by physics
/// headers). Every writer takes const views of the public state only.
///
///   write_vtu(path, assembly)        structure → UnstructuredGrid (.vtu)
///   write_vts(path, solver)          fluid     → StructuredGrid (.vts)
///   write_midplane_csv(path, solver) fluid mid-plane slice → CSV
///   pvd_writer                       time series (.pvd) of any of the above
/// (The block mesh, fluid::block_solver, has its writers in block_vtk.hpp.)
///
/// Encodings: `ascii` (17 significant digits, exact round-trip) or `binary` (the
/// default): base64 inline data, VTK's `header_type="UInt64"` (each array is the
/// base64 of an 8-byte byte count followed by the raw little/big-endian values, as
/// the file's `byte_order` says), no compression. Files are written to `path.tmp` and
/// renamed, so a reader never sees a half-written file.
///
/// Structure (.vtu): points = the assembly's nodes (current positions), then one point
/// per rigid body (its mass centre, a VTK_VERTEX cell). Cells, part by part in the
/// assembly's order: membrane triangles (VTK_TRIANGLE), membrane quads (VTK_QUAD),
/// cable/tape segments (VTK_LINE), bodies (VTK_VERTEX).
///   point data: `velocity` (m/s; nodes at t^{n−½} as the central difference holds them,
///               bodies: mass-centre velocity), `mass` (kg), `constraint` (0 free,
///               1 pinned, 2 prescribed, 3 attached; 0 for body points)
///   cell data:  `part` (index of the part in the assembly), `tag` (user tags, if given),
///               `stress` (S11, S22, S12: second Piola–Kirchhoff, elastic and wrinkling-
///               filtered, in the element's fibre axes, Pa; 0 on lines/bodies),
///               `effective_stress` = √(S11² − S11 S22 + S22² + 3 S12²) (plane-stress
///               von Mises form, Pa), `strain` (E11, E22, γ12 = 2 E12 Green–Lagrange),
///               `tension` (cable/tape tension incl. damping, N; 0 on membranes).
/// Fluid (.vts): the grid's points are the cell CORNERS (face coordinates ξ) mapped to
/// inertial coordinates x = X + R ξ with the current box pose; all fields are CELL data
/// (finite-volume cell averages), interior cells only:
///   `density` (kg/m³), `velocity` (inertial, m/s), `pressure` (Pa), `vorticity`
///   (∇×u of the inertial velocity, inertial components, 1/s), `eddy_viscosity`
///   (μ_t, Pa·s, when the solver has a turbulence closure).
/// Vorticity: the box-frame velocity û = Rᵀu is differentiated along the box axes by
/// central differences between neighbouring cell centres (one-sided at the box faces;
/// exact for linear fields on stretched grids), ω̂ = ∇_ξ × û, then ω = R ω̂. This is
/// the vorticity of the absolute (inertial) velocity, independent of the box's motion:
/// a solid-body rotation u = Ω × r gives 2Ω whatever the box pose.
/// Mid-plane CSV: header `x,y,z,rho,u,v,w,p,vorticity_normal`; the plane normal to box
/// axis `normal_axis` (default 1: the plane spanned by box x and z, which contains the
/// follow_payload axis −z) at ξ = `position` (default: the middle of the box along that
/// axis); values interpolated linearly between the two cell layers around the plane;
/// one row per cell of the plane, the lower remaining box axis fastest; x, y, z are the
/// inertial coordinates of the point, `vorticity_normal` = ω · (R e_normal).
/// Time series (.pvd): `pvd_writer::add(t, file)` appends a DataSet entry and rewrites
/// the collection (always a complete file); with `resume_after = t` an existing
/// collection keeps its entries up to t (restart).
#pragma once
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "../core/config.hpp"
#include "../core/error.hpp"
#include "checked_file.hpp"

namespace parafsi::io {

enum class vtk_encoding { ascii, binary };

struct vtk_options {
  vtk_encoding encoding = vtk_encoding::binary;
  /// Added to every fluid pressure written (Pa): e.g. fluid::pressure_gradient_scaling's
  /// pressure_offset(p∞), so a scaled run shows physical pressures. 0 = as stored.
  double pressure_offset = 0.0;
};

struct vtu_options : vtk_options {
  /// Optional tag per output cell (membrane/line elements in part order, then one per
  /// body); empty = no `tag` array. A size mismatch is an error naming both counts.
  std::vector<int> cell_tags;
};

struct midplane_options {
  int normal_axis = 1;                                         ///< box axis normal to the plane (0, 1 or 2)
  double position = std::numeric_limits<double>::quiet_NaN();  ///< ξ of the plane; NaN = mid-box
};

namespace detail {

inline constexpr const char* vtk_byte_order() {
  return std::endian::native == std::endian::little ? "LittleEndian" : "BigEndian";
}

inline std::string base64(const unsigned char* p, std::size_t n) {
  static constexpr char tbl[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string s;
  s.reserve((n + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < n; i += 3) {
    const unsigned v = (unsigned(p[i]) << 16) | (unsigned(p[i + 1]) << 8) | unsigned(p[i + 2]);
    s += tbl[(v >> 18) & 63];
    s += tbl[(v >> 12) & 63];
    s += tbl[(v >> 6) & 63];
    s += tbl[v & 63];
  }
  if (i < n) {
    unsigned v = unsigned(p[i]) << 16;
    if (i + 1 < n) v |= unsigned(p[i + 1]) << 8;
    s += tbl[(v >> 18) & 63];
    s += tbl[(v >> 12) & 63];
    s += i + 1 < n ? tbl[(v >> 6) & 63] : '=';
    s += '=';
  }
  return s;
}

template <class T>
constexpr const char* vtk_type_name();
template <>
constexpr const char* vtk_type_name<double>() {
  return "Float64";
}
template <>
constexpr const char* vtk_type_name<std::int64_t>() {
  return "Int64";
}
template <>
constexpr const char* vtk_type_name<std::int32_t>() {
  return "Int32";
}
template <>
constexpr const char* vtk_type_name<std::uint8_t>() {
  return "UInt8";
}

/// Appends <DataArray> elements in the chosen encoding.
class xml_out {
 public:
  explicit xml_out(vtk_encoding e) : enc_(e) {}
  std::string s;

  template <class T>
  void array(std::string_view name, int components, const std::vector<T>& v, int indent) {
    s.append(std::size_t(indent), ' ');
    s += "<DataArray type=\"";
    s += vtk_type_name<T>();
    s += "\"";
    if (!name.empty()) {
      s += " Name=\"";
      s += name;
      s += "\"";
    }
    if (components > 1) s += " NumberOfComponents=\"" + std::to_string(components) + "\"";
    s += enc_ == vtk_encoding::ascii ? " format=\"ascii\">\n" : " format=\"binary\">\n";
    s.append(std::size_t(indent + 2), ' ');
    if (enc_ == vtk_encoding::ascii) {
      char buf[40];
      for (std::size_t i = 0; i < v.size(); ++i) {
        if constexpr (std::is_floating_point_v<T>) std::snprintf(buf, sizeof buf, "%.17g", double(v[i]));
        else std::snprintf(buf, sizeof buf, "%lld", static_cast<long long>(v[i]));
        if (i) s += (i % 12 == 0) ? "\n" + std::string(std::size_t(indent + 2), ' ') : std::string(" ");
        s += buf;
      }
    } else {
      const std::uint64_t nbytes = v.size() * sizeof(T);
      std::vector<unsigned char> raw(sizeof nbytes + nbytes);
      std::memcpy(raw.data(), &nbytes, sizeof nbytes);
      if (nbytes) std::memcpy(raw.data() + sizeof nbytes, v.data(), nbytes);
      s += base64(raw.data(), raw.size());
    }
    s += "\n";
    s.append(std::size_t(indent), ' ');
    s += "</DataArray>\n";
  }

 private:
  vtk_encoding enc_;
};

inline std::string vtk_header(const char* type) {
  std::string s = "<?xml version=\"1.0\"?>\n<VTKFile type=\"";
  s += type;
  s += "\" version=\"1.0\" byte_order=\"";
  s += vtk_byte_order();
  s += "\" header_type=\"UInt64\">\n";
  return s;
}

/// The closing part of an UnstructuredGrid piece: its points, its cells and the end tags.
template <class P, class C, class O, class T>
std::string vtu_points_cells_end(xml_out& x, const std::vector<P>& pts, const std::vector<C>& conn,
                                 const std::vector<O>& offs, const std::vector<T>& types) {
  x.s.clear();
  x.array("Points", 3, pts, 8);
  std::string s = "      <Points>\n" + x.s + "      </Points>\n";
  x.s.clear();
  x.array("connectivity", 1, conn, 8);
  x.array("offsets", 1, offs, 8);
  x.array("types", 1, types, 8);
  s += "      <Cells>\n" + x.s + "      </Cells>\n";
  s += "    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n";
  return s;
}

inline std::string time_field_data(double t, xml_out& x) {
  x.s.clear();
  x.array("TIME", 1, std::vector<double>{t}, 4);
  return "    <FieldData>\n" + x.s + "    </FieldData>\n";
}

template <class A>
concept element_part = requires(const A& p, index_t e) {
  p.element(e);
  p.size();
};

template <class Assembly, class F>
void for_each_part(const Assembly& a, F&& f) {
  [&]<std::size_t... I>(std::index_sequence<I...>) {
    (f(std::integral_constant<std::size_t, I>{}, a.template part<I>()), ...);
  }
  (std::make_index_sequence<Assembly::part_count>{});
}

}  // namespace detail

// ============================================================== structure (.vtu)

/// Structure as a VTK UnstructuredGrid (see the file comment for the arrays). `time`
/// (the TIME field) defaults to the assembly's time.
template <class Assembly>
requires requires(const Assembly& a) { a.node_set(); }
void write_vtu(const std::filesystem::path& path, const Assembly& a, const vtu_options& opt = {},
               double time = std::numeric_limits<double>::quiet_NaN()) {
  if (std::isnan(time)) time = a.time();
  const auto& nd = a.node_set();
  const index_t N = nd.size();
  std::vector<double> pts, vel, mass;
  std::vector<std::int32_t> kind;
  pts.reserve(std::size_t(3 * N));
  for (index_t i = 0; i < N; ++i) {
    const Eigen::Vector3d x = nd.position(i), v = nd.velocity(i);
    pts.insert(pts.end(), {x.x(), x.y(), x.z()});
    vel.insert(vel.end(), {v.x(), v.y(), v.z()});
    mass.push_back(nd.needs_finalize() ? nd.point_mass(i) : nd.mass(i));
    kind.push_back(std::int32_t(nd.kind(i)));
  }
  std::vector<std::int64_t> conn, offs;
  std::vector<std::uint8_t> types;
  std::vector<std::int32_t> part;
  std::vector<double> stress, eff, strain, tension;
  auto add_cell = [&](auto nodes_of, std::uint8_t type, std::int32_t p) {
    for (auto n : nodes_of) conn.push_back(std::int64_t(n));
    offs.push_back(std::int64_t(conn.size()));
    types.push_back(type);
    part.push_back(p);
  };
  index_t extra = N;  // next body point
  std::vector<std::pair<index_t, std::int32_t>> body_points;
  detail::for_each_part(a, [&](auto I, const auto& p) {
    using P = std::remove_cvref_t<decltype(p)>;
    const std::int32_t pid = std::int32_t(decltype(I)::value);
    if constexpr (detail::element_part<P>) {
      for (index_t e = 0; e < p.size(); ++e) {
        const auto el = p.element(e);
        constexpr std::size_t k = std::tuple_size_v<std::remove_cvref_t<decltype(el)>>;
        static_assert(k == 2 || k == 3 || k == 4, "io::write_vtu: parts must have 2, 3 or 4 nodes per element");
        add_cell(el, k == 2 ? 3 : (k == 3 ? 5 : 9), pid);
        std::array<double, 6> ss{};
        if constexpr (requires { p.strain_stress(nd, e); }) {
          if (!nd.needs_finalize()) ss = p.strain_stress(nd, e);
        }
        strain.insert(strain.end(), {ss[0], ss[1], ss[2]});
        stress.insert(stress.end(), {ss[3], ss[4], ss[5]});
        eff.push_back(std::sqrt(std::max(0.0, ss[3] * ss[3] - ss[3] * ss[4] + ss[4] * ss[4] + 3 * ss[5] * ss[5])));
        double T = 0;
        if constexpr (requires { p.tension(nd, e); }) {
          if (!nd.needs_finalize()) T = p.tension(nd, e);
        }
        tension.push_back(T);
      }
    } else if constexpr (requires { p.body().mass_centre(); }) {
      const auto& b = p.body();
      const Eigen::Vector3d x = b.mass_centre(), v = b.mass_centre_velocity();
      pts.insert(pts.end(), {x.x(), x.y(), x.z()});
      vel.insert(vel.end(), {v.x(), v.y(), v.z()});
      mass.push_back(b.mass());
      kind.push_back(0);
      add_cell(std::array<index_t, 1>{extra++}, 1, pid);
      strain.insert(strain.end(), {0.0, 0.0, 0.0});
      stress.insert(stress.end(), {0.0, 0.0, 0.0});
      eff.push_back(0.0);
      tension.push_back(0.0);
    }
  });
  const std::size_t ncells = types.size(), npts = pts.size() / 3;
  require(opt.cell_tags.empty() || opt.cell_tags.size() == ncells, "io::write_vtu: ", opt.cell_tags.size(),
          " cell tags for ", ncells, " cells (elements in part order, then one per rigid body)");
  detail::xml_out x(opt.encoding);
  std::string s = detail::vtk_header("UnstructuredGrid");
  s += "  <UnstructuredGrid>\n";
  s += detail::time_field_data(time, x);
  s += "    <Piece NumberOfPoints=\"" + std::to_string(npts) + "\" NumberOfCells=\"" + std::to_string(ncells) + "\">\n";
  x.s.clear();
  x.array("velocity", 3, vel, 8);
  x.array("mass", 1, mass, 8);
  x.array("constraint", 1, kind, 8);
  s += "      <PointData Vectors=\"velocity\">\n" + x.s + "      </PointData>\n";
  x.s.clear();
  x.array("part", 1, part, 8);
  if (!opt.cell_tags.empty())
    x.array("tag", 1, std::vector<std::int32_t>(opt.cell_tags.begin(), opt.cell_tags.end()), 8);
  x.array("stress", 3, stress, 8);
  x.array("effective_stress", 1, eff, 8);
  x.array("strain", 3, strain, 8);
  x.array("tension", 1, tension, 8);
  s += "      <CellData Scalars=\"effective_stress\">\n" + x.s + "      </CellData>\n";
  s += detail::vtu_points_cells_end(x, pts, conn, offs, types);
  io::write_file_atomic(path, s);
}

// ============================================================== fluid (.vts, slices)

/// Inertial vorticity ω = R (∇_ξ × Rᵀu) of every interior cell, x fastest
/// (3 components per cell). See the file comment for the differences used.
template <class Solver>
std::vector<double> vorticity(const Solver& s) {
  const auto& g = s.grid();
  const index_t n[3] = {g.n(0), g.n(1), g.n(2)};
  const Eigen::Matrix3d R = s.pose().R;
  const std::size_t cells = std::size_t(n[0] * n[1] * n[2]);
  std::vector<Eigen::Vector3d> ub(cells);
  auto lin = [&](index_t i, index_t j, index_t k) { return std::size_t(i + n[0] * (j + n[1] * k)); };
  for (index_t k = 0; k < n[2]; ++k)
    for (index_t j = 0; j < n[1]; ++j)
      for (index_t i = 0; i < n[0]; ++i) {
        const auto w = s.primitive(i, j, k);
        ub[lin(i, j, k)] = R.transpose() * Eigen::Vector3d(w.u.x, w.u.y, w.u.z);
      }
  std::vector<double> out(3 * cells);
  for (index_t k = 0; k < n[2]; ++k)
    for (index_t j = 0; j < n[1]; ++j)
      for (index_t i = 0; i < n[0]; ++i) {
        const index_t ijk[3] = {i, j, k};
        Eigen::Matrix3d G = Eigen::Matrix3d::Zero();  // G(a, d) = ∂û_a/∂ξ_d
        for (int d = 0; d < 3; ++d) {
          if (n[d] < 2) continue;
          index_t lo[3] = {i, j, k}, hi[3] = {i, j, k};
          lo[d] = std::max<index_t>(ijk[d] - 1, 0);
          hi[d] = std::min<index_t>(ijk[d] + 1, n[d] - 1);
          const double h = g.centre(d, hi[d]) - g.centre(d, lo[d]);
          G.col(d) = (ub[lin(hi[0], hi[1], hi[2])] - ub[lin(lo[0], lo[1], lo[2])]) / h;
        }
        const Eigen::Vector3d wb(G(2, 1) - G(1, 2), G(0, 2) - G(2, 0), G(1, 0) - G(0, 1));
        const Eigen::Vector3d wi = R * wb;
        const std::size_t c = lin(i, j, k);
        out[3 * c] = wi.x();
        out[3 * c + 1] = wi.y();
        out[3 * c + 2] = wi.z();
      }
  return out;
}

/// Fluid as a VTK StructuredGrid (corner points in inertial coordinates, cell data).
template <class Solver>
void write_vts(const std::filesystem::path& path, const Solver& s, const vtk_options& opt = {}) {
  const auto& g = s.grid();
  const index_t n[3] = {g.n(0), g.n(1), g.n(2)};
  const auto& pose = s.pose();
  std::vector<double> pts;
  pts.reserve(std::size_t(3 * (n[0] + 1) * (n[1] + 1) * (n[2] + 1)));
  for (index_t k = 0; k <= n[2]; ++k)
    for (index_t j = 0; j <= n[1]; ++j)
      for (index_t i = 0; i <= n[0]; ++i) {
        const Eigen::Vector3d x = pose.to_inertial({g.face(0, i), g.face(1, j), g.face(2, k)});
        pts.insert(pts.end(), {x.x(), x.y(), x.z()});
      }
  const std::size_t cells = std::size_t(n[0] * n[1] * n[2]);
  std::vector<double> rho, vel, p, mut;
  rho.reserve(cells);
  vel.reserve(3 * cells);
  p.reserve(cells);
  for (index_t k = 0; k < n[2]; ++k)
    for (index_t j = 0; j < n[1]; ++j)
      for (index_t i = 0; i < n[0]; ++i) {
        const auto w = s.primitive(i, j, k);
        rho.push_back(w.rho);
        vel.insert(vel.end(), {w.u.x, w.u.y, w.u.z});
        p.push_back(w.p + opt.pressure_offset);
        if constexpr (Solver::has_eddy_viscosity) mut.push_back(s.eddy_viscosity()[g.index(i, j, k)]);
      }
  const std::vector<double> vort = vorticity(s);
  const std::string ext = "0 " + std::to_string(n[0]) + " 0 " + std::to_string(n[1]) + " 0 " + std::to_string(n[2]);
  detail::xml_out x(opt.encoding);
  std::string out = detail::vtk_header("StructuredGrid");
  out += "  <StructuredGrid WholeExtent=\"" + ext + "\">\n";
  out += detail::time_field_data(s.time(), x);
  out += "    <Piece Extent=\"" + ext + "\">\n";
  x.s.clear();
  x.array("density", 1, rho, 8);
  x.array("velocity", 3, vel, 8);
  x.array("pressure", 1, p, 8);
  x.array("vorticity", 3, vort, 8);
  if constexpr (Solver::has_eddy_viscosity) x.array("eddy_viscosity", 1, mut, 8);
  out += "      <CellData Scalars=\"pressure\" Vectors=\"velocity\">\n" + x.s + "      </CellData>\n";
  x.s.clear();
  x.array("Points", 3, pts, 8);
  out += "      <Points>\n" + x.s + "      </Points>\n";
  out += "    </Piece>\n  </StructuredGrid>\n</VTKFile>\n";
  io::write_file_atomic(path, out);
}

/// Mid-plane slice as CSV `x,y,z,rho,u,v,w,p,vorticity_normal` (see the file comment).
/// Returns the number of rows written.
template <class Solver>
std::size_t write_midplane_csv(const std::filesystem::path& path, const Solver& s, const midplane_options& opt = {}) {
  const auto& g = s.grid();
  require(opt.normal_axis >= 0 && opt.normal_axis < 3, "io::write_midplane_csv: normal_axis must be 0, 1 or 2, got ",
          opt.normal_axis);
  // The same axis, in a form the compiler sees in range (GCC 12's -Warray-bounds does not
  // follow the check above through the inlined loops).
  const int a = std::clamp(opt.normal_axis, 0, 2);
  const index_t n[3] = {g.n(0), g.n(1), g.n(2)};
  const double lo = g.face(a, 0), hi = g.face(a, n[a]);
  const double xp = std::isnan(opt.position) ? 0.5 * (lo + hi) : opt.position;
  require(xp >= lo && xp <= hi, "io::write_midplane_csv: plane position ", xp, " outside the box [", lo, ", ", hi,
          "] along axis ", a);
  // The two layers around the plane and the weight of the upper one.
  index_t k0 = 0;
  while (k0 + 1 < n[a] && g.centre(a, k0 + 1) <= xp) ++k0;
  index_t k1 = std::min<index_t>(k0 + 1, n[a] - 1);
  double w1 = 0;
  if (k1 != k0 && xp > g.centre(a, k0)) w1 = (xp - g.centre(a, k0)) / (g.centre(a, k1) - g.centre(a, k0));
  if (xp <= g.centre(a, k0)) k1 = k0;  // below the first centre: constant extrapolation
  const std::vector<double> vort = vorticity(s);
  const auto& pose = s.pose();
  const Eigen::Vector3d nrm = pose.R.col(a);
  const int b = a == 0 ? 1 : 0, c = a == 2 ? 1 : 2;  // remaining axes, b < c
  std::string out = "x,y,z,rho,u,v,w,p,vorticity_normal\n";
  char buf[64];
  auto num = [&](double v, bool last) {
    std::snprintf(buf, sizeof buf, "%.10g", v);
    out += buf;
    out += last ? '\n' : ',';
  };
  std::size_t rows = 0;
  for (index_t jc = 0; jc < n[c]; ++jc)
    for (index_t jb = 0; jb < n[b]; ++jb) {
      index_t ijk0[3], ijk1[3];
      ijk0[b] = ijk1[b] = jb;
      ijk0[c] = ijk1[c] = jc;
      ijk0[a] = k0;
      ijk1[a] = k1;
      const auto p0 = s.primitive(ijk0[0], ijk0[1], ijk0[2]), p1 = s.primitive(ijk1[0], ijk1[1], ijk1[2]);
      auto mix = [&](double u0, double u1) { return (1 - w1) * u0 + w1 * u1; };
      const std::size_t c0 = std::size_t(ijk0[0] + n[0] * (ijk0[1] + n[1] * ijk0[2]));
      const std::size_t c1 = std::size_t(ijk1[0] + n[0] * (ijk1[1] + n[1] * ijk1[2]));
      Eigen::Vector3d om;
      for (int q = 0; q < 3; ++q) om[q] = mix(vort[3 * c0 + std::size_t(q)], vort[3 * c1 + std::size_t(q)]);
      Eigen::Vector3d xi;
      xi[a] = xp;
      xi[b] = g.centre(b, jb);
      xi[c] = g.centre(c, jc);
      const Eigen::Vector3d x = pose.to_inertial(xi);
      num(x.x(), false);
      num(x.y(), false);
      num(x.z(), false);
      num(mix(p0.rho, p1.rho), false);
      num(mix(p0.u.x, p1.u.x), false);
      num(mix(p0.u.y, p1.u.y), false);
      num(mix(p0.u.z, p1.u.z), false);
      num(mix(p0.p, p1.p), false);
      num(om.dot(nrm), true);
      ++rows;
    }
  io::write_file_atomic(path, out);
  return rows;
}

// ============================================================== time series (.pvd)

class pvd_writer {
 public:
  /// `resume_after`: keep an existing collection's entries with timestep <= this value
  /// (restart); NaN (default) starts an empty collection.
  explicit pvd_writer(std::filesystem::path path, double resume_after = std::numeric_limits<double>::quiet_NaN())
      : path_(std::move(path)) {
    if (!std::isnan(resume_after) && std::filesystem::exists(path_)) {
      std::ifstream in(path_);
      for (std::string line; std::getline(in, line);) {
        if (line.find("<DataSet") == std::string::npos) continue;
        entry e;
        e.t = std::strtod(attribute(line, "timestep").c_str(), nullptr);
        e.part = std::atoi(attribute(line, "part").c_str());
        e.file = attribute(line, "file");
        if (e.t <= resume_after) entries_.push_back(e);
      }
    }
    write();
  }

  /// Append the dataset `file` at time t (part: for several datasets per instant, e.g.
  /// 0 = fluid, 1 = structure) and rewrite the collection. A `file` inside the
  /// collection's directory is stored relative to it.
  void add(double t, const std::filesystem::path& file, int part = 0) {
    require(std::isfinite(t), "io::pvd_writer::add: non-finite time");
    std::filesystem::path f = file;
    const auto dir = path_.parent_path();
    if (!dir.empty()) {
      const auto rel = file.lexically_relative(dir);
      if (!rel.empty() && *rel.begin() != "..") f = rel;
    }
    entries_.push_back({t, part, f.generic_string()});
    write();
  }
  std::size_t size() const noexcept { return entries_.size(); }
  const std::filesystem::path& path() const noexcept { return path_; }

 private:
  struct entry {
    double t;
    int part;
    std::string file;
  };
  static std::string attribute(const std::string& line, const char* name) {
    const std::string key = std::string(name) + "=\"";
    const auto p = line.find(key);
    if (p == std::string::npos) return {};
    const auto q = line.find('"', p + key.size());
    return line.substr(p + key.size(), q - p - key.size());
  }
  void write() const {
    std::string s = "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"";
    s += detail::vtk_byte_order();
    s += "\">\n  <Collection>\n";
    char buf[64];
    for (const auto& e : entries_) {
      std::snprintf(buf, sizeof buf, "%.17g", e.t);
      s += "    <DataSet timestep=\"" + std::string(buf) + "\" group=\"\" part=\"" + std::to_string(e.part) +
           "\" file=\"" + e.file + "\"/>\n";
    }
    s += "  </Collection>\n</VTKFile>\n";
    io::write_file_atomic(path_, s);
  }
  std::filesystem::path path_;
  std::vector<entry> entries_;
};

}  // namespace parafsi::io
