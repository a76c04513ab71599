/// \file block_vtk.hpp
/// VTK output and mid-plane slices of the block-structured fluid mesh (fluid::block_solver),
/// the counterparts of io/vtk.hpp's write_vts and write_midplane_csv for the box solver.
///
///   write_vtu(path, block_solver)          every leaf cell → one UnstructuredGrid (.vtu)
///   write_vtu(path, block_solver, opt, r)  the leaf cells of blocks r = [first, last) only
///   write_pvtu_piece(path, block_solver, opt, piece, pieces)
///                                          piece `piece` of `pieces` (one per process) and,
///                                          from piece 0, the index (.pvtu) that joins them
///   write_midplane_csv(path, block_solver) mid-plane slice from the leaf cells → CSV
///   vorticity(block_solver)                inertial vorticity of every leaf cell
///
/// UnstructuredGrid: one VTK_HEXAHEDRON (12) per leaf cell, blocks in tree order, cells
/// x-fastest within a block. The points are the cell corners (face coordinates ξ) mapped to
/// inertial coordinates x = X + R ξ with the current box pose, each corner written ONCE:
/// a corner is identified by its integer index on the finest level's lattice (faces are
/// computed from the level-global face index, so a corner shared by blocks of any levels has
/// the same coordinates in all of them), so ParaView's Cell Data to Point Data averages
/// across block boundaries without seams and the file holds about one point per cell
/// instead of eight. Coarse cells do not reference the hanging corners of their finer
/// neighbours (the mesh is non-conforming there; every cell is a plain hexahedron). Cell
/// data, as write_vts: `density`, `velocity` (inertial), `pressure` (+ pressure_offset),
/// `vorticity`; and `level` (the block's refinement level, 0 = root) and `block` (leaf id).
/// Field data TIME. Encodings and the atomic write as in vtk.hpp.
///
/// Pieces (a distributed run, mpi/): the blocks in tree order are cut into `pieces`
/// contiguous runs of equal length (piece_blocks; block counts differ by at most one, so
/// the cells do too: every block has n³), and each process writes its run as
/// `<stem>_<piece>.vtu`, the same file write_vtu would write for those blocks (corners shared
/// within the piece, each piece its own points; the cell data of the pieces in piece order
/// are the whole mesh's, value for value). Piece 0 also writes `<stem>.pvtu`, a
/// PUnstructuredGrid naming the arrays and the pieces (paths relative to the index), which
/// ParaView opens as one data set (and which a .pvd can list). Every process must hold the
/// current state of the blocks its piece and their face neighbours: block_solver::fetch(
/// s.with_face_neighbours(piece's blocks)) brings just those (or gather() every block).
///
/// Vorticity: the box-frame velocity û = Rᵀu of a leaf cell and of its six face
/// neighbours (the leaf cells holding the points ξ_c ± h_d e_d, of any level) gives the
/// least-squares gradient G = (Σ Δû Δξᵀ)(Σ Δξ Δξᵀ)⁻¹ over the centre offsets Δξ, exact for
/// linear fields across level interfaces; between same-level neighbours it is the central
/// difference of write_vts, one-sided at the box faces (no ghost cells, no periodic wrap).
/// ω̂ = ∇_ξ × û, ω = R ω̂.
///
/// Mid-plane CSV: header `x,y,z,rho,u,v,w,p,vorticity_normal` as write_midplane_csv; one row
/// per leaf cell cut by the plane ξ_a = position (cells with face_lo ≤ position < face_hi;
/// the box's upper face counts for its top layer), blocks in tree order, the lower
/// remaining box axis fastest within a block. The row's point is the cell's centre moved
/// onto the plane; its values are interpolated linearly along the normal between the cell
/// and the leaf cell one cell width across the plane (their centres' normal coordinates as
/// the abscissae): the box solver's interpolation between same-level cells, exact for
/// fields linear along the normal across level interfaces. Beyond the box's outermost
/// centres the cell's own value is taken.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "../core/error.hpp"
#include "../fluid/block_solver.hpp"
#include "../fluid/gas.hpp"
#include "../fluid/state.hpp"
#include "checked_file.hpp"
#include "vtk.hpp"

