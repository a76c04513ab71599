// Shared set-ups for the membrane tests (triangle and quad): square test meshes, a
// stand-alone element on a node set, the patch-test map, the rigid-rotation, SIMD /
// thread, folded-start checks and the clamped Föppl–Hencky disk.
#pragma once
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include <parafsi/core/parallel.hpp>
#include <parafsi/model/disk_mesh.hpp>
#include <parafsi/structure/assembly.hpp>
#include <parafsi/structure/membrane_quad.hpp>
#include <parafsi/structure/membrane_tri.hpp>
#include <parafsi/structure/reference/hencky.hpp>
#include <parafsi/structure/relax.hpp>

namespace mrig {
namespace st = parafsi::structure;
using parafsi::index_t;

/// Nodes of the unit square, (n+1)² in rows of constant y; `perturb(i, j, p)` moves node (i, j).
template <class Perturb>
std::vector<Eigen::Vector3d> square_nodes(int n, Perturb perturb) {
  std::vector<Eigen::Vector3d> X;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      Eigen::Vector3d p{double(i) / n, double(j) / n, 0.0};
      perturb(i, j, p);
      X.push_back(p);
    }
  return X;
}

inline bool interior(int i, int j, int n) { return i > 0 && i < n && j > 0 && j < n; }

/// Unit square, n×n cells, interior nodes perturbed by up to `jitter`/n, two triangles per cell.
inline st::triangle_mesh square_mesh(int n, std::vector<Eigen::Vector3d>& X, double jitter, unsigned seed = 7) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  X = square_nodes(n, [&](int i, int j, Eigen::Vector3d& p) {
    if (interior(i, j, n)) p += Eigen::Vector3d{u(g), u(g), 0.0} / n;
  });
  st::triangle_mesh m;
  auto id = [&](int i, int j) { return index_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      m.triangles.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      m.triangles.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return m;
}

