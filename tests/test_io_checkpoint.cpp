// Checkpoint/restart: a run restored from a checkpoint continues bit for bit; bad files
// are refused with messages naming what differs.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/fluid/fluid.hpp>
#include <parafsi/io/checkpoint.hpp>
#include <parafsi/model/rect_mesh.hpp>
#include <parafsi/structure/structure.hpp>

namespace fs = std::filesystem;
namespace pf = parafsi;
namespace st = pf::structure;
using pf::index_t;

namespace {
fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "parafsi_test_io_checkpoint";
  fs::create_directories(d);
  return d / name;
}
std::vector<unsigned char> bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void write_bytes(const fs::path& p, const std::vector<unsigned char>& b) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size()));
}
bool same_bits(const double* a, const double* b, std::size_t n) { return std::memcmp(a, b, n * sizeof(double)) == 0; }
// File layout: 19-byte magic, u32 version, u32 byte order, u64 payload length, payload, u64 checksum.
constexpr std::size_t payload_at = 19 + 16;
/// Replace the entry name `from` by `to` (same length) and re-seal the checksum: a file
/// that is intact but written with another field name.
std::vector<unsigned char> rename_entry(std::vector<unsigned char> b, const std::string& from, const std::string& to) {
  REQUIRE(from.size() == to.size());
  const auto it = std::search(b.begin(), b.end(), from.begin(), from.end());
  REQUIRE(it != b.end());
  std::copy(to.begin(), to.end(), it);
  const std::uint64_t sum = pf::io::ckpt::fnv1a(b.data() + payload_at, b.size() - payload_at - 8);
  std::memcpy(b.data() + b.size() - 8, &sum, 8);
  return b;
}

// ---- fluid: viscous + Smagorinsky on a stretched grid, a box following a turning
// target, a source field; the step comes from stable_dt (reads μ_t).
auto make_fluid(index_t nx = 12) {
  const auto grid = pf::fluid::rectilinear_grid(pf::fluid::axis::refined(-1.0, 1.0, -0.3, 0.3, 0.12, 1.25),
                                                pf::fluid::axis::uniform(nx, -0.8, 0.8),
                                                pf::fluid::axis::uniform(8, -1.0, 0.6));
  pf::frame::follow_payload fp;
  fp.min_speed = 0.1;
  pf::fluid::solver s{grid, pf::boundary::set::all(pf::boundary::far_field{}), fp, pf::turbulence::smagorinsky{},
                      pf::viscosity::constant{}};
  s.initialize([](const Eigen::Vector3d& x) {
    const double r2 = x.squaredNorm();
    return pf::fluid::prim<double>{1.18 * (1 + 0.05 * std::exp(-8 * r2)),
                                   {20 * x.y() * std::exp(-4 * r2), -20 * x.x() * std::exp(-4 * r2), 3.0},
                                   101325.0 * (1 + 0.03 * std::exp(-10 * r2))};
  });
  s.enable_sources();
  const index_t c = s.grid().index(3, 4, 2);
  s.source(2)[c] = -400.0;
  s.source(3)[c] = 50.0;
  s.source_mass()[c] = 0.1;
  return s;
}
Eigen::Vector3d target_x(double t) { return {0.3 * std::sin(4 * t), 0.1 * t, -6.0 * t}; }
Eigen::Vector3d target_v(double t) { return {1.2 * std::cos(4 * t), 0.1, -6.0}; }
template <class S>
void fluid_steps(S& s, int n) {
  for (int i = 0; i < n; ++i) {
    const double dt = s.stable_dt(0.45);
    s.frame().track(target_x(s.time() + dt), target_v(s.time() + dt));
    s.step(dt);
  }
}
template <class S>
void require_same_fluid(const S& a, const S& b) {
  const std::size_t L = pf::io::ckpt::soa_length(a.grid().total_cells());
  for (std::size_t f = 0; f < 5; ++f) CHECK(same_bits(a.conserved_storage().data(f), b.conserved_storage().data(f), L));
  CHECK(a.time() == b.time());
  CHECK(same_bits(a.pose().X.data(), b.pose().X.data(), 3));
  CHECK(same_bits(a.pose().R.data(), b.pose().R.data(), 9));
  CHECK(same_bits(a.pose().V.data(), b.pose().V.data(), 3));
  CHECK(same_bits(a.pose().Omega.data(), b.pose().Omega.data(), 3));
  CHECK(same_bits(a.eddy_viscosity(), b.eddy_viscosity(), L));
}