namespace parafsi::io {

namespace detail {

/// Primitive state of cell (i, j, k) of a leaf block (what block_solver::sample returns).
template <class Block>
fluid::prim<double> block_cell_prim(const Block& b, index_t c, const gas::ideal& gas) {
  using namespace fluid::field;
  const fluid::cons<double> q{b.U.template get<rho>()[c],
                              {b.U.template get<mx>()[c], b.U.template get<my>()[c], b.U.template get<mz>()[c]},
                              b.U.template get<E>()[c]};
  return fluid::to_prim(q, gas);
}

/// Position of leaf cell (i, j, k) of block `id` in the leaf-cell order of the writers.
inline std::size_t leaf_cell(index_t id, index_t n, index_t i, index_t j, index_t k) noexcept {
  return std::size_t(((id * n + k) * n + j) * n + i);
}

struct lattice_hash {
  std::size_t operator()(const std::array<std::int64_t, 3>& p) const noexcept {
    std::uint64_t h = std::uint64_t(p[0]) * 0x9E3779B97F4A7C15ull;
    h ^= std::uint64_t(p[1]) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
    h ^= std::uint64_t(p[2]) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
    return std::size_t(h);
  }
};

}  // namespace detail

/// Blocks [first, last) of the tree order; the default (last < 0) is every block.
struct block_range {
  index_t first = 0, last = -1;
};

namespace detail {
inline block_range whole(block_range r, index_t nb) {
  if (r.last < 0) r.last = nb;
  require(r.first >= 0 && r.first <= r.last && r.last <= nb, "io::block_range: blocks [", r.first, ", ", r.last,
          ") outside the mesh's [0, ", nb, ")");
  return r;
}
}  // namespace detail

/// Piece `piece` of `pieces`: the blocks in tree order cut into `pieces` contiguous runs
/// whose lengths differ by at most one.
inline block_range piece_blocks(index_t blocks, int piece, int pieces) {
  require(pieces >= 1 && piece >= 0 && piece < pieces, "io::piece_blocks: piece ", piece, " of ", pieces);
  return {blocks * piece / pieces, blocks * (piece + 1) / pieces};
}

/// Inertial vorticity ω = R (∇_ξ × Rᵀu) of every leaf cell, 3 values per cell, blocks in
/// tree order, x fastest within a block (see the file comment for the gradient).
/// With a range r, the cells of blocks [r.first, r.last) only (they read their neighbours).
template <class F, class Rc, class Tu, class Vi, class Fr, class Ti>
std::vector<double> vorticity(const fluid::block_solver<F, Rc, Tu, Vi, Fr, Ti>& s, block_range r = {}) {
  const index_t n = s.block_cells(), nb = s.block_count();
  r = detail::whole(r, nb);
  const Eigen::Matrix3d R = s.pose().R;
  // The box-frame velocity of the blocks the range reads (its own and their face
  // neighbours), each block's once, when first needed: memory for those blocks only (a
  // process writing its piece holds only them, block_solver::fetch).
  const std::size_t n3 = std::size_t(n * n * n);
  std::vector<index_t> slot(std::size_t(nb), -1);
  std::vector<Eigen::Vector3d> ubs;
  auto ub_of = [&](index_t id, std::size_t local) -> const Eigen::Vector3d& {
    if (slot[std::size_t(id)] < 0) {
      slot[std::size_t(id)] = index_t(ubs.size() / n3);
      const auto& b = s.block_at(id);
      for (index_t k = 0; k < n; ++k)
        for (index_t j = 0; j < n; ++j)
          for (index_t i = 0; i < n; ++i) {
            const auto w = detail::block_cell_prim(b, b.grid.index(i, j, k), s.gas());
            ubs.push_back(R.transpose() * Eigen::Vector3d(w.u.x, w.u.y, w.u.z));
          }
    }
    return ubs[std::size_t(slot[std::size_t(id)]) * n3 + local];
  };
  auto local_of = [&](index_t i, index_t j, index_t k) { return std::size_t(i + n * (j + n * k)); };
  const std::size_t skip = 3 * detail::leaf_cell(r.first, n, 0, 0, 0);
  std::vector<double> out(3 * detail::leaf_cell(r.last, n, 0, 0, 0) - skip);
  for (index_t id = r.first; id < r.last; ++id) {
    const auto& b = s.block_at(id);
    const auto& g = b.grid;
    for (index_t k = 0; k < n; ++k)
      for (index_t j = 0; j < n; ++j)
        for (index_t i = 0; i < n; ++i) {
          const index_t ijk[3] = {i, j, k};
          const Eigen::Vector3d xc(g.centre(0, i), g.centre(1, j), g.centre(2, k));
          const std::size_t self = detail::leaf_cell(id, n, i, j, k);
          Eigen::Matrix3d M = Eigen::Matrix3d::Zero(), B = Eigen::Matrix3d::Zero();
          for (int d = 0; d < 3; ++d)
            for (int sgn = -1; sgn <= 1; sgn += 2) {
              index_t q[3] = {i, j, k};
              q[d] += sgn;
              Eigen::Vector3d xn;
              index_t other_block = id;
              std::size_t other;
              if (q[d] >= 0 && q[d] < n) {  // inside the block
                xn = {g.centre(0, q[0]), g.centre(1, q[1]), g.centre(2, q[2])};
                other = local_of(q[0], q[1], q[2]);
              } else {
                Eigen::Vector3d p = xc;
                p[d] += sgn * g.width(d, ijk[d]);
                const auto [nid, nc] = s.locate(p);
                if (nid < 0) continue;  // box face: one-sided
                const auto& gn = s.block_at(nid).grid;
                const auto a = gn.ijk(nc);
                xn = {gn.centre(0, a[0]), gn.centre(1, a[1]), gn.centre(2, a[2])};
                other_block = nid;
                other = local_of(a[0], a[1], a[2]);
              }
              const Eigen::Vector3d u_other = ub_of(other_block, other);
              const Eigen::Vector3d dx = xn - xc, du = u_other - ub_of(id, local_of(i, j, k));
              M += dx * dx.transpose();
              B += du * dx.transpose();
            }
          const Eigen::Matrix3d G = B * M.inverse();  // G(a, d) = ∂û_a/∂ξ_d
          const Eigen::Vector3d wi = R * Eigen::Vector3d(G(2, 1) - G(1, 2), G(0, 2) - G(2, 0), G(1, 0) - G(0, 1));
          out[3 * self - skip] = wi.x();
          out[3 * self + 1 - skip] = wi.y();
          out[3 * self + 2 - skip] = wi.z();
        }
  }
  return out;
}

/// The block mesh's leaf cells as one VTK UnstructuredGrid of hexahedra (see the file
/// comment: shared inertial corner points, cell data as write_vts plus `level`, `block`).
/// With a range r, the leaf cells of blocks [r.first, r.last) only (a piece).
template <class F, class Rc, class Tu, class Vi, class Fr, class Ti>
void write_vtu(const std::filesystem::path& path, const fluid::block_solver<F, Rc, Tu, Vi, Fr, Ti>& s,
               const vtk_options& opt = {}, block_range r = {}) {
  const index_t n = s.block_cells();
  r = detail::whole(r, s.block_count());
  const index_t nb = r.last - r.first;
  const int top = s.tree().finest_level();
  const auto& pose = s.pose();
  const std::size_t cells = std::size_t(nb * n * n * n);
  std::vector<double> pts, rho, vel, p;
  std::vector<std::int64_t> conn, offs;
  std::vector<std::int32_t> level, block;
  pts.reserve(3 * cells + 3 * std::size_t(nb) * std::size_t(6 * n * n));
  conn.reserve(8 * cells);
  offs.reserve(cells);
  rho.reserve(cells);
  vel.reserve(3 * cells);
  p.reserve(cells);
  level.reserve(cells);
  block.reserve(cells);
  // Corners on a block's surface may be shared with other blocks: found by their index on
  // the finest lattice; interior corners are new.
  std::unordered_map<std::array<std::int64_t, 3>, std::int64_t, detail::lattice_hash> surface;
  const index_t m = n + 1;
  std::vector<std::int64_t> local(std::size_t(m * m * m));
  for (index_t id = r.first; id < r.last; ++id) {
    const auto& b = s.block_at(id);
    const auto& g = b.grid;
    const int shift = top - b.where.level;
    for (index_t k = 0; k <= n; ++k)
      for (index_t j = 0; j <= n; ++j)
        for (index_t i = 0; i <= n; ++i) {
          const std::int64_t next = std::int64_t(pts.size() / 3);
          std::int64_t pid = next;
          if (i == 0 || j == 0 || k == 0 || i == n || j == n || k == n) {
            const std::array<std::int64_t, 3> key{(b.where.l[0] * n + i) << shift, (b.where.l[1] * n + j) << shift,
                                                  (b.where.l[2] * n + k) << shift};
            pid = surface.try_emplace(key, next).first->second;
          }
          local[std::size_t(i + m * (j + m * k))] = pid;
          if (pid == next) {
            const Eigen::Vector3d x = pose.to_inertial({g.face(0, i), g.face(1, j), g.face(2, k)});
            pts.insert(pts.end(), {x.x(), x.y(), x.z()});
          }
        }
    for (index_t k = 0; k < n; ++k)
      for (index_t j = 0; j < n; ++j)
        for (index_t i = 0; i < n; ++i) {
          auto at = [&](index_t a, index_t bb, index_t c) {
            return local[std::size_t(i + a + m * (j + bb + m * (k + c)))];
          };
          conn.insert(conn.end(), {at(0, 0, 0), at(1, 0, 0), at(1, 1, 0), at(0, 1, 0), at(0, 0, 1), at(1, 0, 1),
                                   at(1, 1, 1), at(0, 1, 1)});
          offs.push_back(std::int64_t(conn.size()));
          const auto w = detail::block_cell_prim(b, g.index(i, j, k), s.gas());
          rho.push_back(w.rho);
          vel.insert(vel.end(), {w.u.x, w.u.y, w.u.z});
          p.push_back(w.p + opt.pressure_offset);
          level.push_back(std::int32_t(b.where.level));
          block.push_back(std::int32_t(id));
        }
  }
  const std::vector<double> vort = vorticity(s, r);
  const std::vector<std::uint8_t> types(cells, std::uint8_t(12));  // VTK_HEXAHEDRON
  detail::xml_out x(opt.encoding);
  std::string out = detail::vtk_header("UnstructuredGrid");
  out += "  <UnstructuredGrid>\n";
  out += detail::time_field_data(s.time(), x);
  out += "    <Piece NumberOfPoints=\"" + std::to_string(pts.size() / 3) + "\" NumberOfCells=\"" +
         std::to_string(cells) + "\">\n";
  x.s.clear();
  x.array("density", 1, rho, 8);
  x.array("velocity", 3, vel, 8);
  x.array("pressure", 1, p, 8);
  x.array("vorticity", 3, vort, 8);
  x.array("level", 1, level, 8);
  x.array("block", 1, block, 8);
  out += "      <CellData Scalars=\"pressure\" Vectors=\"velocity\">\n" + x.s + "      </CellData>\n";
  out += detail::vtu_points_cells_end(x, pts, conn, offs, types);
  io::write_file_atomic(path, out);
}

/// The piece files of the index `pvtu` (…/stem.pvtu → …/stem_<piece>.vtu).
inline std::filesystem::path piece_path(const std::filesystem::path& pvtu, int piece) {
  std::filesystem::path p = pvtu;
  p.replace_filename(pvtu.stem().string() + "_" + std::to_string(piece) + ".vtu");
  return p;
}

/// Piece `piece` of `pieces` of the block mesh (piece_blocks) as piece_path(pvtu, piece),
/// and from piece 0 the index `pvtu` joining them all (see the file comment). Call it on
/// every process with its rank and the process count.
template <class F, class Rc, class Tu, class Vi, class Fr, class Ti>
void write_pvtu_piece(const std::filesystem::path& pvtu, const fluid::block_solver<F, Rc, Tu, Vi, Fr, Ti>& s,
                      const vtk_options& opt, int piece, int pieces) {
  require(pvtu.extension() == ".pvtu", "io::write_pvtu_piece: the index must be a .pvtu file, got '", pvtu.string(),
          "'");
  write_vtu(piece_path(pvtu, piece), s, opt, piece_blocks(s.block_count(), piece, pieces));
  if (piece != 0) return;
  auto array = [](const char* type, const char* name, int components) {
    std::string a = "      <PDataArray type=\"";
    a += type;
    a += "\"";
    a += std::string(" Name=\"") + name + "\"";
    if (components > 1) a += " NumberOfComponents=\"" + std::to_string(components) + "\"";
    return a + "/>\n";
  };
  std::string out = detail::vtk_header("PUnstructuredGrid");
  out += "  <PUnstructuredGrid GhostLevel=\"0\">\n";
  out += "    <PCellData Scalars=\"pressure\" Vectors=\"velocity\">\n";
  const char* f64 = detail::vtk_type_name<double>();
  const char* i32 = detail::vtk_type_name<std::int32_t>();
  out += array(f64, "density", 1);
  out += array(f64, "velocity", 3);
  out += array(f64, "pressure", 1);
  out += array(f64, "vorticity", 3);
  out += array(i32, "level", 1);
  out += array(i32, "block", 1);
  out += "    </PCellData>\n    <PPoints>\n";
  out += array(f64, "Points", 3);
  out += "    </PPoints>\n";
  for (int q = 0; q < pieces; ++q) out += "    <Piece Source=\"" + piece_path(pvtu, q).filename().string() + "\"/>\n";
  out += "  </PUnstructuredGrid>\n</VTKFile>\n";
  io::write_file_atomic(pvtu, out);
}

/// Mid-plane slice of the leaf cells as CSV `x,y,z,rho,u,v,w,p,vorticity_normal` (see the
/// file comment). Returns the number of rows written.
template <class F, class Rc, class Tu, class Vi, class Fr, class Ti>
std::size_t write_midplane_csv(const std::filesystem::path& path, const fluid::block_solver<F, Rc, Tu, Vi, Fr, Ti>& s,
                               const midplane_options& opt = {}) {
  require(opt.normal_axis >= 0 && opt.normal_axis < 3, "io::write_midplane_csv: normal_axis must be 0, 1 or 2, got ",
          opt.normal_axis);
  // The same axis, in a form the compiler sees in range (GCC 12's -Warray-bounds does not
  // follow the check above through the inlined loops).
  const int a = std::clamp(opt.normal_axis, 0, 2);
  const double lo = s.layout().lo[std::size_t(a)], hi = s.layout().hi[std::size_t(a)];
  const double xp = std::isnan(opt.position) ? 0.5 * (lo + hi) : opt.position;
  require(xp >= lo && xp <= hi, "io::write_midplane_csv: plane position ", xp, " outside the box [", lo, ", ", hi,
          "] along axis ", a);
  const index_t n = s.block_cells();
  const std::vector<double> vort = vorticity(s);
  const auto& pose = s.pose();
  const Eigen::Vector3d nrm = pose.R.col(a);
  const int bx = a == 0 ? 1 : 0, cx = a == 2 ? 1 : 2;  // remaining axes, bx < cx
  std::string out = "x,y,z,rho,u,v,w,p,vorticity_normal\n";
  char buf[64];
  auto num = [&](double v, bool last) {
    std::snprintf(buf, sizeof buf, "%.10g", v);
    out += buf;
    out += last ? '\n' : ',';
  };
  std::size_t rows = 0;
  for (index_t id = 0; id < s.block_count(); ++id) {
    const auto& b = s.block_at(id);
    const auto& g = b.grid;
    if (!(g.face(a, 0) <= xp && (xp < g.face(a, n) || (xp == hi && g.face(a, n) == hi)))) continue;
    index_t layer = 0;  // the block's cell layer holding the plane
    while (layer + 1 < n && g.face(a, layer + 1) <= xp) ++layer;
    for (index_t jc = 0; jc < n; ++jc)
      for (index_t jb = 0; jb < n; ++jb) {
        index_t ijk[3];
        ijk[a] = layer;
        ijk[bx] = jb;
        ijk[cx] = jc;
        const index_t c0 = g.index(ijk[0], ijk[1], ijk[2]);
        const std::size_t v0 = detail::leaf_cell(id, n, ijk[0], ijk[1], ijk[2]);
        Eigen::Vector3d xi(g.centre(0, ijk[0]), g.centre(1, ijk[1]), g.centre(2, ijk[2]));
        const double ca = xi[a];
        // The leaf cell one width across the plane, and the weight of its value.
        Eigen::Vector3d q = xi;
        q[a] += xp >= ca ? g.width(a, layer) : -g.width(a, layer);
        const auto [nid, nc] = s.locate(q);
        double w1 = 0.0;
        fluid::prim<double> p1 = detail::block_cell_prim(b, c0, s.gas());
        std::size_t v1 = v0;
        if (nid >= 0 && xp != ca) {
          const auto& gn = s.block_at(nid).grid;
          const auto t = gn.ijk(nc);
          w1 = (xp - ca) / (gn.centre(a, t[std::size_t(a)]) - ca);
          p1 = detail::block_cell_prim(s.block_at(nid), nc, s.gas());
          v1 = detail::leaf_cell(nid, n, t[0], t[1], t[2]);
        }
        const fluid::prim<double> p0 = detail::block_cell_prim(b, c0, s.gas());
        auto mix = [&](double u0, double u1) { return (1 - w1) * u0 + w1 * u1; };
        Eigen::Vector3d om;
        for (int r = 0; r < 3; ++r) om[r] = mix(vort[3 * v0 + std::size_t(r)], vort[3 * v1 + std::size_t(r)]);
        xi[a] = xp;
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
  }
  io::write_file_atomic(path, out);
  return rows;
}

}  // namespace parafsi::io
