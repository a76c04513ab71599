// Coupling throughput: a pinned flat disk (model::disk_mesh, normal along x) across a
// uniform stream in a periodic N³ box, stepped with explicit_stepper, once coupled
// (penalty or embedded, impermeable) and once with the same fluid and structure and
// coupling::none. From the stepper's phase timings (median per step over repeats):
//
//   coupling time / step = coupled step − uncoupled step (same fluid, same structure);
//   share                = coupling time / coupled step;
//   point updates / step = penalty:  coupling points × structure substeps,
//                          embedded: crossed faces × RK stages (face-flux evaluations);
//   point_updates_per_s  = point updates / step ÷ coupling time / step.
//
// The difference includes everything the coupling adds: for penalty the exchange
// (fluid snapshot, stiffness, caps), the point loop of every substep and the source
// scaling; for embedded the face search, the membrane Riemann problems inside the
// fluid step and the nodal spreading.
//
//   coupling_throughput [--cells 48] [--rings 24] [--steps 8] [--repeats 3] [--threads 1,2]
//
// One line per method and thread count:
//   coupling_throughput method=<penalty|embedded> points=<n> threads=<t> point_updates_per_s=<x> share=<s> ...
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <parafsi/coupling/coupling.hpp>
#include <parafsi/explicit_stepper.hpp>
#include <parafsi/model/disk_mesh.hpp>
#include <parafsi/parafsi.hpp>

namespace pf = parafsi;
namespace st = pf::structure;
using pf::index_t;

namespace {

struct setup {
  int cells = 48, rings = 24, steps = 8, repeats = 3;
};

auto make_fluid(const setup& su) {
  const double L = 1.0, U = 20.0;
  auto grid = pf::fluid::rectilinear_grid::uniform({su.cells, su.cells, su.cells}, {0, 0, 0}, {L, L, L});
  pf::fluid::solver fl{grid, pf::boundary::set::all(pf::boundary::periodic{})};
  fl.fill_uniform({1.18, {U, 0, 0}, 101325.0});
  return fl;
}

auto make_structure(const setup& su) {
  const auto dm = pf::model::disk_mesh(0.35, su.rings);
  st::nodes nd;
  for (const auto& p : dm.positions) nd.add(Eigen::Vector3d(0.5, 0.5 + p.x(), 0.5 + p.y()));
  for (index_t i = 0; i < nd.size(); ++i) nd.pin(i);
  st::triangle_mesh tm;
  tm.triangles = dm.triangles;
  st::membrane_tri mem{tm, st::material::fabric<>::isotropic(3e8, 0.3, 0.054, 1.1e-4)};
  st::assembly as{std::move(nd), std::move(mem)};
  as.integrator().gravity = {0, 0, 0};
  return as;
}

struct result {
  double per_step = 0;  // median total seconds per step
  double updates = 0;   // coupling updates per step
  long substeps = 0;
  index_t points = 0;
};

// Median seconds per step (stepper phase timings) over `repeats` runs of `steps` steps.
template <class Stepper, class Count>
result time_stepper(Stepper& s, const setup& su, Count&& count) {
  const double dt = s.stable_dt(0.5);
  for (int w = 0; w < 2; ++w) s.step(dt);  // warm-up
  std::vector<double> per;
  result r;
  for (int rep = 0; rep < su.repeats; ++rep) {
    s.reset_timings();
    double upd = 0;
    for (int k = 0; k < su.steps; ++k) {
      s.step(dt);
      upd += count(s);
    }
    per.push_back(s.timings().total() / su.steps);
    r.updates = upd / su.steps;
  }
  std::sort(per.begin(), per.end());
  r.per_step = per[per.size() / 2];
  r.substeps = s.last_substeps();
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Coupling throughput (point updates/s) and the coupling's share of a coupled step"};
  setup su;
  std::vector<int> threads{1, 2};
  std::vector<std::string> methods{"penalty", "embedded"};
  app.add_option("--cells", su.cells, "fluid cells per side of the periodic unit box")
      ->check(CLI::Range(8, 512))
      ->capture_default_str();
  app.add_option("--rings", su.rings, "disk mesh rings (6 rings^2 triangles, radius 0.35 m)")
      ->check(CLI::Range(2, 1000))
      ->capture_default_str();
  app.add_option("--steps", su.steps, "timed steps per repeat")->check(CLI::Range(1, 100000))->capture_default_str();
  app.add_option("--repeats", su.repeats, "repeats (median)")->check(CLI::Range(1, 1000))->capture_default_str();
  app.add_option("--threads", threads, "thread counts")
      ->check(CLI::Range(1, 1024))
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--method", methods, "couplings to measure")
      ->check(CLI::IsMember({"penalty", "embedded"}))
      ->delimiter(',')
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  std::printf("# command: coupling_throughput --cells %d --rings %d --steps %d --repeats %d (OpenMP %s)\n", su.cells,
              su.rings, su.steps, su.repeats, pf::parallel::enabled() ? "on" : "off");
  for (int t : threads) {
    pf::parallel::set_threads(t);
    // Uncoupled reference: same fluid (threaded the same way) and the same structure.
    pf::explicit_stepper ref{make_fluid(su), make_structure(su)};
    ref.fluid().set_threading(true);
    const result r0 = time_stepper(ref, su, [](auto&) { return 0.0; });
    for (const auto& m : methods) {
      auto report = [&](const result& r, double exch, double str, double flu) {
        const double cost = r.per_step - r0.per_step;
        std::printf(
            "coupling_throughput method=%s points=%ld threads=%d point_updates_per_s=%.4e share=%.3f "
            "coupled_step_s=%.4e uncoupled_step_s=%.4e updates_per_step=%.0f substeps=%ld "
            "phase_exchange=%.3f phase_structure=%.3f phase_fluid=%.3f\n",
            m.c_str(), long(r.points), t, cost > 0 ? r.updates / cost : 0.0, cost / r.per_step, r.per_step, r0.per_step,
            r.updates, r.substeps, exch, str, flu);
        std::fflush(stdout);
      };
      if (m == "penalty") {
        pf::coupling::penalty_options po;
        po.pfac = 1.0;
        pf::explicit_stepper s{make_fluid(su), make_structure(su),
                               pf::coupling::penalty{pf::porosity::impermeable{}, po}};
        s.fluid().set_threading(true);
        result r = time_stepper(s, su, [](auto& sp) {
          return double(sp.coupling().diagnostics().active_points) * double(sp.last_substeps());
        });
        r.points = s.coupling().points().size();
        const auto& ph = s.timings();
        report(r, (ph.move_frame + ph.exchange) / ph.total(), ph.structure / ph.total(), ph.fluid / ph.total());
      } else {
        pf::explicit_stepper s{make_fluid(su), make_structure(su), pf::coupling::embedded{pf::porosity::impermeable{}}};
        s.fluid().set_threading(true);
        using Fl = std::remove_cvref_t<decltype(s.fluid())>;
        constexpr int stages = Fl::time_type::stages;
        result r = time_stepper(s, su, [&](auto& sp) { return double(sp.coupling().diagnostics().faces) * stages; });
        r.points = s.coupling().diagnostics().faces;
        const auto& ph = s.timings();
        report(r, (ph.move_frame + ph.exchange) / ph.total(), ph.structure / ph.total(), ph.fluid / ph.total());
      }
    }
  }
  return 0;
}