// ---- structure: pre-stretched membrane + damped cables + rigid payload under gravity,
// a pressure load, energy tracking; substeps from stable_dt (they vary).
auto make_structure(bool extra_node = false) {
  const auto m = pf::model::rect_mesh({0, 0, 1}, {1, 0, 0}, {0, 1, 0}, 3, 3);
  st::nodes nd;
  st::triangle_mesh tm;
  tm.triangles = m.triangles;
  for (const auto& x : m.positions) {
    nd.add(x, {0.1 * x.y(), 0.0, -0.2 * x.x()});
    tm.reference.push_back({0.96 * x.x(), 0.97 * x.y(), x.z()});
  }
  const index_t hang = nd.add({0.5, 0.5, 0.0});
  tm.reference.push_back({0.5, 0.5, 0.0});
  if (extra_node) {
    nd.add({2, 2, 2}, {0, 0, 0}, 1.0);
    tm.reference.push_back({2, 2, 2});
  }
  st::line_mesh lines;
  for (index_t corner : {index_t(0), index_t(3), index_t(12), index_t(15)}) lines.segments.push_back({corner, hang});
  st::attachment body{st::rigid_body{st::rigid_body::cuboid(1.8, {0.2, 0.25, 0.15}),
                                     {0.5, 0.5, -0.1},
                                     Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX())),
                                     {0.05, 0, 0},
                                     {0.3, -0.2, 0.5}}};
  body.attach(hang, {0.01, 0, 0.1});
  st::assembly a{std::move(nd), st::membrane_tri{tm, st::material::fabric<>::isotropic(2e8, 0.3, 0.05, 1e-4), {0.05}},
                 st::cable{lines, st::material::cable{2e3, 0.01, 0.1, 0}}, std::move(body)};
  a.part<0>().set_pressure(30.0);
  a.integrator().mass_damping = 0.5;
  a.track_energy();
  return a;
}
template <class A>
void structure_steps(A& a, int n) {
  for (int i = 0; i < n; ++i) a.step(a.stable_dt());
}
template <class A>
void require_same_structure(const A& a, const A& b) {
  const auto& sa = a.node_set().data();
  const auto& sb = b.node_set().data();
  for (std::size_t f = 0; f < 6; ++f) CHECK(same_bits(sa.data(f), sb.data(f), std::size_t(a.node_set().size())));
  CHECK(a.time() == b.time());
  CHECK(a.steps() == b.steps());
  CHECK(a.previous_step() == b.previous_step());
  const auto& ba = a.template part<2>().body().state();
  const auto& bb = b.template part<2>().body().state();
  CHECK(same_bits(ba.x_com.data(), bb.x_com.data(), 3));
  CHECK(same_bits(ba.p.data(), bb.p.data(), 3));
  CHECK(same_bits(ba.l.data(), bb.l.data(), 3));
  CHECK(same_bits(ba.q.coeffs().data(), bb.q.coeffs().data(), 4));
  CHECK(a.energy().balance() == b.energy().balance());
  CHECK(a.energy().damping == b.energy().damping);
}
}  // namespace

