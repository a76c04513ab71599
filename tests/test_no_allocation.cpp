// No heap allocation inside a step after the first steps of a run: global operator
// new/delete are replaced by counting versions in this test, small scenes take two
// warm-up steps (scratch buffers are sized then), and the next steps must allocate
// nothing — exactly zero calls of operator new — for the coupled stepper with each
// coupling, a fluid-only stepper (viscous + turbulent, far field with sponge, sources)
// and a structure-only stepper, and for the embedded coupling (one-sided faces, solved into
// records and replayed) on three levels of blocks. stable_dt() is counted too (it runs
// every step).
#include <doctest/doctest.h>

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/fluid/fluid.hpp>
#include <parafsi/model/rect_mesh.hpp>
#include <parafsi/structure/structure.hpp>

#include "coupling_test_util.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};

void* counted(std::size_t n, std::size_t align) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (n == 0) n = 1;
  void* p = align > alignof(std::max_align_t) ? std::aligned_alloc(align, (n + align - 1) / align * align)
                                              : std::malloc(n);
  if (!p) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t n) { return counted(n, 0); }
void* operator new[](std::size_t n) { return counted(n, 0); }
void* operator new(std::size_t n, std::align_val_t a) { return counted(n, std::size_t(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return counted(n, std::size_t(a)); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted(n, 0);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted(n, 0);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace pf = parafsi;
namespace st = pf::structure;

namespace {
/// Allocations made by `steps` calls of s.step(s.stable_dt()) after `warmup` uncounted ones.
template <class S>
long allocations_in_steps(S& s, int warmup, int steps) {
  for (int k = 0; k < warmup; ++k) s.step(s.stable_dt(0.5));
  g_allocations = 0;
  g_counting = true;
  for (int k = 0; k < steps; ++k) s.step(s.stable_dt(0.5));
  g_counting = false;
  return g_allocations.load();
}

/// A tilted 3 × 3 membrane patch (18 triangles) moving obliquely, free in space.
auto membrane() {
  const auto m = pf::model::rect_mesh({0.12, 0.1, 0.11}, {0.02, 0.18, 0.0}, {0.0, 0.03, 0.17}, 3, 3);
  st::nodes nd;
  for (const auto& x : m.positions) nd.add(x, {4.0, 1.0, -0.5});
  st::triangle_mesh tm;
  tm.triangles = m.triangles;
  st::membrane_tri mem{tm, st::material::fabric<>::isotropic(1e6, 0.3, 0.05, 1e-4)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity = {0, 0, -9.81};
  return as;
}

auto box() {
  auto bc = pf::boundary::set::all(pf::boundary::far_field{1.2, {0, 0, 0}, 101325.0});
  bc.layer = {2, 0.5};
  return pf::fluid::solver{pf::fluid::rectilinear_grid::uniform({8, 8, 8}, {0, 0, 0}, {0.4, 0.4, 0.4}), bc};
}
}  // namespace

TEST_CASE("a coupled step with the penalty coupling allocates nothing after warm-up") {
  pf::coupling::penalty_options o;
  o.damping_ratio = 0.1;
  o.stiffening = 0.25;
  pf::explicit_stepper s{box(), membrane(), pf::coupling::penalty{pf::porosity::impermeable{}, o}};
  CHECK(allocations_in_steps(s, 2, 4) == 0);
  CHECK(s.coupling().diagnostics().active_points > 0);
}

TEST_CASE("a coupled step with the embedded coupling allocates nothing after warm-up") {
  pf::explicit_stepper s{box(), membrane(), pf::coupling::embedded{pf::porosity::impermeable{}}};
  CHECK(allocations_in_steps(s, 2, 4) == 0);
  CHECK(s.coupling().diagnostics().faces > 0);
}

TEST_CASE("a coupled step with the one-sided embedded coupling on three levels of blocks allocates nothing") {
  auto s = ctu::blocks_patch(2, pf::coupling::embedded<pf::porosity::impermeable, true>{pf::porosity::impermeable{}});
  CHECK(allocations_in_steps(s, 2, 4) == 0);
  CHECK(s.coupling().diagnostics().faces > 0);
  CHECK(s.fluid().tree().finest_level() == 2);
}

TEST_CASE("a subcycled coupled step (one-sided embedded coupling, levels 1-2 of blocks) allocates nothing") {
  auto s = ctu::blocks_patch(2, pf::coupling::embedded<pf::porosity::impermeable, true>{pf::porosity::impermeable{}});
  for (int k = 0; k < 2; ++k) s.step_subcycled(s.stable_dt_subcycled(0.5));
  g_allocations = 0;
  g_counting = true;
  for (int k = 0; k < 4; ++k) s.step_subcycled(s.stable_dt_subcycled(0.5));
  g_counting = false;
  CHECK(g_allocations.load() == 0);
  CHECK(s.coupling().diagnostics().faces > 0);
  CHECK(s.fluid().finest_substeps() == 2);
}

TEST_CASE("a fluid-only step (viscous, turbulent, sponge, sources, moving box) allocates nothing after warm-up") {
  auto bc = pf::boundary::set::all(pf::boundary::far_field{1.2, {5.0, 0, 0}, 101325.0});
  bc.layer = {2, 0.5};
  pf::fluid::solver fl{pf::fluid::rectilinear_grid::uniform({10, 8, 6}, {0, 0, 0}, {0.5, 0.4, 0.3}), bc,
                       pf::viscosity::sutherland{}, pf::turbulence::smagorinsky{},
                       pf::frame::rigid{{1.0, 0.0, -2.0}, {0.0, 0.3, 0.0}}};
  fl.initialize([](const Eigen::Vector3d& x) {
    return pf::fluid::prim<double>{1.2, {5.0 + std::sin(9.0 * x[1]), 0.0, 0.0}, 101325.0};
  });
  fl.enable_sources();
  fl.source(0)[fl.index(3, 3, 3)] = 100.0;
  pf::explicit_stepper s{std::move(fl), pf::no_structure{}};
  CHECK(allocations_in_steps(s, 2, 4) == 0);
}

TEST_CASE("a structure-only step allocates nothing after warm-up") {
  pf::explicit_stepper s{pf::no_fluid{}, membrane()};
  CHECK(allocations_in_steps(s, 2, 20) == 0);
}

TEST_CASE("the counter sees the first step's allocations (row buffers, scratch)") {
  pf::explicit_stepper s{box(), pf::no_structure{}};
  CHECK(allocations_in_steps(s, 0, 1) > 0);
}