/// Unit square, n×n quads, interior nodes perturbed by up to `jitter` cells in plane and
/// every node by up to `zjitter` cells out of plane.
inline st::quad_mesh square_quads(int n, std::vector<Eigen::Vector3d>& X, double jitter, double zjitter = 0.0,
                                  unsigned seed = 7) {
  std::mt19937 g(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  X = square_nodes(n, [&](int i, int j, Eigen::Vector3d& p) {
    if (interior(i, j, n)) p += Eigen::Vector3d{jitter * u(g), jitter * u(g), 0.0} / n;
    p.z() += zjitter * u(g) / n;
  });
  st::quad_mesh m;
  auto id = [&](int i, int j) { return index_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) m.quads.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return m;
}

/// R = Rz(a) Ry(b) Rx(c).
inline Eigen::Matrix3d rotation(double a, double b, double c) {
  return (Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(b, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

/// A stand-alone membrane part (membrane_tri or membrane_quad) on a node set (no assembly),
/// forces evaluated directly.
template <class Element>
struct rig {
  st::nodes nd;
  Element mem;
  template <class Mesh, class Fabric, class... Options>
  rig(const std::vector<Eigen::Vector3d>& X, Mesh m, Fabric f, Options... o) : mem(std::move(m), f, o...) {
    for (const auto& x : X) nd.add(x);
    nd.materialize();
    nd.reset_masses();
    mem.finalize(nd);
    nd.finalize_masses();
  }
  void place(const std::vector<Eigen::Vector3d>& x) {
    for (std::size_t i = 0; i < x.size(); ++i) nd.set_position(index_t(i), x[i]);
  }
  template <bool Vectorize = true>
  std::vector<Eigen::Vector3d> forces() {
    auto& s = nd.data();
    for (index_t i = 0; i < nd.size(); ++i)
      s.get<st::field::fx>()[i] = s.get<st::field::fy>()[i] = s.get<st::field::fz>()[i] = 0;
    mem.template compute_forces<false, Vectorize>(nd.kinematics());
    mem.template scatter<false>(nd);
    std::vector<Eigen::Vector3d> f;
    for (index_t i = 0; i < nd.size(); ++i) f.push_back(nd.force(i));
    return f;
  }
};
template <class Fabric>
rig(const std::vector<Eigen::Vector3d>&, st::triangle_mesh, Fabric) -> rig<st::membrane_tri<Fabric>>;
template <class Fabric, class... Options>
rig(const std::vector<Eigen::Vector3d>&, st::quad_mesh, Fabric, Options...) -> rig<st::membrane_quad<Fabric>>;

/// The patch-test map x = R (F0 X) + c: a general in-plane F0, a 3-D rigid rotation R, and
/// the exact Green strain it gives in the fibre axes (e1 = warp at `warp_angle`, e2 = z × e1).
struct patch_map {
  Eigen::Matrix3d F0 = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d R = rotation(0.7, -0.4, 1.1);
  double E11 = 0, E22 = 0, E12x2 = 0;
  explicit patch_map(double warp_angle) {
    F0(0, 0) = 1.02;
    F0(0, 1) = 0.013;
    F0(1, 0) = 0.004;
    F0(1, 1) = 0.985;
    const Eigen::Matrix3d Eg = 0.5 * (F0.transpose() * F0 - Eigen::Matrix3d::Identity());
    const Eigen::Vector3d e1{std::cos(warp_angle), std::sin(warp_angle), 0},
        e2{-std::sin(warp_angle), std::cos(warp_angle), 0};
    E11 = e1.dot(Eg * e1);
    E22 = e2.dot(Eg * e2);
    E12x2 = 2 * e1.dot(Eg * e2);
  }
  std::vector<Eigen::Vector3d> operator()(const std::vector<Eigen::Vector3d>& X) const {
    std::vector<Eigen::Vector3d> x;
    for (const auto& p : X) x.push_back(R * (F0 * p) + Eigen::Vector3d{0.3, -2.0, 5.0});
    return x;
  }
  /// Largest deviation of an element's strain (strain_stress()[0..2]) from the exact one.
  double strain_error(const std::array<double, 6>& ss) const {
    return std::max({std::abs(ss[0] - E11), std::abs(ss[1] - E22), std::abs(ss[2] - E12x2)});
  }
};

/// Largest nodal force on the whole (n+1)² square and on its interior nodes.
struct residual {
  double max_force = 0, max_interior = 0;
};
inline residual square_residual(const std::vector<Eigen::Vector3d>& f, int n) {
  residual r;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double m = f[std::size_t(j * (n + 1) + i)].norm();
      r.max_force = std::max(r.max_force, m);
      if (interior(i, j, n)) r.max_interior = std::max(r.max_interior, m);
    }
  return r;
}

/// Largest |E| (first three components) and |S| / 1e9 Pa (last three) over the elements.
template <class Rig>
double max_strain_stress(const Rig& r) {
  double smax = 0;
  for (index_t e = 0; e < r.mem.size(); ++e) {
    const auto ss = r.mem.strain_stress(r.nd, e);
    for (int k = 0; k < 6; ++k) smax = std::max(smax, std::abs(ss[std::size_t(k)]) / (k < 3 ? 1.0 : 1e9));
  }
  return smax;
}

inline double max_norm(const std::vector<Eigen::Vector3d>& f) {
  double m = 0;
  for (const auto& v : f) m = std::max(m, v.norm());
  return m;
}

/// SIMD and scalar kernels agree to 1e-12 of the largest force; with OpenMP, one and two
/// threads give identical forces.
template <class Rig>
void check_simd_and_threads(Rig& r, const char* label) {
  const auto fv = r.template forces<true>();
  const auto fs = r.template forces<false>();
  double diff = 0, scale = 0;
  for (std::size_t i = 0; i < fv.size(); ++i) {
    diff = std::max(diff, (fv[i] - fs[i]).norm());
    scale = std::max(scale, fs[i].norm());
  }
  std::printf("%sSIMD (width %zu) vs scalar: max diff %.3e of %.3e\n", label, parafsi::simd::width, diff, scale);
  CHECK(scale > 0);
  CHECK(diff <= 1e-12 * scale);
  if (parafsi::parallel::enabled()) {
    parafsi::parallel::set_threads(1);
    const auto f1 = r.template forces<true>();
    parafsi::parallel::set_threads(2);
    const auto f2 = r.template forces<true>();
    bool same = true;
    for (std::size_t i = 0; i < f1.size(); ++i) same = same && f1[i] == f2[i];
    CHECK(same);
    parafsi::parallel::set_threads(1);
  }
}

/// Disk positions 1.01 x + uniform noise of ±0.01 m (generator seeded 11); the generator
/// is returned for further draws.
inline std::vector<Eigen::Vector3d> stretched_noisy(const std::vector<Eigen::Vector3d>& X, std::mt19937& g) {
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  std::vector<Eigen::Vector3d> x;
  for (const auto& p : X) x.push_back(1.01 * p + Eigen::Vector3d{u(g), u(g), u(g)});
  return x;
}

/// Folded start: a flat disk (the cut pattern) folded radially to 30 % with a corrugation,
/// the rim held at its folded position (like a skirt gathered by the lines).
inline st::nodes folded_disk(const std::vector<Eigen::Vector3d>& X, const std::vector<index_t>& rim) {
  st::nodes nd;
  for (const auto& p : X) {
    const double r = std::hypot(p.x(), p.y()), th = std::atan2(p.y(), p.x());
    nd.add({0.3 * p.x(), 0.3 * p.y(), 0.02 * std::sin(8 * th) * r});
  }
  for (auto i : rim) nd.pin(i);
  return nd;
}

struct folded_result {
  double U0 = 0, apex = 0, emin = 0, emax = 0;
  long max_substeps = 0;
};

/// Pressure 200 Pa inflates the slack bag, mass damping 30/s brings it to rest by 0.3 s;
/// `before` runs on the assembly after the initial force evaluation.
template <class Asm, class Before>
folded_result run_folded(Asm& s, index_t apex_node, Before before) {
  s.template part<0>().set_pressure(200.0);
  s.integrator().gravity.setZero();
  s.integrator().mass_damping = 30.0;
  s.track_energy();
  folded_result r;
  r.U0 = s.evaluate_forces();  // the folded start stores some (residual) strain energy
  before(s);
  while (s.time() < 0.3) r.max_substeps = std::max(r.max_substeps, s.advance(1e-3));
  for (index_t e = 0; e < s.template part<0>().size(); ++e) {
    const auto ss = s.template part<0>().strain_stress(s.node_set(), e);
    r.emax = std::max({r.emax, ss[0], ss[1]});
    r.emin = std::min({r.emin, ss[0], ss[1]});
  }
  r.apex = s.node_set().position(apex_node).z();
  return r;
}

/// Inflated into a bag (slack length 0.35 m from rim to apex), taut parts at small strain,
/// much of the fabric still slack, close to rest, energy accounted for within 5 %.
inline void check_folded(const folded_result& r, const st::energy_ledger& E) {
  const double input = r.U0 + E.external;
  CHECK(r.apex > 0.2);
  CHECK(r.emax < 0.02);
  CHECK(r.emin < -0.1);
  CHECK(E.kinetic < 1e-3 * input);
  CHECK(std::abs(E.balance() - r.U0) < 0.05 * input);
}

/// Clamped circular membrane (radius a, thickness h, modulus E, Poisson ν) under pressure p,
/// relaxed by mass damping at twice the first-mode frequency of the Hencky prestress.
struct hencky_case {
  double a = 0.5, h = 1e-4, E = 1e9, nu = 0.3, p = 40.0;
  double w_ref() const { return st::reference::hencky(nu).coefficient * a * std::cbrt(p * a / (E * h)); }
  double omega1() const {
    const double sigma = st::reference::hencky(nu).s0 * std::cbrt(E * p * p * a * a / (8 * h * h));
    return 2.405 * std::sqrt(sigma / 1000.0) / a;
  }
  template <class Asm>
  void relax(Asm& s) const {
    s.integrator().gravity.setZero();
    s.integrator().mass_damping = 2 * omega1();
    st::relax_options ro;
    ro.tolerance = 1e-14;
    ro.t_min = 6.3 / omega1();
    ro.t_max = 400 / omega1();
    REQUIRE(st::relax(s, ro).converged);
  }
  auto fabric() const { return st::material::fabric<>::isotropic(E, nu, 1000 * h, h); }

  /// Centre deflection of the CST disk with 6 rings² triangles.
  double tri_deflection(int rings) const {
    const auto d = parafsi::model::disk_mesh(a, rings);
    st::nodes nd;
    for (const auto& x : d.positions) nd.add(x);
    for (auto i : d.rim) nd.pin(i);
    st::triangle_mesh m;
    m.triangles = d.triangles;
    st::membrane_tri mem{m, fabric()};
    mem.set_pressure(p);
    st::assembly s{std::move(nd), std::move(mem)};
    relax(s);
    return s.node_set().position(0).z();
  }
};

}  // namespace mrig