TEST_CASE("checkpoint: a fluid run restored mid-way continues bit-identically") {
  pf::parallel::set_threads(1);
  auto ref = make_fluid();
  fluid_steps(ref, 6);
  const fs::path p = scratch("fluid.ckpt");
  pf::io::save_checkpoint(p, ref);
  fluid_steps(ref, 6);

  auto again = make_fluid();
  pf::io::load_checkpoint(p, again);
  CHECK(again.time() > 0);
  CHECK(again.steps() == 6);  // the fluid's step count is restored
  fluid_steps(again, 6);
  CHECK(again.steps() == ref.steps());
  require_same_fluid(ref, again);
  CHECK(ref.pose().R.isApprox(again.pose().R));
  CHECK_FALSE(ref.pose().R.isIdentity(1e-6));  // the box did turn
  const auto info = pf::io::read_checkpoint_info(p);
  CHECK(info.fluid_steps == 6);
  CHECK(info.sections == std::vector<std::string>{"fluid"});
}

TEST_CASE("checkpoint: a membrane + cable + rigid body assembly restored mid-way continues bit-identically") {
  auto ref = make_structure();
  structure_steps(ref, 50);
  const fs::path p = scratch("structure.ckpt");
  pf::io::save_checkpoint(p, ref);
  structure_steps(ref, 50);

  auto again = make_structure();
  again.part<0>().set_pressure(0.0);  // restored from the file
  pf::io::load_checkpoint(p, again);
  CHECK(again.steps() == 50);
  structure_steps(again, 50);
  require_same_structure(ref, again);
  CHECK(ref.energy().damping > 0);
}

TEST_CASE("checkpoint: a stepper's fluid and assembly restored, stepper rebuilt, continues bit-identically") {
  pf::parallel::set_threads(1);
  auto run = [](auto& s, int n) {
    for (int i = 0; i < n; ++i) {
      s.fluid().frame().track(target_x(s.time() + 2e-5), target_v(s.time() + 2e-5));
      s.step(2e-5);
    }
  };
  pf::explicit_stepper ref{make_fluid(), make_structure()};
  run(ref, 4);
  const fs::path p = scratch("stepper.ckpt");
  pf::io::save_checkpoint(p, ref);
  run(ref, 4);
  CHECK(pf::io::read_checkpoint_info(p).sections == std::vector<std::string>{"fluid", "structure", "stepper"});

  auto fl = make_fluid();
  auto as = make_structure();
  pf::io::load_checkpoint(p, fl, as);
  pf::explicit_stepper again{std::move(fl), std::move(as)};
  CHECK(again.time() == pf::io::read_checkpoint_info(p).time);
  run(again, 4);
  require_same_fluid(ref.fluid(), again.fluid());
  require_same_structure(ref.structure(), again.structure());
}

TEST_CASE("checkpoint: an embedded-coupling stepper restored mid-way continues bit-identically") {
  pf::parallel::set_threads(1);
  auto make = [] {
    auto grid = pf::fluid::rectilinear_grid::uniform({8, 8, 8}, {0, 0, 0}, {0.4, 0.4, 0.4});
    pf::fluid::solver fl{grid, pf::boundary::set::all(pf::boundary::periodic{})};
    fl.fill_uniform({1.2, {0, 0, 0}, 101325.0});
    const auto m = pf::model::rect_mesh({0.12, 0.1, 0.11}, {0.02, 0.18, 0.0}, {0.0, 0.03, 0.17}, 3, 3);
    st::nodes nd;
    for (const auto& x : m.positions) nd.add(x, {4.0, 1.0, -0.5});
    st::triangle_mesh tm;
    tm.triangles = m.triangles;
    st::assembly as{std::move(nd), st::membrane_tri{tm, st::material::fabric<>::isotropic(1e5, 0.3, 0.5, 1e-4)}};
    as.integrator().gravity = {0, 0, 0};
    return std::pair{std::move(fl), std::move(as)};
  };
  auto [f0, a0] = make();
  pf::explicit_stepper ref{std::move(f0), std::move(a0), pf::coupling::embedded{pf::porosity::impermeable{}}};
  const double dt = 0.5 * ref.stable_dt(0.5);
  for (int i = 0; i < 5; ++i) ref.step(dt);
  const fs::path p = scratch("embedded.ckpt");
  pf::io::save_checkpoint(p, ref);
  for (int i = 0; i < 5; ++i) ref.step(dt);

  auto [f1, a1] = make();
  pf::io::load_checkpoint(p, f1, a1);
  pf::explicit_stepper again{std::move(f1), std::move(a1), pf::coupling::embedded{pf::porosity::impermeable{}}};
  for (int i = 0; i < 5; ++i) again.step(dt);
  const std::size_t L = pf::io::ckpt::soa_length(ref.fluid().grid().total_cells());
  for (std::size_t f = 0; f < 5; ++f)
    CHECK(same_bits(ref.fluid().conserved_storage().data(f), again.fluid().conserved_storage().data(f), L));
  const auto& sa = ref.structure().node_set().data();
  const auto& sb = again.structure().node_set().data();
  for (std::size_t f = 0; f < 6; ++f)
    CHECK(same_bits(sa.data(f), sb.data(f), std::size_t(ref.structure().node_set().size())));
}

TEST_CASE("checkpoint: a penalty-coupled stepper restored mid-way continues bit-identically") {
  pf::parallel::set_threads(1);
  auto make = [](double pfac = 1.0) {
    auto grid = pf::fluid::rectilinear_grid::uniform({8, 8, 8}, {0, 0, 0}, {0.4, 0.4, 0.4});
    pf::fluid::solver fl{grid, pf::boundary::set::all(pf::boundary::periodic{})};
    fl.fill_uniform({1.2, {0, 0, 0}, 101325.0});
    const auto m = pf::model::rect_mesh({0.12, 0.1, 0.11}, {0.02, 0.18, 0.0}, {0.0, 0.03, 0.17}, 3, 3);
    st::nodes nd;
    for (const auto& x : m.positions) nd.add(x, {4.0, 1.0, -0.5});
    st::triangle_mesh tm;
    tm.triangles = m.triangles;
    st::assembly as{std::move(nd), st::membrane_tri{tm, st::material::fabric<>::isotropic(1e5, 0.3, 0.05, 1e-4)}};
    as.integrator().gravity = {0, 0, 0};
    pf::coupling::penalty_options o;
    o.pfac = pfac;
    return pf::explicit_stepper{std::move(fl), std::move(as),
                                pf::coupling::penalty{pf::porosity::ergun{1e9, 1e5, 1e-4}, o}};
  };
  auto ref = make();
  // Varying steps, so the restored stepper must know its previous substep.
  for (int i = 0; i < 5; ++i) ref.step((0.4 + 0.05 * i) * ref.stable_dt(0.5));
  const fs::path p = scratch("penalty.ckpt");
  pf::io::save_checkpoint(p, ref);
  std::vector<double> dts;
  for (int i = 0; i < 5; ++i) {
    dts.push_back((0.6 - 0.04 * i) * ref.stable_dt(0.5));
    ref.step(dts.back());
  }
  auto again = make();
  pf::io::load_checkpoint(p, again);
  CHECK(again.steps() == 5);
  CHECK(again.fluid().steps() == 5);
  for (double dt : dts) again.step(dt);
  CHECK(again.time() == ref.time());
  CHECK(again.steps() == ref.steps());
  CHECK(again.fluid().steps() == ref.fluid().steps());
  const std::size_t L = pf::io::ckpt::soa_length(ref.fluid().grid().total_cells());
  for (std::size_t f = 0; f < 5; ++f)
    CHECK(same_bits(ref.fluid().conserved_storage().data(f), again.fluid().conserved_storage().data(f), L));
  const auto& sa = ref.structure().node_set().data();
  const auto& sb = again.structure().node_set().data();
  for (std::size_t f = 0; f < 6; ++f)
    CHECK(same_bits(sa.data(f), sb.data(f), std::size_t(ref.structure().node_set().size())));
  for (index_t c = 0; c < index_t(ref.coupling().points().size()); ++c)
    CHECK(ref.coupling().penetration(c) == again.coupling().penetration(c));
  CHECK(ref.coupling().diagnostics().coupling_energy == again.coupling().diagnostics().coupling_energy);
  // The coupling's settings are part of the scene: another PFAC is refused by name.
  auto stiffer = make(2.0);
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(p, stiffer),
                       doctest::Contains("the penalty factor PFAC is 1 in the file but 2 here"),
                       pf::io::checkpoint_error);
}

TEST_CASE("checkpoint: truncated, corrupted, foreign and mismatched files are refused with clear messages") {
  pf::parallel::set_threads(1);
  auto s = make_fluid();
  fluid_steps(s, 2);
  auto a = make_structure();
  structure_steps(a, 3);
  const fs::path p = scratch("good.ckpt");
  pf::io::save_checkpoint(p, s, a);
  CHECK_FALSE(fs::exists(p.string() + ".tmp"));
  const auto good = bytes_of(p);

  auto fresh = make_fluid();
  const std::vector<double> before(fresh.conserved_storage().data(0),
                                   fresh.conserved_storage().data(0) + fresh.grid().total_cells());
  auto unchanged = [&] {
    return same_bits(before.data(), fresh.conserved_storage().data(0), before.size()) && fresh.time() == 0.0;
  };

  const fs::path bad = scratch("bad.ckpt");
  write_bytes(bad, std::vector<unsigned char>(good.begin(), good.begin() + std::ptrdiff_t(good.size() / 2)));
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(bad, fresh), doctest::Contains("truncated"), pf::io::checkpoint_error);
  write_bytes(bad, std::vector<unsigned char>(good.begin(), good.begin() + 20));
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(bad, fresh), doctest::Contains("truncated"), pf::io::checkpoint_error);

  auto flipped = good;
  flipped[flipped.size() / 3] ^= 0x10;
  write_bytes(bad, flipped);
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(bad, fresh), doctest::Contains("checksum mismatch"),
                       pf::io::checkpoint_error);

  write_bytes(bad, {'h', 'e', 'l', 'l', 'o', '\n'});
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(bad, fresh), doctest::Contains("not a parafsi checkpoint"),
                       pf::io::checkpoint_error);
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(scratch("missing.ckpt"), fresh), doctest::Contains("cannot open"),
                       pf::io::checkpoint_error);

  auto other_grid = make_fluid(13);
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(p, other_grid),
                       doctest::Contains("grid axis 1 has 12 cells in the file but 13 in this solver"),
                       pf::io::checkpoint_error);
  pf::fluid::solver other_type{fresh.grid(), pf::boundary::set::all(pf::boundary::far_field{})};
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(p, other_type), doctest::Contains("the solver type is"),
                       pf::io::checkpoint_error);

  auto other_scene = make_structure(/*extra_node=*/true);
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(p, other_scene),
                       doctest::Contains("the node count is 17 in the file but 18 here"), pf::io::checkpoint_error);
  const fs::path fluid_only = scratch("fluid_only.ckpt");
  pf::io::save_checkpoint(fluid_only, s);
  auto a2 = make_structure();
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(fluid_only, a2),
                       doctest::Contains("has no section 'structure' (it holds: fluid)"), pf::io::checkpoint_error);
  CHECK(unchanged());

  // And the good file still loads.
  pf::io::load_checkpoint(p, fresh, a2);
  CHECK(fresh.time() == s.time());
  CHECK(a2.steps() == 3);
}

TEST_CASE("checkpoint: format version 1 is refused naming both versions") {
  pf::parallel::set_threads(1);
  auto s = make_fluid();
  const fs::path p = scratch("v2.ckpt");
  pf::io::save_checkpoint(p, s);
  auto b = bytes_of(p);
  std::uint32_t version;
  std::memcpy(&version, b.data() + 19, 4);
  CHECK(version == 2);
  CHECK(pf::io::checkpoint_version == 2);
  version = 1;
  std::memcpy(b.data() + 19, &version, 4);
  const fs::path v1 = scratch("v1.ckpt");
  write_bytes(v1, b);
  auto fresh = make_fluid();
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(v1, fresh),
                       doctest::Contains(
                           "checkpoint format version 1 (entries by position); this build reads version 2"),
                       pf::io::checkpoint_error);
  CHECK_THROWS_WITH_AS(pf::io::read_checkpoint_info(v1), doctest::Contains("format version 1"),
                       pf::io::checkpoint_error);
  CHECK(fresh.time() == 0.0);
}

TEST_CASE("checkpoint: fields are stored by their tag names; another name is refused naming both") {
  pf::parallel::set_threads(1);
  auto s = make_fluid();
  fluid_steps(s, 1);
  auto a = make_structure();
  structure_steps(a, 2);
  const fs::path p = scratch("named.ckpt");
  pf::io::save_checkpoint(p, s, a);
  const auto good = bytes_of(p);
  // Every conserved field, source, μ_t and node field appears under its tag name.
  const std::string text(good.begin(), good.end());
  for (const char* n : {"conserved.rho", "conserved.mx", "conserved.my", "conserved.mz", "conserved.E", "sources.s_mx",
                        "sources.s_rho", "turbulence.mu_t", "frame.target_position", "node.x", "node.vz", "node.minv",
                        "node.fez", "part0.pressure", "part2.body.q_half", "nodes.constraints"})
    CHECK_MESSAGE(text.find(n) != std::string::npos, n);

  const fs::path bad = scratch("renamed.ckpt");
  write_bytes(bad, rename_entry(good, "conserved.rho", "conserved.RHO"));
  auto f2 = make_fluid();
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(bad, f2),
                       doctest::Contains("expected entry 'conserved.rho' but found 'conserved.RHO'"),
                       pf::io::checkpoint_error);
  write_bytes(bad, rename_entry(good, "node.vy", "node.VY"));
  auto a2 = make_structure();
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(bad, a2),
                       doctest::Contains("expected entry 'node.vy' but found 'node.VY'"), pf::io::checkpoint_error);
  // The untouched file loads, and the restored fluid and structure clocks equal the saved ones.
  auto f3 = make_fluid();
  auto a3 = make_structure();
  pf::io::load_checkpoint(p, f3, a3);
  CHECK(f3.steps() == s.steps());
  CHECK(f3.steps() == 1);
  CHECK(a3.steps() == 2);
}

TEST_CASE("checkpoint: a non-finite value in an intact file is refused naming the entry") {
  pf::parallel::set_threads(1);
  auto s = make_fluid();
  s.conserved_storage().data(4)[s.grid().index(2, 3, 1)] = std::numeric_limits<double>::quiet_NaN();
  const fs::path p = scratch("nan.ckpt");
  pf::io::save_checkpoint(p, s);
  auto fresh = make_fluid();
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(p, fresh),
                       doctest::Contains("entry 'conserved.E' holds a non-finite value (nan at index"),
                       pf::io::checkpoint_error);
}

TEST_CASE("checkpoint: a scene signature is saved and a restart with another scene is refused by name") {
  pf::parallel::set_threads(1);
  auto s = make_fluid();
  pf::io::scene_signature scene;
  scene.add("pgs_alpha", 8.0).add("payload_mass", 100.0).add("fabric", "mat544").add("line_stiffness_scale", 1.0);
  const fs::path p = scratch("scene.ckpt");
  pf::io::save_checkpoint(p, s, scene);
  CHECK(pf::io::read_checkpoint_info(p).sections == std::vector<std::string>{"fluid", "scene"});

  auto fresh = make_fluid();
  pf::io::scene_signature other;
  other.add("pgs_alpha", 8.0).add("payload_mass", 50.0).add("fabric", "mat544").add("line_stiffness_scale", 1.0);
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(p, fresh, other),
                       doctest::Contains("scene parameter 'payload_mass' is 100 in the file but 50 here"),
                       pf::io::checkpoint_error);
  pf::io::scene_signature fabric;
  fabric.add("pgs_alpha", 8.0).add("payload_mass", 100.0).add("fabric", "mat509").add("line_stiffness_scale", 1.0);
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(p, fresh, fabric),
                       doctest::Contains("scene parameter 'fabric' is 'mat544' in the file but 'mat509' here"),
                       pf::io::checkpoint_error);
  pf::io::scene_signature fewer;
  fewer.add("pgs_alpha", 8.0).add("payload_mass", 100.0).add("fabric", "mat544");
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(p, fresh, fewer),
                       doctest::Contains("scene parameter 'line_stiffness_scale' is in the file but not in this run"),
                       pf::io::checkpoint_error);
  pf::io::scene_signature more = scene;
  more.add("modulus_scale", 10.0);
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(p, fresh, more),
                       doctest::Contains("scene parameter 'modulus_scale' is in this run's scene signature but not in "
                                         "the file"),
                       pf::io::checkpoint_error);
  CHECK_THROWS_AS(scene.add("pgs_alpha", 6.0), pf::invalid_input);  // a parameter is given once
  CHECK_THROWS_AS(pf::io::scene_signature{}.add("alpha", std::numeric_limits<double>::quiet_NaN()), pf::invalid_input);

  pf::io::load_checkpoint(p, fresh, scene);  // the same scene loads
  CHECK(fresh.time() == s.time());
  // A file without a scene section: a restart that gives one is refused, naming the section.
  const fs::path bare = scratch("no_scene.ckpt");
  pf::io::save_checkpoint(bare, s);
  CHECK_THROWS_WITH_AS(pf::io::load_checkpoint(bare, fresh, scene), doctest::Contains("has no section 'scene'"),
                       pf::io::checkpoint_error);
}

TEST_CASE("checkpoint: a quad membrane with a pinned edge and a pressure load continues bit-identically") {
  auto make = [] {
    st::nodes nd;
    st::quad_mesh qm;
    const int n = 4;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d x{0.1 * i, 0.1 * j, 0.002 * i * j};
        nd.add(x, {0.0, 0.0, 0.01 * i});
        qm.reference.push_back({0.098 * i, 0.099 * j, 0.0});
      }
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i)
        qm.quads.push_back(
            {index_t(j * n + i), index_t(j * n + i + 1), index_t((j + 1) * n + i + 1), index_t((j + 1) * n + i)});
    for (int i = 0; i < n; ++i) nd.pin(i);
    st::quad_options o;
    o.damping_ratio = 0.05;
    st::assembly a{std::move(nd), st::membrane_quad{qm, st::material::fabric<>::isotropic(2e8, 0.3, 0.05, 1e-4), o}};
    std::vector<double> p(9);
    for (std::size_t e = 0; e < p.size(); ++e) p[e] = 20.0 + 3.0 * double(e);
    a.part<0>().set_pressure(p);
    a.integrator().gravity = {0, 0, -9.81};
    return a;
  };
  auto ref = make();
  structure_steps(ref, 40);
  const fs::path path = scratch("quad.ckpt");
  pf::io::save_checkpoint(path, ref);
  structure_steps(ref, 40);
  auto again = make();
  again.part<0>().set_pressure(0.0);  // restored from the file
  pf::io::load_checkpoint(path, again);
  CHECK(again.steps() == 40);
  structure_steps(again, 40);
  const auto& sa = ref.node_set().data();
  const auto& sb = again.node_set().data();
  for (std::size_t f = 0; f < 6; ++f) CHECK(same_bits(sa.data(f), sb.data(f), std::size_t(ref.node_set().size())));
  CHECK(again.time() == ref.time());
  CHECK(again.part<0>().pressure()[8] == 44.0);
}
